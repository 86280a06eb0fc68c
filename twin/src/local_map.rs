//! The map a log's scans have built so far, as the scan each new one is matched against: the
//! centroids of the cells the scans' points fell in, seen from where the lidar is thought to be
//! (the surface nearest along each bearing). Matching each scan to everything seen so far rather
//! than to the last key scan alone keeps the path's drift from adding up scan by scan, and where
//! the robot comes back to a place it is matched to what it saw there before: the map's walls
//! stay single instead of doubled by the drift gathered in between (CoreSLAM matches to its
//! whole map the same way: Steux and El Hamzaoui, ICARCV 2010).

use std::collections::BTreeMap;

use hilsim_calibrator::scan_match::Scan as Points;
use hilsim_recording::Pose;

/// A map cell's side, metres: a few times a URG's or a SICK's range noise (1–3 cm), so that a
/// wall's readings average to one point across it, and fine against the 0.3 m a scan moves
/// before it is added.
const CELL_M: f64 = 0.05;

/// The bearing step of the view, degrees: about a URG-04LX's 0.35° beam step and finer than a
/// SICK's 1°, so that a view has a point for about every beam of the scan matched to it.
const VIEW_STEP_DEG: f64 = 0.5;

/// How deep behind the nearest cell along a bearing a cell still counts as the same surface,
/// metres: two cells, the most a wall's readings spread across (a few centimetres of range
/// noise, a scan placed a centimetre or two off).
const WALL_DEPTH_M: f64 = 2.0 * CELL_M;

/// Scans' points in the world, averaged by cell.
#[derive(Debug, Clone, Default)]
pub struct LocalMap {
    /// Per cell: the sum of its points and their count. Ordered, so that a view sums its cells
    /// in the same order every run: the path, the world built along it and every diagnosis
    /// of it are then the same for the same log.
    cells: BTreeMap<(i64, i64), ([f64; 2], u32)>,
}

impl LocalMap {
    /// Adds `points` (in the frame of a lidar at `lidar`) to the map.
    pub fn add(&mut self, points: &Points, lidar: &Pose) {
        let (sin, cos) = lidar.yaw.sin_cos();
        for &[x, y] in &points.points {
            let w = [lidar.x + cos * x - sin * y, lidar.y + sin * x + cos * y];
            let cell = cell_of(w);
            let entry = self.cells.entry(cell).or_insert(([0.0; 2], 0));
            entry.0[0] += w[0];
            entry.0[1] += w[1];
            entry.1 += 1;
        }
    }

    /// The map as a lidar at `lidar` would see it within `max_range_m`: along each bearing
    /// step the nearest cell's centroid, in the lidar's frame (cells behind a nearer one are
    /// hidden by it).
    #[must_use]
    pub fn view(&self, lidar: &Pose, max_range_m: f64) -> Points {
        let bins = (360.0 / VIEW_STEP_DEG).round() as usize;
        let mut along: Vec<Vec<(f64, [f64; 2], u32)>> = vec![Vec::new(); bins];
        let (sin, cos) = lidar.yaw.sin_cos();
        // Only the cells within range across x: the map's ordered keys give that stripe
        // without looking at the rest of a large map.
        let stripe =
            cell_of([lidar.x - max_range_m, 0.0]).0..=cell_of([lidar.x + max_range_m, 0.0]).0;
        let cells = self
            .cells
            .range((*stripe.start(), i64::MIN)..=(*stripe.end(), i64::MAX))
            .map(|(_, cell)| cell);
        for (sum, n) in cells {
            let (wx, wy) = (sum[0] / f64::from(*n), sum[1] / f64::from(*n));
            let (dx, dy) = (wx - lidar.x, wy - lidar.y);
            let range = dx.hypot(dy);
            if !(range > 0.0 && range <= max_range_m) {
                continue;
            }
            let local = [cos * dx + sin * dy, -sin * dx + cos * dy];
            let bearing = local[1].atan2(local[0]).to_degrees().rem_euclid(360.0);
            let bin = ((bearing / VIEW_STEP_DEG) as usize).min(bins - 1);
            along[bin].push((range, local, *n));
        }
        // The surface along each bearing: the cells within a wall's depth of the nearest,
        // averaged by their points, so that a wall whose readings spread over two cells is
        // seen at its middle, not at its near face (which would move each scan matched to it
        // back by that much, and the map with it, scan after scan).
        let points = along
            .into_iter()
            .filter_map(|cells| {
                let nearest = cells.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
                let (mut sum, mut weight) = ([0.0; 2], 0.0);
                for (range, p, n) in cells {
                    if range <= nearest + WALL_DEPTH_M {
                        let w = f64::from(n);
                        sum = [sum[0] + w * p[0], sum[1] + w * p[1]];
                        weight += w;
                    }
                }
                (weight > 0.0).then(|| [sum[0] / weight, sum[1] / weight])
            })
            .collect();
        Points { points }
    }
}

fn cell_of(w: [f64; 2]) -> (i64, i64) {
    // Saturating casts: a point beyond i64's cells (never a lidar's) lands in the edge cell.
    (
        (w[0] / CELL_M).floor() as i64,
        (w[1] / CELL_M).floor() as i64,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wall_seen_from_two_places_is_one_wall_in_the_view() {
        // A wall along y = 2 m seen from the origin facing +y, and again from 1 m to the right.
        let wall = |from_x: f64| Points {
            points: (-20..=20)
                .map(|i| {
                    let x = f64::from(i) * 0.05;
                    [2.0, -(x - from_x)]
                })
                .collect(),
        };
        let mut map = LocalMap::default();
        let facing_y = |x: f64| Pose::new(x, 0.0, std::f64::consts::FRAC_PI_2);
        map.add(&wall(0.0), &facing_y(0.0));
        map.add(&wall(1.0), &facing_y(1.0));
        let view = map.view(&facing_y(0.5), 8.0);
        assert!(view.points.len() > 20);
        // Every point of the view is on the wall: 2 m ahead of the lidar, within a cell.
        for p in &view.points {
            assert!((p[0] - 2.0).abs() < CELL_M, "{p:?}");
        }
    }

    #[test]
    fn a_cell_behind_a_nearer_one_is_hidden() {
        let mut map = LocalMap::default();
        let at = Pose::new(0.0, 0.0, 0.0);
        map.add(
            &Points {
                points: vec![[1.0, 0.01], [3.0, 0.03]],
            },
            &at,
        );
        let view = map.view(&at, 8.0);
        assert_eq!(view.points.len(), 1);
        assert!((view.points[0][0] - 1.0).abs() < CELL_M);
        assert!(map.view(&at, 0.5).points.is_empty());
    }
}
