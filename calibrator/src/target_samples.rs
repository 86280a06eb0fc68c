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

mod align;
#[cfg(test)]
mod tests;

use hilsim_recording::{LidarSample, Mount, Recording};

use self::align::{commanded_forward, interpolate_odometry, nearest_sonar, truth_distances};
use crate::{CalibrationError, LidarModelMetrics, Metrics};

/// The start distances a calibration takes: a centimetre (no range sensor reads closer) to a
/// kilometre (a scenario's world is ±1 km). Outside them the model's d² terms lose every digit of
/// the distances' variation.
pub const START_DISTANCE_RANGE_M: std::ops::RangeInclusive<f64> = 0.01..=1e3;

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
    let beam_index = beam_index(opts)?;
    let start = start_distance(rec, opts, beam_index)?;
    let Some(lidar) = rec.lidar.as_ref() else {
        return Err(CalibrationError::Missing(
            "the recording has no lidar.csv: the calibration follows a lidar beam".into(),
        ));
    };
    if rec.commands.is_empty() {
        return Err(CalibrationError::Missing(
            "commands.csv is empty: following the target needs the commanded motion".into(),
        ));
    }
    check_finite_commands(rec)?;
    let beam_index = nearest_beam(lidar, beam_index);
    let (mount, phi) = beam_direction(rec, beam_index)?;
    let beam_cos = phi.cos();
    let (t_s, lidar_m) = beam_readings(lidar, beam_index)?;

    let forward = commanded_forward(rec, &t_s);
    let commanded_m: Vec<f64> = forward.iter().map(|f| -beam_cos * f).collect();
    if let Some(d0) = start {
        // The commands would drive through the target: the start distance is wrong.
        let closest = commanded_m.iter().fold(d0, |m, c| m.min(d0 + c));
        if closest <= 0.0 {
            return Err(CalibrationError::Invalid(format!(
                "start distance {d0:?} m is shorter than the {:?} m the commands drive towards the \
                 target",
                d0 - closest
            )));
        }
    }
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

/// The requested beam angle, degrees in [0, 360).
fn beam_index(opts: &SampleOptions) -> Result<f64, CalibrationError> {
    if !opts.beam_deg.is_finite() {
        return Err(CalibrationError::Invalid(format!(
            "beam angle must be finite, got {}",
            opts.beam_deg
        )));
    }
    Ok(opts.beam_deg.rem_euclid(360.0) % 360.0)
}

/// How far a revolution's reading may be from the beam's angle and still be its reading: a
/// lidar's angles may shift a little from one revolution to the next (each scan has its own
/// start angle), and none that is followed is spaced wider than a degree or two.
const BEAM_TOLERANCE_DEG: f64 = 1.0;

/// The angle between two directions, degrees in [0, 180].
fn angular_distance_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

/// The lidar's angle nearest the requested one (the XV-11's whole degree, another lidar's
/// nearest step); the requested angle when no reading is within [`BEAM_TOLERANCE_DEG`].
fn nearest_beam(lidar: &[LidarSample], requested: f64) -> f64 {
    lidar
        .iter()
        .map(|s| (angular_distance_deg(s.angle_deg, requested), s.angle_deg))
        .filter(|(d, _)| *d <= BEAM_TOLERANCE_DEG)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(requested, |(_, a)| a)
}

/// The start distance: the caller's, else meta.toml's for the beam straight ahead.
fn start_distance(
    rec: &Recording,
    opts: &SampleOptions,
    beam_index: f64,
) -> Result<Option<f64>, CalibrationError> {
    // meta.toml's start distance is the frontal target's (interfaces.md): it says nothing about
    // what another beam sees, so another beam needs its own start distance.
    let meta_start = rec
        .meta
        .world
        .target_start_distance_m
        .filter(|_| angular_distance_deg(beam_index, 0.0) < 0.5);
    match opts.start_distance_m.or(meta_start) {
        Some(d) if START_DISTANCE_RANGE_M.contains(&d) => Ok(Some(d)),
        Some(d) => Err(CalibrationError::Invalid(format!(
            "start distance must be from {} to {} m, got {d:?}",
            START_DISTANCE_RANGE_M.start(),
            START_DISTANCE_RANGE_M.end()
        ))),
        None => Ok(None),
    }
}

/// The lidar mount and the beam's direction φ from the robot's forward axis, radians; a beam
/// (nearly) perpendicular to the motion is an error.
fn beam_direction(rec: &Recording, beam_index: f64) -> Result<(Mount, f64), CalibrationError> {
    let mount = rec.meta.lidar.unwrap_or_default();
    if ![mount.x_m, mount.y_m, mount.yaw_deg]
        .iter()
        .all(|v| v.is_finite())
    {
        return Err(CalibrationError::Invalid(
            "meta.toml [lidar] mount pose is not finite".into(),
        ));
    }
    let phi = (mount.yaw_deg + beam_index).to_radians();
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
    Ok((mount, phi))
}

/// The beam's reading in each revolution (its instant, and its range or `None` when invalid);
/// a beam that never, or only in a minority of revolutions, returns a valid reading is an error.
fn beam_readings(
    lidar: &[LidarSample],
    beam_index: f64,
) -> Result<(Vec<f64>, Vec<Option<f64>>), CalibrationError> {
    let mut t_s = Vec::new();
    let mut lidar_m = Vec::new();
    let mut last_t = f64::NEG_INFINITY;
    let mut last_rev = None;
    for s in beam_of_each_revolution(lidar, beam_index) {
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
    Ok((t_s, lidar_m))
}

/// Each revolution's reading nearest the beam (within [`BEAM_TOLERANCE_DEG`]; the first of
/// equally near ones), in table order.
fn beam_of_each_revolution(
    lidar: &[LidarSample],
    beam_deg: f64,
) -> impl Iterator<Item = &LidarSample> {
    let mut chosen: Vec<&LidarSample> = Vec::new();
    let mut best = f64::INFINITY;
    for s in lidar {
        let d = angular_distance_deg(s.angle_deg, beam_deg);
        if d > BEAM_TOLERANCE_DEG {
            continue;
        }
        match chosen.last() {
            Some(last) if last.rev == s.rev => {
                if d < best {
                    *chosen.last_mut().expect("not empty") = s;
                    best = d;
                }
            }
            _ => {
                chosen.push(s);
                best = d;
            }
        }
    }
    chosen.into_iter()
}

fn check_finite_commands(rec: &Recording) -> Result<(), CalibrationError> {
    align::check_rows(
        "commands.csv",
        rec.commands.iter().map(|c| {
            let finite = c.t_s.is_finite() && c.left_mps.is_finite() && c.right_mps.is_finite();
            (c.t_s, finite)
        }),
    )
}

/// The lidar model alone on the target beam's readings: each raw reading inverted through
/// `alpha` (the landmark paper's eq. 30) against the truth. `None` without a scorable sample or
/// when the model cannot be inverted (it nowhere increases with distance).
#[must_use]
pub fn lidar_model_metrics(
    truth: &[f64],
    raw: &[Option<f64>],
    alpha: &[f64],
) -> Option<LidarModelMetrics> {
    let far = raw.iter().flatten().chain(truth).fold(0.0_f64, |m, v| {
        if v.is_finite() {
            m.max(v.abs())
        } else {
            m
        }
    });
    let inverse = crate::landmarks::Inverse::new(alpha, [0.0, 2.0 * far + 1.0]).ok()?;
    LidarModelMetrics::score(
        truth
            .iter()
            .zip(raw)
            .filter_map(|(&d, y)| y.map(|y| (y, inverse.distance(y), d))),
    )
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
            lidar_model: None,
        }
    })
}
