//! When, in an interval of zero wheel commands, the robot has come to rest: the paper uses only
//! "measurements recorded after the robot reached its new position" (Sec. 3.1), and a real
//! robot's settling time is not known in advance. In order of preference: the settling time the
//! user gives; the odometry, when it is dense enough to see the wheels stop; the scans, when
//! consecutive revolutions stop changing; a default settling time.

use hilsim_recording::{LidarSample, OdometrySample};

/// The settling time when nothing in the recording tells: 0.3 s, three time constants of the
/// 0.1 s motor lag of small differential-drive robots (and of hilsim's default scenario).
pub const DEFAULT_SETTLE_S: f64 = 0.3;

/// The XV-11's nominal revolution (5 Hz), for a recording whose lidar does not tell its own.
const NOMINAL_REVOLUTION_S: f64 = 0.2;

/// Odometry is dense enough to see the wheels stop when its readings are at most this far apart
/// (at 0.15 m/s a wheel moves 1.5 cm in 0.1 s, far above the stand-still speed's 1 mm).
const DENSE_ODOMETRY_S: f64 = 0.1;

/// The window over which the wheels' speed is fitted to decide that they have stopped.
const SPEED_WINDOW_S: f64 = 0.25;

/// How much more two consecutive revolutions may differ than the stop's last two and still be
/// taken as at rest: 1.5× (the median change of ~300 beams scatters by a few per cent), plus
/// 2 mm (the XV-11's millimetre quantisation on both readings).
const SCAN_CHANGE_FACTOR: f64 = 1.5;
const SCAN_CHANGE_SLACK_M: f64 = 0.002;

/// How the start of rest was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RestFrom {
    /// The settling time given (`--settle-s`).
    Given,
    /// The odometry: the wheels' fitted speed fell below the stand-still speed.
    Odometry,
    /// The scans: consecutive revolutions stopped changing.
    ScanStability,
    /// Nothing told: [`DEFAULT_SETTLE_S`] after the command went to zero.
    DefaultSettling,
}

impl RestFrom {
    /// In words, for the notes.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Self::Given => "the settling time given",
            Self::Odometry => "the odometry (wheels stopped)",
            Self::ScanStability => "the scans (consecutive revolutions alike)",
            Self::DefaultSettling => "the default settling time",
        }
    }
}

/// The recording's lidar revolution period: the median time between the starts of consecutive
/// revolutions, or the XV-11's nominal 0.2 s when the lidar has fewer than two.
#[must_use]
pub fn revolution_period_s(lidar: &[LidarSample]) -> f64 {
    let mut starts = Vec::new();
    let mut last_rev = None;
    for s in lidar {
        if last_rev != Some(s.rev) {
            starts.push((s.rev, s.t_s));
            last_rev = Some(s.rev);
        }
    }
    let mut periods: Vec<f64> = starts
        .windows(2)
        .filter(|w| w[1].0 == w[0].0 + 1)
        .map(|w| w[1].1 - w[0].1)
        .filter(|p| p.is_finite() && *p > 0.0)
        .collect();
    if periods.is_empty() {
        return NOMINAL_REVOLUTION_S;
    }
    crate::stats::median(&mut periods)
}

/// When the robot came to rest in the zero-command interval `[t0, t1]`, and how that was found.
/// Dense odometry that never shows the wheels stopped (noisy encoders, a short stop) leaves the
/// answer to the scans; whether the robot really stood is the stop finder's own test over the
/// whole window.
#[must_use]
pub fn rest_start(
    (t0, t1): (f64, f64),
    settle_s: Option<f64>,
    still_speed_mps: f64,
    odometry: Option<&[OdometrySample]>,
    lidar: Option<&[LidarSample]>,
) -> (f64, RestFrom) {
    if let Some(settle) = settle_s {
        return (t0 + settle, RestFrom::Given);
    }
    let from_odometry = odometry.filter(|o| is_dense(o, t0, t1)).and_then(|odo| {
        odo.iter()
            .filter(|s| s.t_s >= t0 && s.t_s < t1)
            .find(|s| {
                let window = (s.t_s, (s.t_s + SPEED_WINDOW_S).min(t1));
                wheel_speed(odo, window).is_some_and(|v| v <= still_speed_mps)
            })
            .map(|s| (s.t_s, RestFrom::Odometry))
    });
    if let Some(rest) = from_odometry {
        return rest;
    }
    if let Some(t) = lidar.and_then(|l| scans_settle(l, t0, t1)) {
        return (t, RestFrom::ScanStability);
    }
    (t0 + DEFAULT_SETTLE_S, RestFrom::DefaultSettling)
}

