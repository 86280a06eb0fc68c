//! The EM paper's data set drawn from a recording: one sample per lidar revolution, at the
//! instant the beam facing the target was read, with the other sensors and the commanded motion
//! at the same instants.
//!
//! What a sample holds (Alhashimi, Varagnolo, Gustafsson, IEEE Sensors J. 2017, Sec. III–IV):
//!
//! - **lidar** `y^l_k`: the range of the beam at `beam_deg` (lidar frame, default 0 = the
//!   lidar's forward axis) in revolution `k`. An invalid reading (flag set or range ≤ 0) is a
//!   *missing* observation, never a zero.
//! - **commanded displacement** `u_k`: how much the commands say the distance to the target
//!   changed between samples `k` and `k + 1`. `commands.csv` is piecewise constant (each row
//!   holds until the next; before the first row the robot is still); the robot's forward
//!   displacement is `∫ (left + right) / 2 dt`, and since the robot moves along its heading the
//!   distance along the beam changes by `−forward · cos φ`, with `φ` the beam's direction from
//!   the robot's forward axis (`meta.lidar.yaw_deg + beam_deg`). For the default straight-ahead
//!   beam, reversing increases the distance.
//! - **odometer** `y^o_k`: the paper's odometer model (1) maps the true distance to
//!   `α0 + α1 d + β0 e`, so the cumulative wheel travel becomes a distance-like reading:
//!   `y^o_k = start_distance − cos φ · (left_m + right_m) / 2`, linearly interpolated between
//!   encoder readings at the sample instant. Slip then shows as `α1 ≠ 1`.
//! - **sonar** `y^u_k`: the sonar ping nearest in time, if within half the median ping spacing.
//! - **truth** `d_k` (when `truth.csv` and the start distance are known): the start distance
//!   minus the lidar's displacement along its initial beam direction,
//!   `d_k = d_0 − (p(t_k) − p(0)) · e_0`, with `p` the lidar's position (robot pose plus the
//!   mount offset) interpolated in `truth.csv` and `e_0` the unit vector of the beam at t = 0.
//!   Exact for a robot that moves along its beam towards a fixed target, whatever the angle at
//!   which the beam meets the target.
//!
//! The start distance (lidar to target at t = 0) comes from the caller or
//! `meta.world.target_start_distance_m`.

use hilsim_recording::{OdometrySample, Recording, SonarSample, TruthSample};

use crate::{CalibrationError, Metrics};

/// Which beam to follow and what is known of the start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleOptions {
    /// Beam angle in the lidar's frame, degrees (rounded to the nearest whole degree: the XV-11
    /// reads one beam per degree).
    pub beam_deg: f64,
    /// Lidar-to-target distance at t = 0; overrides `meta.world.target_start_distance_m`, which
    /// is used only for the beam straight ahead (it is the frontal target's).
    pub start_distance_m: Option<f64>,
}

impl Default for SampleOptions {
    fn default() -> Self {
        Self {
            beam_deg: 0.0,
            start_distance_m: None,
        }
    }
}

/// One sample per lidar revolution. All vectors have one entry per sample.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetSamples {
    /// Sample instants: when the target-facing beam was read, seconds.
    pub t_s: Vec<f64>,
    /// Commanded change of the distance since t = 0 at each sample, metres (so that
    /// `u_k = commanded_m[k + 1] − commanded_m[k]`).
    pub commanded_m: Vec<f64>,
    /// Lidar range of the beam, metres; `None` where the reading was invalid.
    pub lidar_m: Vec<Option<f64>>,
    /// Change of the distance since t = 0 as the encoders report it
    /// (`−cos φ · (left + right) / 2`), metres; `None` for the table when the recording has no
    /// odometry, per sample when the instant is outside the encoder log.
    pub odometer_travel_m: Option<Vec<Option<f64>>>,
    /// Sonar range, metres; `None` for the table when the recording has no sonar, per sample
    /// when no ping was close enough in time.
    pub sonar_m: Option<Vec<Option<f64>>>,
    /// True distance, metres, when the recording has truth and the start distance is known.
    pub truth_m: Option<Vec<f64>>,
    /// Lidar-to-target distance at t = 0, when known.
    pub start_distance_m: Option<f64>,
    /// `cos φ`: the beam's direction against the robot's forward axis.
    pub beam_cos: f64,
    /// Whether any command turns the robot (left ≠ right): a violation of the straight-line
    /// assumption worth telling the user about.
    pub turns: bool,
}

