//! Sensors that report nothing the world could give: dead (every reading invalid where the
//! simulation expects valid ones) or stuck (one value where the simulation's distances vary).
//!
//! The residual stages compare only readings that can be compared: valid ones, away from the
//! range limits. A lidar stuck at 2.5 m has every reading at its own extreme, and one that
//! reports nothing has no valid reading, so both would leave the comparison quietly and the
//! recording would "agree with the simulation". This stage looks at what the sensor reported as
//! a whole first, so that a dead sensor is a mismatch, never a sensor left out.

use crate::catalogue::Sensor;
use crate::locate::{Evidence, TestKind};
use crate::physics::{Hypothesis, LidarQuery};
use crate::residuals::Context;

/// Readings a sensor needs before its health is judged (as many as a sensor needs to be
/// tested at all).
const MIN_READINGS: usize = 60;

/// Readings predicted for the check, at most: evenly thinned beyond (a share and a spread are
/// estimated to a few per cent from a thousand).
const MAX_CHECKED: usize = 2_000;

/// A sensor is dead when it reports valid readings for fewer than this share of the readings
/// the simulation expects valid. A faithful unit loses some to dark or glancing surfaces, not
/// nine in ten.
const DEAD_VALID_SHARE: f64 = 0.1;

/// A sensor is stuck when its valid readings span less than this, metres, while the true
/// distances it was pointed at span [`STUCK_TRUE_SPAN_M`] or more: a triangulation lidar's or
/// a sonar's noise alone spreads readings over millimetres (the XV-11 reports whole
/// millimetres; a sonar's resolution is about 3 mm, HC-SR04 datasheet), so one value across
/// distances that differ by decimetres is no reading of them.
const STUCK_SPAN_M: f64 = 0.002;
const STUCK_TRUE_SPAN_M: f64 = 0.2;

/// The evidence of each dead or stuck sensor, score infinite (it is no matter of noise).
pub(crate) fn dead_or_stuck(ctx: &Context<'_>) -> Vec<Evidence> {
    [lidar(ctx), sonar(ctx)].into_iter().flatten().collect()
}

fn lidar(ctx: &Context<'_>) -> Option<Evidence> {
    let declared = ctx.physics.declared().lidar?;
    let checked = looked_at(ctx.recording.lidar.as_ref()?, |s| s.t_s, ctx.end_s)?;
    let period = 60.0 / (declared.rpm * 360.0);
    let queries: Vec<LidarQuery> = checked
        .iter()
        .map(|s| LidarQuery {
            t_s: s.t_s,
            rev_start_s: s.t_s - s.angle_deg * period,
            angle_deg: s.angle_deg,
        })
        .collect();
    let predicted = ctx
        .physics
        .lidar(ctx.trajectory, &queries, &Hypothesis::nominal());
    let expected: Vec<(f64, f64)> = checked
        .iter()
        .zip(&predicted)
        .filter(|(_, p)| !p.components.is_empty())
        .filter_map(|(s, p)| {
            let valid = !s.invalid && s.range_m.is_finite() && s.range_m > 0.0;
            Some((if valid { s.range_m } else { f64::NAN }, p.true_range_m?))
        })
        .collect();
    judge(Sensor::Lidar, &expected, checked.len())
}

fn sonar(ctx: &Context<'_>) -> Option<Evidence> {
    ctx.physics.declared().sonar_half_angle_deg?;
    let checked = looked_at(ctx.recording.sonar.as_ref()?, |s| s.t_s, ctx.end_s)?;
    let times: Vec<f64> = checked.iter().map(|s| s.t_s).collect();
    let predicted = ctx
        .physics
        .sonar(ctx.trajectory, &times, &Hypothesis::nominal());
    let expected: Vec<(f64, f64)> = checked
        .iter()
        .zip(&predicted)
        .filter(|(_, p)| p.reading.is_some())
        .filter_map(|(s, p)| {
            let valid = s.range_m.is_finite() && s.range_m > 0.0;
            Some((if valid { s.range_m } else { f64::NAN }, p.true_range_m?))
        })
        .collect();
    judge(Sensor::Sonar, &expected, checked.len())
}

