//! The landmark method's assumptions tested on the data ([`crate::checks`]): a landmark is seen
//! from enough stops, over a wide enough span of distances, to separate the bias coefficients
//! from its own unknown distance; each landmark is seen from directions far enough apart to be
//! placed; and the detections associated to a landmark agree with it.
//!
//! Why per landmark. A landmark's distance is estimated from the same data: the bearings fix it
//! only to about d·σθ/γ (γ its triangulation angle: 4 % of d at the 5° minimum with the XV-11's
//! σθ ≈ 0.2°, comparable with the bias, 3-13 % of d at 2-4 m for the papers' model). So its
//! ranges trace the bias about its own unknown distance D: r̃ₖ = f(D + Δₖ), Δₖ the stops'
//! displacements along its line of sight (the commanded motion, the method's metric reference).
//! Ranges to landmarks at other distances add levels whose distances are themselves unknown:
//! they cannot stand in for one landmark seen from many stops. Counted over all landmarks, two
//! stops among near and far landmarks span metres while each landmark spans only the step
//! between the stops.

use hilsim_recording::wrap_angle;

use super::estimate::ObservationSet;
use crate::checks::Check;

/// The order the bias is taken to have at least, whatever order was selected: both papers'
/// XV-11 bias is quadratic (the landmark paper's Sec. 4.1, the EM paper's Table I). AIC picks a
/// lower order when the data cannot show the higher one; that must not pass as a result.
pub const XV11_BIAS_ORDER: usize = 2;

/// Stops a landmark must be seen from for a bias of order `order`: `order + 2`. Its ranges
/// r̃ₖ = f(D + Δₖ) are a polynomial of that order in Δₖ (f's Taylor series about the unknown
/// D), whose `order + 1` coefficients take ranges from as many distinct stops; one more leaves
/// a residual, without which AIC and cross-validation cannot tell the order from the next
/// (a fit through `order + 1` points is exact). Two stops give each landmark a slope only.
#[must_use]
pub const fn stops_needed(order: usize) -> usize {
    order + 2
}

/// One XV-11 reading's noise at 2 m, the middle of the landmark paper's 0.5-4 m: σ = 0.004 d²
/// (the EM paper's Table I, a real XV-11), 1.6 cm.
pub const XV11_NOISE_AT_2M_M: f64 = 0.004 * 2.0 * 2.0;

/// The span of distances over which the order-`order` term `alpha_p dᵖ` departs from the best
/// lower-order polynomial by `noise_m`: that departure is at least `2 |alpha_p| (w/4)ᵖ` over a
/// span `w` (the minimax error of dᵖ, Chebyshev), so `w = 4 (noise / (2 |alpha_p|))^(1/p)`.
#[must_use]
pub fn span_needed_m(alpha_p: f64, order: usize, noise_m: f64) -> f64 {
    let p = order.max(1) as f64;
    4.0 * (noise_m / (2.0 * alpha_p.abs())).powf(1.0 / p)
}

/// Smallest span of distances over which one landmark is seen: 1.5 m.
/// [`span_needed_m`] for the papers' quadratic term (α2 = 0.0584 /m, the landmark paper's
/// Sec. 4.1) against [`XV11_NOISE_AT_2M_M`] is 1.48 m: over less, α2 w²/8 is below one
/// reading's noise and AIC picks a straight line for a curved bias. A floor, not a guarantee:
/// the data's averaged ranges are less noisy than one reading, and the paper's robot spans 3 m.
pub const MIN_DISTANCE_SPAN_M: f64 = 1.5;

/// Smallest angle under which a landmark's stops are seen from it: 5°. Its position is where
/// the bearing lines cross; at 5° a bearing error of the XV-11's ~0.2° moves the crossing
/// along the lines by about 0.2/5 of the distance (4 cm at 1 m).
pub const MIN_TRIANGULATION_DEG: f64 = 5.0;

/// Bearing residual beyond which an observation disagrees with its landmark: 3°, fifteen times
/// the XV-11's bearing noise (the landmark paper's σθ ≈ 0.2°).
pub const ASSOCIATION_BEARING_DEG: f64 = 3.0;