impl TargetSamples {
    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Whether there are no samples.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// The paper's input `u_k`: commanded change of the distance from sample `k` to `k + 1`
    /// (0 for the last sample).
    #[must_use]
    pub fn u(&self, k: usize) -> f64 {
        if k + 1 < self.len() {
            self.commanded_m[k + 1] - self.commanded_m[k]
        } else {
            0.0
        }
    }

    /// The odometer's distance-like reading `y^o_k = start + travel_k`, when both are known.
    #[must_use]
    pub fn odometer_distance(&self, k: usize) -> Option<f64> {
        let travel = self.odometer_travel_m.as_ref()?[k]?;
        Some(self.start_distance_m? + travel)
    }

    /// Dead reckoning: the distance the commands alone imply, `start + commanded_m[k]`.
    #[must_use]
    pub fn dead_reckoning(&self, k: usize) -> Option<f64> {
        Some(self.start_distance_m? + self.commanded_m[k])
    }

    /// Number of samples with a valid lidar reading.
    #[must_use]
    pub fn lidar_count(&self) -> usize {
        self.lidar_m.iter().filter(|y| y.is_some()).count()
    }
}

/// Draws the samples from a recording.
///
/// # Errors
/// - [`CalibrationError::Missing`]: no lidar table, no reading at the beam, no commands;
/// - [`CalibrationError::Invalid`]: a non-finite value, time going backwards, a non-finite beam
///   or start distance, or a beam that never returns a valid reading (it never sees a target);
/// - [`CalibrationError::Unidentifiable`]: the beam is perpendicular to the motion.
pub fn extract(rec: &Recording, opts: &SampleOptions) -> Result<TargetSamples, CalibrationError> {
    if !opts.beam_deg.is_finite() {
        return Err(CalibrationError::Invalid(format!(
            "beam angle must be finite, got {}",
            opts.beam_deg
        )));
    }
    let beam_index = opts.beam_deg.round().rem_euclid(360.0) as u16;
    // meta.toml's start distance is the frontal target's (interfaces.md): it says nothing about
    // what another beam sees, so another beam needs its own start distance.
    let meta_start = rec
        .meta
        .world
        .target_start_distance_m
        .filter(|_| beam_index == 0);
    let start = match opts.start_distance_m.or(meta_start) {
        Some(d) if d.is_finite() && d > 0.0 => Some(d),
        Some(d) => {
            return Err(CalibrationError::Invalid(format!(
                "start distance must be a positive number of metres, got {d}"
            )))
        }
        None => None,
    };
    let Some(lidar) = rec.lidar.as_ref() else {
        return Err(CalibrationError::Missing(
            "the recording has no lidar.csv: the EM paper's calibration follows a lidar beam"
                .into(),
        ));
    };
    if rec.commands.is_empty() {
        return Err(CalibrationError::Missing(
            "commands.csv is empty: the EM calibration needs the commanded motion".into(),
        ));
    }
    check_finite_commands(rec)?;
    let mount = rec
        .meta
        .lidar
        .clone()
        .unwrap_or(hilsim_recording::LidarMount {
            x_m: 0.0,
            y_m: 0.0,
            yaw_deg: 0.0,
        });
    if ![mount.x_m, mount.y_m, mount.yaw_deg]
        .iter()
        .all(|v| v.is_finite())
    {
        return Err(CalibrationError::Invalid(
            "meta.toml [lidar] mount pose is not finite".into(),
        ));
    }
    let phi = (mount.yaw_deg + f64::from(beam_index)).to_radians();
    let beam_cos = phi.cos();
    // A beam within ~5.7° of perpendicular to the motion sees the distance change by less than
    // a tenth of the travel: the commands no longer pin the distance down.
    if beam_cos.abs() < 0.1 {
        return Err(CalibrationError::Unidentifiable(format!(
            "the beam at {beam_index}° (mount yaw {}°) is perpendicular to the robot's motion: \
             the distance along it does not change as the robot drives",
            mount.yaw_deg
        )));
    }

    let mut t_s = Vec::new();
    let mut lidar_m = Vec::new();
    let mut last_t = f64::NEG_INFINITY;
    let mut last_rev = None;
    for s in lidar.iter().filter(|s| s.angle_deg == beam_index) {
        if !(s.t_s.is_finite() && s.range_m.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "lidar.csv: non-finite value in revolution {} at {}°",
                s.rev, s.angle_deg
            )));
        }
        if s.t_s < last_t {
            return Err(CalibrationError::Invalid(format!(
                "lidar.csv: time goes backwards at revolution {} ({} s after {} s)",
                s.rev, s.t_s, last_t
            )));
        }
        // One sample per revolution: a duplicate row of the same revolution is ignored.
        if last_rev == Some(s.rev) {
            continue;
        }
        last_rev = Some(s.rev);
        last_t = s.t_s;
        t_s.push(s.t_s);
        lidar_m.push((!s.invalid && s.range_m > 0.0).then_some(s.range_m));
    }
    if t_s.is_empty() {
        return Err(CalibrationError::Missing(format!(
            "lidar.csv has no reading at beam {beam_index}°"
        )));
    }
    if lidar_m.iter().all(Option::is_none) {
        return Err(CalibrationError::Invalid(format!(
            "the lidar beam at {beam_index}° never returned a valid reading in {} revolutions: \
             it never sees a target (choose another beam with --beam)",
            t_s.len()
        )));
    }
    // The method follows one target along one beam: a beam that loses it in most revolutions is
    // looking at something else (or at nothing) and would give a confident wrong model.
    let valid = lidar_m.iter().flatten().count();
    if 2 * valid < t_s.len() {
        return Err(CalibrationError::Invalid(format!(
            "the lidar beam at {beam_index}° returned a valid reading in only {valid} of {} \
             revolutions: it does not see one target throughout the run (choose another beam \
             with --beam)",
            t_s.len()
        )));
    }

    let forward = commanded_forward(rec, &t_s);
    let commanded_m: Vec<f64> = forward.iter().map(|f| -beam_cos * f).collect();
    let odometer_travel_m = rec
        .odometry
        .as_deref()
        .map(|odo| interpolate_odometry(odo, &t_s, beam_cos))
        .transpose()?;
    let sonar_m = rec
        .sonar
        .as_deref()
        .map(|sonar| nearest_sonar(sonar, &t_s))
        .transpose()?;
    let truth_m = match (rec.truth.as_deref(), start) {
        (Some(truth), Some(d0)) if !truth.is_empty() => Some(truth_distances(
            truth,
            &t_s,
            d0,
            [mount.x_m, mount.y_m],
            phi,
        )?),
        _ => None,
    };
    let turns = rec
        .commands
        .iter()
        .any(|c| (c.left_mps - c.right_mps).abs() > 1e-9);
    Ok(TargetSamples {
        t_s,
        commanded_m,
        lidar_m,
        odometer_travel_m,
        sonar_m,
        truth_m,
        start_distance_m: start,
        beam_cos,
        turns,
    })
}

