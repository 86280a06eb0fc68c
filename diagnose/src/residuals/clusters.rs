//! The groups of readings whose errors an estimated trajectory shares.

use crate::trajectory::Trajectory;

/// The groups of readings at times `t` whose errors an estimated trajectory shares: one per
/// second of motion along `trajectory` (the estimate is corrected revolution by revolution and
/// interpolated between, so its error changes over a few revolutions), and one for the whole
/// of each stop (standing still, every reading sees the same pose error).
pub(crate) fn shared_error_clusters(trajectory: &Trajectory, t: &[f64]) -> Vec<u32> {
    const BLOCK_S: f64 = 1.0;
    let end = t.iter().copied().fold(0.0, f64::max);
    let blocks = (end / BLOCK_S).floor() as usize + 1;
    // A block is its own cluster when the robot moves in it; a still block joins the one before.
    let mut id = Vec::with_capacity(blocks);
    let mut current = 0u32;
    for k in 0..blocks {
        let moving = (0..=4).any(|j| {
            let (v, w) = trajectory.twist_at((k as f64 + f64::from(j) / 4.0) * BLOCK_S);
            v.abs() > 1e-3 || w.abs() > 1e-3
        });
        if moving || k == 0 {
            current += u32::from(k > 0);
        }
        id.push(current);
    }
    t.iter()
        .map(|&t| id[((t.max(0.0) / BLOCK_S).floor() as usize).min(blocks - 1)])
        .collect()
}