/// Largest share of observations that may disagree with their landmark: 5 %.
pub const MAX_MISASSOCIATED: f64 = 0.05;

/// The checks, over the observations `used`, the estimated landmark `positions` and the
/// selected polynomial `order`.
#[must_use]
pub fn landmark_checks(
    set: &ObservationSet,
    used: &[usize],
    positions: &[Option<[f64; 2]>],
    order: usize,
) -> Vec<Check> {
    let observations: Vec<_> = used
        .iter()
        .filter_map(|&i| set.observations.get(i))
        .collect();
    // In the order `hilsim calibrate` prints them (the README shows it), the stop count last.
    let mut checks: Vec<Check> = span_check(set, &observations, positions)
        .into_iter()
        .collect();
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
                "landmark {} is seen from stops {spread:.1} deg apart (the narrowest); \
                 below {MIN_TRIANGULATION_DEG} deg its position, and the distances to it, are \
                 poorly determined",
                landmark + 1
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
    checks.push(stops_check(set, &observations, order));
    checks
}

/// The most stops any one landmark is seen from, against [`stops_needed`] for the selected order
/// or [`XV11_BIAS_ORDER`], whichever is higher.
fn stops_check(
    set: &ObservationSet,
    observations: &[&super::estimate::Observation],
    order: usize,
) -> Check {
    let mut seen_from: Vec<Vec<usize>> = vec![Vec::new(); set.landmarks];
    for o in observations {
        if let Some(stops) = seen_from.get_mut(o.landmark) {
            stops.push(o.stop);
        }
    }
    let counts: Vec<usize> = seen_from
        .iter_mut()
        .map(|s| {
            s.sort_unstable();
            s.dedup();
            s.len()
        })
        .collect();
    let (best, most) = counts
        .iter()
        .enumerate()
        .max_by_key(|(_, n)| **n)
        .map_or((0, 0), |(l, n)| (l, *n));
    let mut all: Vec<usize> = observations.iter().map(|o| o.stop).collect();
    all.sort_unstable();
    all.dedup();
    let needed = order.max(XV11_BIAS_ORDER);
    Check::at_least(
        "landmarks.stops",
        most as f64,
        stops_needed(needed) as f64,
        format!(
            "landmark {} is seen from {most} stop(s), the most of any ({} stop(s) in all); a \
             landmark's ranges trace the bias about its own unknown distance, so order p needs \
             p + 2 stops: order 1 needs {}, order 2 (the papers' quadratic) {}, order 3 {}; \
             checked for order {needed}",
            best + 1,
            all.len(),
            stops_needed(1),
            stops_needed(2),
            stops_needed(3),
        ),
    )
}