/// The rows up to `end_s` a check looks at, evenly thinned to at most [`MAX_CHECKED`]; `None`
/// with too few to judge.
fn looked_at<T>(rows: &[T], t_s: impl Fn(&T) -> f64, end_s: f64) -> Option<Vec<&T>> {
    let rows: Vec<&T> = rows.iter().filter(|r| t_s(r) <= end_s).collect();
    if rows.len() < MIN_READINGS {
        return None;
    }
    let step = rows.len().div_ceil(MAX_CHECKED);
    Some(rows.into_iter().step_by(step).collect())
}

/// `expected`: each reading the simulation expects valid, as (the reading, NaN when the sensor
/// reported none; the true distance). `checked`: how many readings were looked at.
fn judge(sensor: Sensor, expected: &[(f64, f64)], checked: usize) -> Option<Evidence> {
    if expected.len() < MIN_READINGS {
        return None;
    }
    let valid: Vec<(f64, f64)> = expected
        .iter()
        .copied()
        .filter(|(reading, _)| !reading.is_nan())
        .collect();
    let share = valid.len() as f64 / expected.len() as f64;
    if share < DEAD_VALID_SHARE {
        return Some(evidence(
            sensor,
            "no valid readings",
            format!(
                "the {sensor} reported a valid reading for {:.0} % of the {} readings the \
                 simulation expects one for (of {checked} looked at): the sensor is dead or \
                 blind",
                100.0 * share,
                expected.len()
            ),
        ));
    }
    let span = |values: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        hi - lo
    };
    let reading_span = span(&mut valid.iter().map(|(r, _)| *r));
    let true_span = span(&mut valid.iter().map(|(_, t)| *t));
    if valid.len() >= MIN_READINGS && reading_span < STUCK_SPAN_M && true_span >= STUCK_TRUE_SPAN_M
    {
        return Some(evidence(
            sensor,
            "one value in every reading",
            format!(
                "every valid {sensor} reading is {:.3} m (to within {:.1} mm) while the \
                 distances the simulation puts in front of it span {:.2} m: the sensor is \
                 stuck",
                valid[0].0,
                1000.0 * reading_span,
                true_span
            ),
        ));
    }
    None
}

fn evidence(sensor: Sensor, place: &str, detail: String) -> Evidence {
    Evidence {
        sensor,
        test: TestKind::Spread,
        covariate: None,
        score: f64::INFINITY,
        place: place.to_string(),
        detail,
        range: None,
        size_m: f64::NAN,
        median_m: f64::NAN,
        noise_m: f64::NAN,
        world_m: 0.0,
        beyond_world_m: f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(readings: impl Fn(usize) -> (f64, f64)) -> Option<Evidence> {
        let expected: Vec<(f64, f64)> = (0..500).map(readings).collect();
        judge(Sensor::Lidar, &expected, 600)
    }

    #[test]
    fn a_sensor_reading_its_distances_is_healthy() {
        let true_m = |k: usize| 0.5 + (k % 50) as f64 * 0.1;
        assert!(run(|k| (true_m(k) + 0.01, true_m(k))).is_none());
        // Most readings lost (dark surfaces) but not nine in ten: still reading.
        assert!(run(|k| (if k % 5 == 0 { true_m(k) } else { f64::NAN }, true_m(k))).is_none());
    }

    #[test]
    fn a_sensor_with_no_valid_reading_is_dead() {
        let found = run(|k| (f64::NAN, 1.0 + k as f64 * 0.01)).expect("dead");
        assert!(found.score.is_infinite());
        assert!(found.detail.contains("dead"), "{}", found.detail);
    }

    #[test]
    fn one_value_across_varied_distances_is_stuck() {
        let found = run(|k| (2.5, 1.0 + (k % 40) as f64 * 0.1)).expect("stuck");
        assert!(found.detail.contains("stuck"), "{}", found.detail);
        // One value where the distances hardly vary (facing one wall) is a reading of it.
        assert!(run(|k| (2.5, 2.5 + (k % 2) as f64 * 0.01)).is_none());
    }
}
