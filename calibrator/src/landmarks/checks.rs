//! The landmark method's assumptions tested on the data ([`crate::checks`]): the distances span
//! enough range to separate the bias coefficients, each landmark is seen from directions far
//! enough apart to be placed, and the detections associated to a landmark agree with it.

use hilsim_recording::wrap_angle;

use super::estimate::ObservationSet;
use crate::checks::Check;

/// Smallest span of the observed ranges: 1 m. A quadratic bias fitted over less is an
/// extrapolation everywhere else (the landmark paper's robot spans 0.5-4 m).
pub const MIN_DISTANCE_SPAN_M: f64 = 1.0;

/// Smallest angle under which a landmark's stops are seen from it: 5°. Its position is where
/// the bearing lines cross; at 5° a bearing error of the XV-11's ~0.2° moves the crossing
/// along the lines by about 0.2/5 of the distance (4 cm at 1 m).
pub const MIN_TRIANGULATION_DEG: f64 = 5.0;

/// Bearing residual beyond which an observation disagrees with its landmark: 3°, fifteen times
/// the XV-11's bearing noise (the landmark paper's σθ ≈ 0.2°).
pub const ASSOCIATION_BEARING_DEG: f64 = 3.0;

/// Largest share of observations that may disagree with their landmark: 5 %.
pub const MAX_MISASSOCIATED: f64 = 0.05;

/// The checks, over the observations `used` and the estimated landmark `positions`.
#[must_use]
pub fn landmark_checks(
    set: &ObservationSet,
    used: &[usize],
    positions: &[Option<[f64; 2]>],
) -> Vec<Check> {
    let observations: Vec<_> = used
        .iter()
        .filter_map(|&i| set.observations.get(i))
        .collect();
    let mut checks = Vec::new();
    let (lo, hi) = observations
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), o| {
            (lo.min(o.range_m), hi.max(o.range_m))
        });
    if lo <= hi {
        checks.push(Check::at_least(
            "landmarks.distance_span_m",
            hi - lo,
            MIN_DISTANCE_SPAN_M,
            format!(
                "the landmarks were seen from {lo:.2} m to {hi:.2} m; a bias fitted over a \
                 narrow span extrapolates everywhere else"
            ),
        ));
    }
    let mut narrowest: Option<(usize, f64)> = None;
    let (mut disagreeing, mut scored) = (0usize, 0usize);
    for (landmark, centre) in positions.iter().enumerate() {
        let Some(c) = centre else { continue };
        let seen: Vec<_> = observations
            .iter()
            .filter(|o| o.landmark == landmark)
            .filter_map(|o| set.stops.get(o.stop).map(|s| (o, *s)))
            .collect();
        // Directions from the landmark to the stops that saw it.
        let directions: Vec<f64> = seen
            .iter()
            .map(|(_, s)| (s[1] - c[1]).atan2(s[0] - c[0]))
            .collect();
        if let Some(&first) = directions.first() {
            let offsets: Vec<f64> = directions.iter().map(|d| wrap_angle(d - first)).collect();
            let spread = offsets.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - offsets.iter().copied().fold(f64::INFINITY, f64::min);
            let spread = spread.to_degrees();
            if narrowest.is_none_or(|(_, s)| spread < s) {
                narrowest = Some((landmark, spread));
            }
        }
        for (o, s) in &seen {
            let expected = (c[1] - s[1]).atan2(c[0] - s[0]);
            scored += 1;
            if wrap_angle(o.bearing_rad - expected).abs().to_degrees() > ASSOCIATION_BEARING_DEG {
                disagreeing += 1;
            }
        }
    }
    if let Some((landmark, spread)) = narrowest {
        checks.push(Check::at_least(
            "landmarks.triangulation_angle_deg",
            spread,
            MIN_TRIANGULATION_DEG,
            format!(
                "landmark {landmark} is seen from stops {spread:.1} deg apart (the narrowest); \
                 below {MIN_TRIANGULATION_DEG} deg its position, and the distances to it, are \
                 poorly determined"
            ),
        ));
    }
    if scored > 0 {
        let share = disagreeing as f64 / scored as f64;
        checks.push(Check::at_most(
            "landmarks.association_consistent",
            share,
            MAX_MISASSOCIATED,
            format!(
                "{disagreeing} of {scored} observations lie more than {ASSOCIATION_BEARING_DEG} \
                 deg off the bearing of the landmark they were associated with; many means \
                 detections of different objects were taken for one landmark"
            ),
        ));
    }
    checks
}
