//! The other sensors, the commands and the truth at the lidar samples' instants (module docs of
//! [`super`]).

use hilsim_recording::{OdometrySample, Recording, SonarSample, TruthSample};

use crate::CalibrationError;

/// `F(t) = ∫_0^t (left + right)/2 dt` at each (sorted) instant, with each command held until
/// the next and the robot still before the first.
pub(super) fn commanded_forward(rec: &Recording, times: &[f64]) -> Vec<f64> {
    let cmds = &rec.commands;
    let mut out = Vec::with_capacity(times.len());
    // Integral up to cmds[i].t_s, advanced lazily.
    let mut i = 0usize;
    let mut integral_at_i = 0.0;
    for &t in times {
        while i + 1 < cmds.len() && cmds[i + 1].t_s <= t {
            let v = (cmds[i].left_mps + cmds[i].right_mps) / 2.0;
            integral_at_i += v * (cmds[i + 1].t_s - cmds[i].t_s);
            i += 1;
        }
        let f = if t <= cmds[0].t_s {
            0.0
        } else {
            let v = (cmds[i].left_mps + cmds[i].right_mps) / 2.0;
            integral_at_i + v * (t - cmds[i].t_s)
        };
        out.push(f);
    }
    out
}

/// Encoder travel along the beam, linearly interpolated at each instant; `None` outside the
/// encoder log (no extrapolation).
pub(super) fn interpolate_odometry(
    odo: &[OdometrySample],
    times: &[f64],
    beam_cos: f64,
) -> Result<Vec<Option<f64>>, CalibrationError> {
    check_rows(
        "odometry.csv",
        odo.iter().map(|o| {
            (
                o.t_s,
                o.t_s.is_finite() && o.left_m.is_finite() && o.right_m.is_finite(),
            )
        }),
    )?;
    let travel = |o: &OdometrySample| -beam_cos * (o.left_m + o.right_m) / 2.0;
    let mut j = 0usize;
    Ok(times
        .iter()
        .map(|&t| {
            let (first, last) = (odo.first()?, odo.last()?);
            if t < first.t_s || t > last.t_s {
                return None;
            }
            while j + 1 < odo.len() && odo[j + 1].t_s <= t {
                j += 1;
            }
            let a = &odo[j];
            match odo.get(j + 1) {
                Some(b) if b.t_s > a.t_s => {
                    let w = (t - a.t_s) / (b.t_s - a.t_s);
                    Some(travel(a) + w * (travel(b) - travel(a)))
                }
                _ => Some(travel(a)),
            }
        })
        .collect())
}

/// The sonar ping nearest each instant, if within half the median ping spacing (so that one
/// ping serves at most the samples around it; a missed echo leaves a gap, not a stale value).
pub(super) fn nearest_sonar(
    sonar: &[SonarSample],
    times: &[f64],
) -> Result<Vec<Option<f64>>, CalibrationError> {
    check_rows(
        "sonar.csv",
        sonar
            .iter()
            .map(|s| (s.t_s, s.t_s.is_finite() && s.range_m.is_finite())),
    )?;
    if sonar.is_empty() {
        return Ok(vec![None; times.len()]);
    }
    let mut gaps: Vec<f64> = sonar.windows(2).map(|w| w[1].t_s - w[0].t_s).collect();
    gaps.sort_by(f64::total_cmp);
    // With a single ping there is no spacing to measure; 0.05 s is half the 10 Hz of an
    // HC-SR04-class sonar.
    let tolerance = gaps
        .get(gaps.len() / 2)
        .map_or(0.05, |g| (g / 2.0).max(1e-6));
    let mut j = 0usize;
    Ok(times
        .iter()
        .map(|&t| {
            while j + 1 < sonar.len() && (sonar[j + 1].t_s - t).abs() <= (sonar[j].t_s - t).abs() {
                j += 1;
            }
            let s = &sonar[j];
            ((s.t_s - t).abs() <= tolerance && s.range_m > 0.0).then_some(s.range_m)
        })
        .collect())
}

/// True distance along the initial beam at each instant (module docs).
pub(super) fn truth_distances(
    truth: &[TruthSample],
    times: &[f64],
    start_distance: f64,
    mount_xy: [f64; 2],
    phi: f64,
) -> Result<Vec<f64>, CalibrationError> {
    check_rows(
        "truth.csv",
        truth.iter().map(|s| {
            (
                s.t_s,
                s.t_s.is_finite()
                    && s.x_m.is_finite()
                    && s.y_m.is_finite()
                    && s.yaw_rad.is_finite(),
            )
        }),
    )?;
    let lidar_at = |s: &TruthSample| {
        let (sin, cos) = s.yaw_rad.sin_cos();
        [
            s.x_m + cos * mount_xy[0] - sin * mount_xy[1],
            s.y_m + sin * mount_xy[0] + cos * mount_xy[1],
        ]
    };
    let first = truth[0];
    let p0 = lidar_at(&first);
    let e0 = [(first.yaw_rad + phi).cos(), (first.yaw_rad + phi).sin()];
    let mut j = 0usize;
    Ok(times
        .iter()
        .map(|&t| {
            while j + 1 < truth.len() && truth[j + 1].t_s <= t {
                j += 1;
            }
            let a = lidar_at(&truth[j]);
            let p = match truth.get(j + 1) {
                Some(next) if next.t_s > truth[j].t_s && t > truth[j].t_s => {
                    let b = lidar_at(next);
                    let w = (t - truth[j].t_s) / (next.t_s - truth[j].t_s);
                    [a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1])]
                }
                _ => a,
            };
            start_distance - ((p[0] - p0[0]) * e0[0] + (p[1] - p0[1]) * e0[1])
        })
        .collect())
}

/// Every row finite and time never going backwards; else the error naming `file` and the row
/// (from 1). `rows`: each row's time and whether all its values are finite.
pub(super) fn check_rows(
    file: &str,
    rows: impl Iterator<Item = (f64, bool)>,
) -> Result<(), CalibrationError> {
    let mut previous = f64::NEG_INFINITY;
    for (i, (t_s, finite)) in rows.enumerate() {
        if !finite {
            return Err(CalibrationError::Invalid(format!(
                "{file}: non-finite value in row {}",
                i + 1
            )));
        }
        if t_s < previous {
            return Err(CalibrationError::Invalid(format!(
                "{file}: time goes backwards in row {}",
                i + 1
            )));
        }
        previous = t_s;
    }
    Ok(())
}