fn check_finite_commands(rec: &Recording) -> Result<(), CalibrationError> {
    for (i, c) in rec.commands.iter().enumerate() {
        if !(c.t_s.is_finite() && c.left_mps.is_finite() && c.right_mps.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "commands.csv: non-finite value in row {}",
                i + 1
            )));
        }
        if i > 0 && c.t_s < rec.commands[i - 1].t_s {
            return Err(CalibrationError::Invalid(format!(
                "commands.csv: time goes backwards in row {}",
                i + 1
            )));
        }
    }
    Ok(())
}

/// `F(t) = ∫_0^t (left + right)/2 dt` at each (sorted) instant, with each command held until
/// the next and the robot still before the first.
fn commanded_forward(rec: &Recording, times: &[f64]) -> Vec<f64> {
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
fn interpolate_odometry(
    odo: &[OdometrySample],
    times: &[f64],
    beam_cos: f64,
) -> Result<Vec<Option<f64>>, CalibrationError> {
    for (i, o) in odo.iter().enumerate() {
        if !(o.t_s.is_finite() && o.left_m.is_finite() && o.right_m.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "odometry.csv: non-finite value in row {}",
                i + 1
            )));
        }
        if i > 0 && o.t_s < odo[i - 1].t_s {
            return Err(CalibrationError::Invalid(format!(
                "odometry.csv: time goes backwards in row {}",
                i + 1
            )));
        }
    }
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
fn nearest_sonar(
    sonar: &[SonarSample],
    times: &[f64],
) -> Result<Vec<Option<f64>>, CalibrationError> {
    for (i, s) in sonar.iter().enumerate() {
        if !(s.t_s.is_finite() && s.range_m.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "sonar.csv: non-finite value in row {}",
                i + 1
            )));
        }
        if i > 0 && s.t_s < sonar[i - 1].t_s {
            return Err(CalibrationError::Invalid(format!(
                "sonar.csv: time goes backwards in row {}",
                i + 1
            )));
        }
    }
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
fn truth_distances(
    truth: &[TruthSample],
    times: &[f64],
    start_distance: f64,
    mount_xy: [f64; 2],
    phi: f64,
) -> Result<Vec<f64>, CalibrationError> {
    for (i, s) in truth.iter().enumerate() {
        if !(s.t_s.is_finite() && s.x_m.is_finite() && s.y_m.is_finite() && s.yaw_rad.is_finite()) {
            return Err(CalibrationError::Invalid(format!(
                "truth.csv: non-finite value in row {}",
                i + 1
            )));
        }
        if i > 0 && s.t_s < truth[i - 1].t_s {
            return Err(CalibrationError::Invalid(format!(
                "truth.csv: time goes backwards in row {}",
                i + 1
            )));
        }
    }
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

/// MSE and the EM paper's NMSE (Sec. VI: `NMSE = (1/N) Σ (d̂_k − d_k)² / d_k²`) of raw readings
/// and calibrated estimates against the truth, over the samples where both a raw reading and a
/// finite estimate exist. `None` when there is no such sample.
#[must_use]
pub fn distance_metrics(
    truth: &[f64],
    raw: &[Option<f64>],
    calibrated: &[Option<f64>],
) -> Option<Metrics> {
    let mut n = 0usize;
    let (mut mse_raw, mut mse_cal, mut nmse_raw, mut nmse_cal) = (0.0, 0.0, 0.0, 0.0);
    for ((&d, y), est) in truth.iter().zip(raw).zip(calibrated) {
        let (Some(y), Some(est)) = (y, est) else {
            continue;
        };
        if !(est.is_finite() && d.abs() > 0.0) {
            continue;
        }
        let (er, ec) = ((y - d).powi(2), (est - d).powi(2));
        mse_raw += er;
        mse_cal += ec;
        nmse_raw += er / (d * d);
        nmse_cal += ec / (d * d);
        n += 1;
    }
    (n > 0).then(|| {
        let n = n as f64;
        Metrics {
            mse_raw: mse_raw / n,
            mse_calibrated: mse_cal / n,
            nmse_raw: nmse_raw / n,
            nmse_calibrated: nmse_cal / n,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_recording::{CommandSample, LidarSample, Meta};

    fn rec_with(commands: Vec<CommandSample>, revs: u64) -> Recording {
        let mut rec = Recording::new(Meta::default());
        rec.meta.world.target_start_distance_m = Some(0.5);
        rec.commands = commands;
        rec.lidar = Some(
            (0..revs)
                .map(|r| LidarSample {
                    t_s: r as f64 * 0.2,
                    rev: r,
                    angle_deg: 0,
                    range_m: 1.0,
                    strength: 100,
                    invalid: r == 1,
                    warning: false,
                    true_range_m: None,
                })
                .collect(),
        );
        rec
    }

    #[test]
    fn reversing_increases_the_distance_and_commands_hold_until_the_next() {
        let cmds = vec![
            CommandSample {
                t_s: 0.1,
                left_mps: -0.1,
                right_mps: -0.1,
            },
            CommandSample {
                t_s: 0.5,
                left_mps: 0.0,
                right_mps: 0.0,
            },
        ];
        let s = extract(&rec_with(cmds, 5), &SampleOptions::default()).unwrap();
        // Moving at -0.1 m/s from 0.1 s to 0.5 s: +0.04 m in total, 0.01 m by t = 0.2 s.
        let expect = [0.0, 0.01, 0.03, 0.04, 0.04];
        for (c, e) in s.commanded_m.iter().zip(expect) {
            assert!((c - e).abs() < 1e-12, "{c} vs {e}");
        }
        assert_eq!(
            s.lidar_m[1], None,
            "an invalid reading is missing, not zero"
        );
        assert!((s.u(0) - 0.01).abs() < 1e-12);
        assert_eq!(s.dead_reckoning(4), Some(0.54));
    }

    #[test]
    fn metrics_follow_the_papers_nmse() {
        let m = distance_metrics(
            &[1.0, 2.0],
            &[Some(1.1), Some(2.0)],
            &[Some(1.0), Some(2.2)],
        )
        .unwrap();
        assert!((m.mse_raw - 0.005).abs() < 1e-12);
        assert!((m.nmse_calibrated - 0.5 * 0.04 / 4.0).abs() < 1e-12);
    }
}