/// Whether the odometry has at least three readings in `[t0, t1]`, at most
/// [`DENSE_ODOMETRY_S`] apart.
fn is_dense(odo: &[OdometrySample], t0: f64, t1: f64) -> bool {
    let inside: Vec<f64> = odo
        .iter()
        .map(|s| s.t_s)
        .filter(|t| *t >= t0 && *t <= t1)
        .collect();
    inside.len() >= 3 && inside.windows(2).all(|w| w[1] - w[0] <= DENSE_ODOMETRY_S)
}

/// The larger of the two wheels' speeds over `[a, b]`, fitted by least squares (the encoders'
/// noise is per reading, so a slope is far steadier than a difference of two readings); `None`
/// with fewer than three readings.
#[must_use]
pub fn wheel_speed(odo: &[OdometrySample], (a, b): (f64, f64)) -> Option<f64> {
    let window: Vec<&OdometrySample> = odo.iter().filter(|s| s.t_s >= a && s.t_s <= b).collect();
    if window.len() < 3 {
        return None;
    }
    let n = window.len() as f64;
    let tm = window.iter().map(|s| s.t_s).sum::<f64>() / n;
    let stt: f64 = window.iter().map(|s| (s.t_s - tm).powi(2)).sum();
    if stt <= 0.0 {
        return None;
    }
    let slope = |f: fn(&OdometrySample) -> f64| {
        let ym = window.iter().map(|s| f(s)).sum::<f64>() / n;
        window
            .iter()
            .map(|s| (s.t_s - tm) * (f(s) - ym))
            .sum::<f64>()
            / stt
    };
    Some(slope(|s| s.left_m).abs().max(slope(|s| s.right_m).abs()))
}

/// The start of the first whole revolution inside `[t0, t1]` from which every revolution differs
/// from the next no more than the interval's last two do (with [`SCAN_CHANGE_FACTOR`] and
/// [`SCAN_CHANGE_SLACK_M`]); `None` with fewer than three whole revolutions to compare.
fn scans_settle(lidar: &[LidarSample], t0: f64, t1: f64) -> Option<f64> {
    let first = lidar.partition_point(|s| s.t_s < t0);
    let last = lidar.partition_point(|s| s.t_s <= t1);
    let window = &lidar[first..last];
    // Revolutions wholly inside: not the one the window starts or ends inside.
    let starts_inside = |rev: u64| first == 0 || lidar[first - 1].rev != rev;
    let ends_inside = |rev: u64| last == lidar.len() || lidar[last].rev != rev;
    let mut revolutions: Vec<(f64, Vec<(i64, f64)>)> = Vec::new();
    let mut current: Option<u64> = None;
    for s in window
        .iter()
        .filter(|s| starts_inside(s.rev) && ends_inside(s.rev))
    {
        if current != Some(s.rev) {
            current = Some(s.rev);
            revolutions.push((s.t_s, Vec::new()));
        }
        if let Some((_, beams)) = revolutions.last_mut() {
            if !s.invalid && s.range_m > 0.0 && s.range_m.is_finite() {
                beams.push((angle_key(s.angle_deg), s.range_m));
            }
        }
    }
    // The recording's last revolution may be cut short: keep the revolutions of at least half
    // the most readings.
    let most = revolutions.iter().map(|r| r.1.len()).max().unwrap_or(0);
    revolutions.retain(|r| 2 * r.1.len() >= most);
    if revolutions.len() < 3 {
        return None;
    }
    let changes: Vec<Option<f64>> = revolutions
        .windows(2)
        .map(|w| median_change(&w[0].1, &w[1].1))
        .collect();
    let reference = changes.iter().rev().find_map(|c| *c)?;
    let limit = SCAN_CHANGE_FACTOR * reference + SCAN_CHANGE_SLACK_M;
    // The first revolution after the last pair that changed more than the limit.
    let settled_from = changes
        .iter()
        .rposition(|c| c.is_none_or(|c| c > limit))
        .map_or(0, |i| i + 1);
    Some(revolutions[settled_from].0)
}

/// A beam's angle as a key that the same beam of another revolution shares: millidegrees (a
/// lidar's angles repeat from one revolution to the next to far better than that).
fn angle_key(angle_deg: f64) -> i64 {
    (angle_deg * 1e3).round() as i64
}

