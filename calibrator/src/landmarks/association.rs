//! Matching detections of the same cylinder across stops.
//!
//! Each detection is placed in the start-pose frame from its stop's nominal sensor pose, its
//! bearing and its raw range (plus the radius, to the centre). The raw range is biased (for the
//! paper's model by up to ~13 % at 4 m), but the bias changes little between neighbouring stops,
//! so stops are taken in order and each detection joins the track whose latest position is
//! nearest, within a gate that grows with the range. Tracks that lost their landmark for a while
//! and found it again are merged at the end when they never share a stop and lie within the gate
//! of each other.

use super::detection::Detection;
use super::options::AssociationOptions;
use hilsim_recording::Pose;

/// A landmark's detections: indices into the detection list, one per stop at most.
pub type Track = Vec<usize>;

/// Where a detection puts the landmark's centre, start-pose frame.
#[must_use]
pub fn place(det: &Detection, sensor: &Pose, radius_m: f64) -> [f64; 2] {
    let a = sensor.yaw + det.bearing_rad;
    let r = det.range_m + radius_m;
    [sensor.x + r * a.cos(), sensor.y + r * a.sin()]
}

/// Groups `dets` into tracks; `sensors[k]` is stop k's nominal sensor pose.
#[must_use]
pub fn associate(
    dets: &[Detection],
    sensors: &[Pose],
    radius_m: f64,
    opts: &AssociationOptions,
) -> Vec<Track> {
    let places: Vec<[f64; 2]> = dets
        .iter()
        .map(|d| place(d, &sensors[d.stop], radius_m))
        .collect();
    let gate = |i: usize| opts.gate_abs_m + opts.gate_rel * dets[i].range_m;
    let mut tracks: Vec<Track> = Vec::new();
    let stops = dets.iter().map(|d| d.stop).max().map_or(0, |m| m + 1);
    for k in 0..stops {
        let here: Vec<usize> = (0..dets.len()).filter(|&i| dets[i].stop == k).collect();
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (t, track) in tracks.iter().enumerate() {
            let Some(&last) = track.last() else { continue };
            for &i in &here {
                let d = dist(places[last], places[i]);
                if d <= gate(i).max(gate(last)) {
                    pairs.push((d, t, i));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut used_track = vec![false; tracks.len()];
        let mut used_det = vec![false; dets.len()];
        for (_, t, i) in pairs {
            if !used_track[t] && !used_det[i] {
                used_track[t] = true;
                used_det[i] = true;
                tracks[t].push(i);
            }
        }
        for &i in &here {
            if !used_det[i] {
                tracks.push(vec![i]);
            }
        }
    }
    merge(tracks, dets, &places, &gate)
}

/// Merges tracks that never share a stop and whose mean positions lie within the gate.
fn merge(
    mut tracks: Vec<Track>,
    dets: &[Detection],
    places: &[[f64; 2]],
    gate: &impl Fn(usize) -> f64,
) -> Vec<Track> {
    let mean = |t: &Track| {
        let n = t.len() as f64;
        let (sx, sy) = t.iter().fold((0.0, 0.0), |(x, y), &i| {
            (x + places[i][0], y + places[i][1])
        });
        [sx / n, sy / n]
    };
    loop {
        let mut best: Option<(f64, usize, usize)> = None;
        for a in 0..tracks.len() {
            for b in a + 1..tracks.len() {
                let shared = tracks[a]
                    .iter()
                    .any(|&i| tracks[b].iter().any(|&j| dets[i].stop == dets[j].stop));
                if shared {
                    continue;
                }
                let d = dist(mean(&tracks[a]), mean(&tracks[b]));
                let g = tracks[a]
                    .iter()
                    .chain(&tracks[b])
                    .map(|&i| gate(i))
                    .fold(0.0, f64::max);
                if d <= g && best.is_none_or(|x| d < x.0) {
                    best = Some((d, a, b));
                }
            }
        }
        let Some((_, a, b)) = best else { break };
        let moved = tracks.remove(b);
        tracks[a].extend(moved);
        tracks[a].sort_by_key(|&i| dets[i].stop);
    }
    tracks
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}