/// The widest span of distances d̂ = |ĉ − s| − R over which one landmark is seen, against
/// [`MIN_DISTANCE_SPAN_M`]; `None` without a placed landmark.
fn span_check(
    set: &ObservationSet,
    observations: &[&super::estimate::Observation],
    positions: &[Option<[f64; 2]>],
) -> Option<Check> {
    let mut widest: Option<(usize, f64, f64)> = None;
    for (landmark, centre) in positions.iter().enumerate() {
        let Some(c) = centre else { continue };
        let (lo, hi) = observations
            .iter()
            .filter(|o| o.landmark == landmark)
            .filter_map(|o| set.stops.get(o.stop))
            .map(|s| (c[0] - s[0]).hypot(c[1] - s[1]) - set.radius_m)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
                (lo.min(d), hi.max(d))
            });
        if lo <= hi && widest.is_none_or(|(_, l, h)| hi - lo > h - l) {
            widest = Some((landmark, lo, hi));
        }
    }
    let (landmark, lo, hi) = widest?;
    Some(Check::at_least(
        "landmarks.distance_span_m",
        hi - lo,
        MIN_DISTANCE_SPAN_M,
        format!(
            "landmark {} is seen from {lo:.2} m to {hi:.2} m, the widest span of any one \
             landmark; over a span w the papers' quadratic term departs from a straight line by \
             alpha2 w^2/8, which needs {MIN_DISTANCE_SPAN_M} m to exceed one XV-11 reading's \
             noise (order p: 2 |alpha_p| (w/4)^p); spans across landmarks do not count, each \
             landmark's distance being unknown",
            landmark + 1
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::landmarks::estimate::Observation;
    use hilsim_fixtures::landmark_study::PAPER_ALPHA;

    /// Two stops 0.3 m apart, landmarks at 1 m and 3 m ahead-left: wide across landmarks, narrow
    /// along each.
    fn two_stops() -> (ObservationSet, Vec<Option<[f64; 2]>>) {
        let stops: Vec<[f64; 2]> = vec![[0.0, 0.0], [0.3, 0.0]];
        let landmarks: [[f64; 2]; 2] = [[1.0, 0.5], [3.0, 1.0]];
        let observations = landmarks
            .iter()
            .enumerate()
            .flat_map(|(l, c)| {
                stops.iter().enumerate().map(move |(k, s)| Observation {
                    landmark: l,
                    stop: k,
                    bearing_rad: (c[1] - s[1]).atan2(c[0] - s[0]),
                    range_m: (c[0] - s[0]).hypot(c[1] - s[1]) - 0.12,
                    count: 1,
                    scatter: Vec::new(),
                })
            })
            .collect();
        let set = ObservationSet {
            stop_sd_m: vec![None; stops.len()],
            stops,
            landmarks: 2,
            radius_m: 0.12,
            observations,
        };
        (set, landmarks.iter().copied().map(Some).collect())
    }

    fn find<'a>(checks: &'a [Check], name: &str) -> &'a Check {
        checks
            .iter()
            .find(|c| c.name == name)
            .unwrap_or_else(|| panic!("{name} missing: {checks:?}"))
    }

    #[test]
    fn span_threshold_is_the_papers_quadratic_against_the_xv11_noise() {
        let w = span_needed_m(PAPER_ALPHA[2], 2, XV11_NOISE_AT_2M_M);
        assert!((w - 1.48).abs() < 0.005, "{w}");
        assert!(MIN_DISTANCE_SPAN_M >= w && MIN_DISTANCE_SPAN_M - w < 0.05);
    }

    #[test]
    fn spans_across_landmarks_do_not_count() {
        let (set, positions) = two_stops();
        let used: Vec<usize> = (0..set.observations.len()).collect();
        let checks = landmark_checks(&set, &used, &positions, 1);
        let span = find(&checks, "landmarks.distance_span_m");
        // Across the two landmarks 0.74-3.04 m; along the far one, the widest, 2.76-3.04 m.
        assert!((span.value - 0.283).abs() < 0.001, "{span:?}");
        assert!(
            !span.pass && span.detail.contains("landmark 2"),
            "{}",
            span.detail
        );
    }

    #[test]
    fn two_stops_fail_even_when_a_line_was_selected() {
        let (set, positions) = two_stops();
        let used: Vec<usize> = (0..set.observations.len()).collect();
        // A line selected: still checked for the papers' quadratic, 2 + 2 stops.
        let checks = landmark_checks(&set, &used, &positions, 1);
        let stops = find(&checks, "landmarks.stops");
        assert!(!stops.pass, "{stops:?}");
        assert_eq!((stops.value, stops.threshold), (2.0, 4.0));
        let checks = landmark_checks(&set, &used, &positions, 3);
        assert_eq!(find(&checks, "landmarks.stops").threshold, 5.0);
    }

    #[test]
    fn no_observations_fail_the_stop_count_without_a_panic() {
        let (mut set, positions) = two_stops();
        set.observations.clear();
        let checks = landmark_checks(&set, &[0, 1], &positions, 2);
        assert!(!find(&checks, "landmarks.stops").pass);
        assert!(checks.iter().all(|c| c.name != "landmarks.distance_span_m"));
    }
}