/// The median over the beams both revolutions read of how much their ranges differ.
fn median_change(a: &[(i64, f64)], b: &[(i64, f64)]) -> Option<f64> {
    let mut by_angle = std::collections::HashMap::with_capacity(a.len());
    for &(angle, r) in a {
        by_angle.insert(angle, r);
    }
    let mut diffs: Vec<f64> = b
        .iter()
        .filter_map(|(angle, r)| by_angle.get(angle).map(|ra| (r - ra).abs()))
        .collect();
    // Fewer than 30 common beams (a lidar facing open space): no evidence either way.
    (diffs.len() >= 30).then(|| crate::stats::median(&mut diffs))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Readings of a 5 Hz lidar from `t0` to `t1`, ranges from `range(t, angle)`.
    fn lidar(t0: f64, t1: f64, range: impl Fn(f64, u16) -> f64) -> Vec<LidarSample> {
        let dt = 0.2 / 360.0;
        let mut out = Vec::new();
        let mut i = 0u64;
        loop {
            let t = t0 + i as f64 * dt;
            if t > t1 {
                break;
            }
            let angle = (i % 360) as u16;
            out.push(LidarSample {
                t_s: t,
                rev: i / 360,
                angle_deg: f64::from(angle),
                range_m: range(t, angle),
                strength: 100,
                invalid: false,
                warning: false,
                true_range_m: None,
            });
            i += 1;
        }
        out
    }

    /// A wobble no two revolutions share, of about `size` metres.
    fn noise(t: f64, angle: u16, size: f64) -> f64 {
        let x = (t * 1e4).sin() * 43_758.545 + f64::from(angle) * 12.9898;
        size * (x.sin() * 2.0)
    }

    #[test]
    fn the_period_is_measured_from_the_revolutions() {
        let l = lidar(0.0, 2.0, |_, _| 2.0);
        assert!((revolution_period_s(&l) - 0.2).abs() < 1e-9);
        assert_eq!(revolution_period_s(&[]), NOMINAL_REVOLUTION_S);
    }

    /// The robot keeps moving (ranges change 3 cm a revolution) until 0.5 s into the stop, then
    /// stands: rest is found within a revolution of it.
    #[test]
    fn rest_is_found_where_the_scans_stop_changing() {
        let l = lidar(0.0, 3.0, |t, a| {
            let drift = 0.15 * (t.min(1.5) - 1.0).max(0.0);
            2.0 + drift * f64::from(a).to_radians().cos() + noise(t, a, 0.004)
        });
        let (t, from) = rest_start((1.0, 3.0), None, 0.01, None, Some(&l));
        assert_eq!(from, RestFrom::ScanStability);
        assert!((1.4..=1.81).contains(&t), "{t}");
    }

    /// Already at rest when the command goes to zero: the first whole revolution.
    #[test]
    fn a_robot_already_at_rest_is_used_from_the_first_whole_revolution() {
        let l = lidar(0.0, 2.0, |t, a| 2.0 + noise(t, a, 0.004));
        let (t, from) = rest_start((1.0, 2.0), None, 0.01, None, Some(&l));
        assert_eq!(from, RestFrom::ScanStability);
        assert!((1.0..=1.2).contains(&t), "{t}");
    }

    #[test]
    fn dense_odometry_tells_when_the_wheels_stopped() {
        // 50 Hz odometry; the wheels move at 0.15 m/s until 1.4 s, then stand.
        let odo: Vec<OdometrySample> = (0..150)
            .map(|i| {
                let t = f64::from(i) * 0.02;
                let d = 0.15 * t.min(1.4);
                OdometrySample {
                    t_s: t,
                    left_m: d,
                    right_m: d,
                }
            })
            .collect();
        let (t, from) = rest_start((1.0, 3.0), None, 0.01, Some(&odo), None);
        assert_eq!(from, RestFrom::Odometry);
        // Within the speed window's reach of the stop (3 mm of travel left at most).
        assert!((1.35..=1.41).contains(&t), "{t}");
        // Never at rest in the interval: left to the scans (here none: the default).
        assert_eq!(
            rest_start((0.5, 1.3), None, 0.01, Some(&odo), None).1,
            RestFrom::DefaultSettling
        );
    }

    #[test]
    fn a_given_settling_time_wins_and_nothing_falls_back_to_the_default() {
        assert_eq!(
            rest_start((1.0, 3.0), Some(0.5), 0.01, None, None),
            (1.5, RestFrom::Given)
        );
        assert_eq!(
            rest_start((1.0, 3.0), None, 0.01, None, None),
            (1.0 + DEFAULT_SETTLE_S, RestFrom::DefaultSettling)
        );
    }
}
