//! Residuals: every sensor's readings against the simulation's prediction, under the scenario's
//! declared noise model. Each reading gets a predictive distribution (a Gaussian, or a mixture
//! where the lidar's direction noise reaches an edge), a small uniform outlier component, and
//! from them a log-likelihood, a residual in metres and a normal score (the probability integral
//! transform: `z = Φ⁻¹(F(y))`, standard normal when the prediction is right).
//!
//! The readings are split in time into training and held-out halves: alternate 2 s blocks (a
//! lidar revolution goes with the block its start falls in), so both halves see the whole run
//! (the warm-up, every manoeuvre) and the held-out half is never fitted.

use hilsim_recording::Recording;

use crate::catalogue::Sensor;
use crate::error::MismatchError;
use crate::physics::{DeclaredActuation, Gaussian, Hypothesis, LidarQuery, Physics};
use crate::stats::normal_quantile;
use crate::trajectory::Trajectory;

/// Length of the alternating training / held-out blocks, seconds.
pub const SPLIT_BLOCK_S: f64 = 2.0;
/// Window of the drive's residuals (wheel travel increments), seconds.
pub const DRIVE_WINDOW_S: f64 = 0.1;
/// Margin around a contact of the replayed robot in which the drive is not compared, seconds.
const CONTACT_MARGIN_S: f64 = 0.5;
/// Normal scores are clipped here, so one wild reading cannot dominate a test.
pub const Z_CLIP: f64 = 6.0;

/// A variable the residuals are tested against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Covariate {
    /// The true range, metres.
    Range,
    /// The beam's angle in the lidar frame, degrees.
    Bearing,
    /// The angle of incidence on the surface, degrees.
    Incidence,
    /// The object the beam hit (categorical).
    Object,
    /// Whether the beam's direction noise reaches an edge (0 or 1).
    Edge,
    /// Time since the recording's start, seconds.
    Time,
    /// The robot's forward speed, m/s (absolute).
    Speed,
    /// The robot's acceleration, m/s² (absolute).
    Accel,
    /// The robot's turn rate, degrees per second (absolute).
    TurnRate,
    /// The wheel's speed, m/s (signed).
    WheelSpeed,
    /// How much nearer than the axis an echo within 30° of it is, metres.
    OffAxisNearer,
    /// Time since the wheel command last changed, seconds.
    SinceCommand,
}

impl Covariate {
    /// Its name in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Covariate::Range => "range",
            Covariate::Bearing => "bearing",
            Covariate::Incidence => "incidence angle",
            Covariate::Object => "object",
            Covariate::Edge => "edge",
            Covariate::Time => "time",
            Covariate::Speed => "speed",
            Covariate::Accel => "acceleration",
            Covariate::TurnRate => "turn rate",
            Covariate::WheelSpeed => "wheel speed",
            Covariate::OffAxisNearer => "off-axis echo nearer by",
            Covariate::SinceCommand => "time since a command change",
        }
    }

    /// Its unit in reports.
    #[must_use]
    pub fn unit(self) -> &'static str {
        match self {
            Covariate::Range | Covariate::OffAxisNearer => "m",
            Covariate::Bearing | Covariate::Incidence => "deg",
            Covariate::Object | Covariate::Edge => "",
            Covariate::Time | Covariate::SinceCommand => "s",
            Covariate::Speed | Covariate::WheelSpeed => "m/s",
            Covariate::Accel => "m/s²",
            Covariate::TurnRate => "deg/s",
        }
    }

    /// Whether its values are categories rather than quantities.
    #[must_use]
    pub fn categorical(self) -> bool {
        matches!(self, Covariate::Object | Covariate::Edge)
    }

    /// Whether it describes the robot's motion (reported as "while …").
    #[must_use]
    pub fn is_motion(self) -> bool {
        matches!(
            self,
            Covariate::Speed
                | Covariate::Accel
                | Covariate::TurnRate
                | Covariate::WheelSpeed
                | Covariate::SinceCommand
        )
    }
}

/// What to ask the physics for a sensor's readings.
#[derive(Debug, Clone)]
pub(crate) enum Queries {
    Lidar(Vec<LidarQuery>),
    Sonar(Vec<f64>),
    /// One reading time per pair of rows (left, right).
    Odometer(Vec<f64>),
    /// One window per pair of rows (left, right).
    Drive(Vec<(f64, f64)>),
}

/// One sensor's readings, ready to be predicted.
#[derive(Debug, Clone)]
pub(crate) struct SensorData {
    pub sensor: Sensor,
    pub t: Vec<f64>,
    pub y: Vec<f64>,
    pub heldout: Vec<bool>,
    pub covariates: Vec<(Covariate, Vec<f64>)>,
    pub queries: Queries,
    /// Weight of the uniform outlier component.
    pub epsilon: f64,
    /// Its density: ε over the span readings can take.
    pub outlier_density: f64,
    /// Groups of readings that share an error (of an estimated trajectory), by row; `None`:
    /// every reading's error is its own.
    pub clusters: Option<Vec<u32>>,
}

/// One reading's predictive distribution (empty: no reading expected).
pub(crate) type Predictive = Vec<Gaussian>;

impl SensorData {
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// Row indices of one half (`heldout`) or of both (`None`).
    pub fn rows(&self, half: Option<bool>) -> Vec<usize> {
        (0..self.len())
            .filter(|&i| half.is_none_or(|h| self.heldout[i] == h))
            .collect()
    }

    pub fn covariate(&self, c: Covariate) -> Option<&[f64]> {
        self.covariates
            .iter()
            .find(|(k, _)| *k == c)
            .map(|(_, v)| v.as_slice())
    }
}

/// What the diagnosis holds while it works: the physics, the aligned trajectory, the commands.
pub(crate) struct Context<'a> {
    pub physics: &'a dyn Physics,
    pub trajectory: &'a Trajectory,
    pub recording: &'a Recording,
    pub end_s: f64,
    /// The trajectory's position noise, metres (widens the drive's and encoders' residuals,
    /// and those of the lidar and sonar when the trajectory is estimated).
    pub position_sd_m: f64,
    /// The trajectory's heading noise, radians (0 for a recorded one).
    pub yaw_sd_rad: f64,
    /// Whether the trajectory is estimated (its errors then widen every range).
    pub estimated: bool,
}

impl Context<'_> {
    /// Widens range predictions by the estimated trajectory's uncertainty: its position error
    /// along the beam and its heading error times the range.
    fn widen(&self, mut g: Gaussian) -> Gaussian {
        if self.estimated {
            let extra = self.position_sd_m.powi(2) + (g.mean_m * self.yaw_sd_rad).powi(2);
            g.sd_m = (g.sd_m * g.sd_m + extra).sqrt();
        }
        g
    }
}

impl Context<'_> {
    /// The predictive distributions of `rows` of `data` under `h`.
    pub fn predict(&self, data: &SensorData, h: &Hypothesis, rows: &[usize]) -> Vec<Predictive> {
        match &data.queries {
            Queries::Lidar(q) => {
                let qs: Vec<LidarQuery> = rows.iter().map(|&i| q[i]).collect();
                self.physics
                    .lidar(self.trajectory, &qs, h)
                    .into_iter()
                    .map(|p| p.components.into_iter().map(|g| self.widen(g)).collect())
                    .collect()
            }
            Queries::Sonar(times) => {
                let ts: Vec<f64> = rows.iter().map(|&i| times[i]).collect();
                self.physics
                    .sonar(self.trajectory, &ts, h)
                    .into_iter()
                    .map(|p| p.reading.into_iter().map(|g| self.widen(g)).collect())
                    .collect()
            }
            Queries::Odometer(times) => {
                let ts: Vec<f64> = rows.iter().map(|&i| times[i / 2]).collect();
                let preds = self.physics.odometry(self.trajectory, &ts, h);
                // The trajectory's own position noise enters each wheel's travel.
                let extra = self.position_sd_m * self.position_sd_m;
                rows.iter()
                    .zip(preds)
                    .map(|(&i, p)| {
                        let mut g = p.wheels[i % 2];
                        g.sd_m = (g.sd_m * g.sd_m + extra).sqrt();
                        vec![g]
                    })
                    .collect()
            }
            Queries::Drive(windows) => {
                let predicted = self.physics.drive(&self.recording.commands, self.end_s, h);
                let Ok(path) = Trajectory::new(&predicted) else {
                    return rows.iter().map(|_| Vec::new()).collect();
                };
                let travel = path.wheel_travel(self.physics.declared().wheel_base_m);
                let increments: Vec<f64> = (0..data.len())
                    .map(|i| {
                        let (a, b) = windows[i / 2];
                        let (wa, wb) = (path.interpolate(&travel, a), path.interpolate(&travel, b));
                        wb[i % 2] - wa[i % 2]
                    })
                    .collect();
                // Two differences of the trajectory's positions per window.
                let noise_var = 2.0 * self.position_sd_m * self.position_sd_m;
                let starts: Vec<f64> = windows.iter().map(|w| w.0).collect();
                let all = drive_predictions(
                    &increments,
                    &data.y,
                    &starts,
                    self.physics.declared().actuation,
                    noise_var,
                );
                rows.iter().map(|&i| vec![all[i]]).collect()
            }
        }
    }
}

/// The one-step predictive distributions of the wheels' travel over each window (rows: window
/// `i / 2`, wheel `i % 2`, in time order), given the travel the commands give (`increments`),
/// the real travel (`y`) and the declared actuation error.
///
/// The actuation error is one scale factor on both wheels, `1 + f + w(t)`: `f` fixed for the
/// run, `w` an Ornstein–Uhlenbeck wander. It is correlated across every window, so the windows'
/// residuals against the commands alone are not independent: a run whose fixed error happens
/// to be 2 % would show as a bias in every window. A Kalman filter on `(f, w)` conditions each
/// window on the windows before it; its innovations are independent, with the variances it
/// predicts, exactly when the drive is as declared (the prediction-error decomposition of the
/// likelihood: Shumway & Stoffer, *Time Series Analysis and Its Applications*, §6.2). With an
/// ideal drive the filter's state stays at zero and this is the commands' travel itself.
fn drive_predictions(
    increments: &[f64],
    y: &[f64],
    starts: &[f64],
    actuation: DeclaredActuation,
    noise_var: f64,
) -> Vec<Gaussian> {
    let noise_var = noise_var.max(1e-12);
    // Discrete OU from one window to the next (`dt` apart): w' = a w + √(1 − a²) σ_w e.
    let decay = |dt: f64| {
        if actuation.wander_tau_s > 0.0 {
            (-dt / actuation.wander_tau_s).exp()
        } else {
            0.0
        }
    };
    // State (f, w) and its covariance [[pff, pfw], [pfw, pww]].
    let (mut f, mut w) = (0.0, 0.0);
    let (mut pff, mut pfw, mut pww) =
        (actuation.scale_sd.powi(2), 0.0, actuation.wander_sd.powi(2));
    let mut out = Vec::with_capacity(increments.len());
    for (i, (&inc, &real)) in increments.iter().zip(y).enumerate() {
        if i % 2 == 0 && i > 0 {
            let a = decay(starts[i / 2] - starts[i / 2 - 1]);
            w *= a;
            pfw *= a;
            pww = a * a * pww + actuation.wander_sd.powi(2) * (1.0 - a * a);
        }
        // Observation: real = inc (1 + f + w) + noise.
        let mean = inc * (1.0 + f + w);
        let (hf, hw) = (inc, inc);
        let (phf, phw) = (pff * hf + pfw * hw, pfw * hf + pww * hw);
        let var = hf * phf + hw * phw + noise_var;
        out.push(Gaussian::new(1.0, mean, var.sqrt()));
        let innovation = real - mean;
        // A reading far outside its prediction (an outlier to the model) does not steer the
        // state: that is the outlier component's business.
        if innovation.is_finite() && innovation.abs() <= 5.0 * var.sqrt() {
            let (kf, kw) = (phf / var, phw / var);
            f += kf * innovation;
            w += kw * innovation;
            pff -= kf * phf;
            pfw -= kf * phw;
            pww -= kw * phw;
        }
    }
    out
}

/// How well one prediction fits one reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Fit {
    /// Log-likelihood of the reading.
    pub ll: f64,
    /// Normal score (probability integral transform), clipped to ±[`Z_CLIP`].
    pub z: f64,
    /// Reading minus the mean of the component that explains it best, metres (NaN: no
    /// prediction).
    pub residual: f64,
    /// That component's standard deviation, metres.
    pub sd: f64,
    /// Whether the outlier component explains the reading better than the prediction does
    /// (posterior probability above ½).
    pub outlier: bool,
}

/// The fit of reading `y` to `pred` with an outlier component of weight `epsilon` and density
/// `outlier_density`.
pub(crate) fn fit(y: f64, pred: &[Gaussian], epsilon: f64, outlier_density: f64) -> Fit {
    if pred.is_empty() {
        // Nothing was expected: only the outlier component explains it.
        return Fit {
            ll: outlier_density.ln(),
            z: Z_CLIP,
            residual: f64::NAN,
            sd: f64::NAN,
            outlier: true,
        };
    }
    let mut density = 0.0;
    let mut cdf = 0.0;
    let mut best = (f64::NEG_INFINITY, 0usize);
    for (k, g) in pred.iter().enumerate() {
        let ln = g.weight.ln() + g.ln_density(y);
        density += ln.exp();
        cdf += g.weight * g.cdf(y);
        if ln > best.0 {
            best = (ln, k);
        }
    }
    let total = (1.0 - epsilon) * density + outlier_density;
    let ll = if total > 0.0 {
        total.ln()
    } else {
        f64::MIN_POSITIVE.ln()
    };
    // The uniform part's CDF is taken as ½ (its span is not centred on the reading): it adds at
    // most ε/2 to the probability, 0.001 here, invisible in the tests.
    let u = ((1.0 - epsilon) * cdf + epsilon * 0.5).clamp(1e-300, 1.0 - 1e-16);
    let (mean, sd) = pred[best.1].moments();
    Fit {
        ll,
        z: normal_quantile(u).clamp(-Z_CLIP, Z_CLIP),
        residual: y - mean,
        sd,
        outlier: outlier_density > (1.0 - epsilon) * density,
    }
}

/// The log-likelihood of reading `y` alone (what the fits maximise; no normal score).
pub(crate) fn log_likelihood(y: f64, pred: &[Gaussian], epsilon: f64, outlier_density: f64) -> f64 {
    let density: f64 = pred.iter().map(|g| g.weight * g.ln_density(y).exp()).sum();
    let total = (1.0 - epsilon) * density + outlier_density;
    if total > 0.0 {
        total.ln()
    } else {
        f64::MIN_POSITIVE.ln()
    }
}

/// The fits of `rows` of `data` under predictions `preds` (one per row).
pub(crate) fn fits(data: &SensorData, rows: &[usize], preds: &[Predictive]) -> Vec<Fit> {
    rows.iter()
        .zip(preds)
        .map(|(&i, p)| fit(data.y[i], p, data.epsilon, data.outlier_density))
        .collect()
}

/// Root mean square of the residuals of `fits` that have one (and that `keep` keeps), and the
/// noise floor there (the root mean square of the predicted standard deviations).
pub(crate) fn rmse(fits: &[Fit], keep: impl Fn(usize) -> bool) -> (f64, f64, usize) {
    let (mut se, mut var, mut n) = (0.0, 0.0, 0usize);
    for (i, f) in fits.iter().enumerate() {
        if f.residual.is_finite() && keep(i) {
            se += f.residual * f.residual;
            var += f.sd * f.sd;
            n += 1;
        }
    }
    if n == 0 {
        return (f64::NAN, f64::NAN, 0);
    }
    ((se / n as f64).sqrt(), (var / n as f64).sqrt(), n)
}

fn split(t: f64) -> bool {
    ((t / SPLIT_BLOCK_S).floor() as i64).rem_euclid(2) == 1
}

/// Forward acceleration magnitude at `t` from the trajectory's speeds 50 ms either side.
fn accel_at(tr: &Trajectory, t: f64) -> f64 {
    let (a, _) = tr.twist_at(t - 0.05);
    let (b, _) = tr.twist_at(t + 0.05);
    ((b - a) / 0.1).abs()
}

/// The motion covariates at `t`.
fn motion(tr: &Trajectory, t: f64) -> [f64; 3] {
    let (v, w) = tr.twist_at(t);
    [v.abs(), accel_at(tr, t), w.abs().to_degrees()]
}

/// The lidar's valid readings.
pub(crate) fn lidar(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let (Some(samples), Some(declared)) = (&ctx.recording.lidar, ctx.physics.declared().lidar)
    else {
        return Ok(None);
    };
    // Each revolution's start: the timestamp of its reading 0, or extrapolated from its first
    // reading at the nominal reading period.
    let period = 60.0 / (declared.rpm * 360.0);
    let mut rev_start = std::collections::HashMap::new();
    for s in samples {
        rev_start
            .entry(s.rev)
            .or_insert(s.t_s - f64::from(s.angle_deg) * period);
    }
    let valid: Vec<_> = samples
        .iter()
        .filter(|s| !s.invalid && s.range_m > 0.0 && s.t_s <= ctx.end_s)
        .collect();
    let queries: Vec<LidarQuery> = valid
        .iter()
        .map(|s| LidarQuery {
            t_s: s.t_s,
            rev_start_s: rev_start[&s.rev],
            angle_deg: f64::from(s.angle_deg),
        })
        .collect();
    let nominal = ctx
        .physics
        .lidar(ctx.trajectory, &queries, &Hypothesis::nominal());
    let mut cov: Vec<(Covariate, Vec<f64>)> = [
        Covariate::Range,
        Covariate::Bearing,
        Covariate::Incidence,
        Covariate::Object,
        Covariate::Edge,
        Covariate::Time,
        Covariate::Speed,
        Covariate::Accel,
        Covariate::TurnRate,
    ]
    .into_iter()
    .map(|c| (c, Vec::with_capacity(valid.len())))
    .collect();
    for (q, p) in queries.iter().zip(&nominal) {
        let m = motion(ctx.trajectory, q.t_s);
        let values = [
            p.true_range_m.unwrap_or(f64::NAN),
            q.angle_deg,
            if p.true_range_m.is_some() {
                p.incidence_deg
            } else {
                f64::NAN
            },
            p.object.map_or(f64::NAN, f64::from),
            f64::from(u8::from(p.near_edge)),
            q.t_s,
            m[0],
            m[1],
            m[2],
        ];
        for ((_, col), v) in cov.iter_mut().zip(values) {
            col.push(v);
        }
    }
    Ok(Some(SensorData {
        sensor: Sensor::Lidar,
        t: valid.iter().map(|s| s.t_s).collect(),
        y: valid.iter().map(|s| s.range_m).collect(),
        heldout: queries.iter().map(|q| split(q.rev_start_s)).collect(),
        covariates: cov,
        queries: Queries::Lidar(queries),
        epsilon: 0.002,
        outlier_density: 0.002 / declared.max_range_m,
        clusters: None,
    }))
}

/// The sonar's pings.
pub(crate) fn sonar(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let (Some(samples), Some(_)) = (
        &ctx.recording.sonar,
        ctx.physics.declared().sonar_half_angle_deg,
    ) else {
        return Ok(None);
    };
    let rows: Vec<_> = samples
        .iter()
        .filter(|s| s.range_m.is_finite() && s.t_s <= ctx.end_s)
        .collect();
    let times: Vec<f64> = rows.iter().map(|s| s.t_s).collect();
    let nominal = ctx
        .physics
        .sonar(ctx.trajectory, &times, &Hypothesis::nominal());
    let mut cov: Vec<(Covariate, Vec<f64>)> = [
        Covariate::Range,
        Covariate::OffAxisNearer,
        Covariate::Time,
        Covariate::Speed,
        Covariate::TurnRate,
    ]
    .into_iter()
    .map(|c| (c, Vec::new()))
    .collect();
    for (s, p) in rows.iter().zip(&nominal) {
        let m = motion(ctx.trajectory, s.t_s);
        let axis = p.true_range_m.unwrap_or(f64::INFINITY);
        let nearer = p.wide_cone_m.map_or(0.0, |w| (axis - w).clamp(0.0, 5.0));
        let values = [
            p.true_range_m.unwrap_or(s.range_m),
            nearer,
            s.t_s,
            m[0],
            m[2],
        ];
        for ((_, col), v) in cov.iter_mut().zip(values) {
            col.push(v);
        }
    }
    Ok(Some(SensorData {
        sensor: Sensor::Sonar,
        t: times.clone(),
        y: rows.iter().map(|s| s.range_m).collect(),
        heldout: times.iter().map(|&t| split(t)).collect(),
        covariates: cov,
        queries: Queries::Sonar(times),
        epsilon: 0.002,
        outlier_density: 0.002 / 5.0,
        clusters: None,
    }))
}

/// The encoders' readings: two rows (left, right) per reading.
pub(crate) fn odometer(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let (Some(samples), true) = (&ctx.recording.odometry, ctx.physics.declared().odometer) else {
        return Ok(None);
    };
    let rows: Vec<_> = samples.iter().filter(|s| s.t_s <= ctx.end_s).collect();
    let times: Vec<f64> = rows.iter().map(|s| s.t_s).collect();
    let tr = ctx.trajectory;
    let travel = tr.wheel_travel(ctx.physics.declared().wheel_base_m);
    let speed = |t: f64, wheel: usize| {
        let k = tr.interval(t);
        let dt = tr.times().get(k + 1).map_or(1.0, |t1| t1 - tr.times()[k]);
        travel
            .get(k + 1)
            .map_or(0.0, |next| (next[wheel] - travel[k][wheel]) / dt)
    };
    let mut t = Vec::new();
    let mut y = Vec::new();
    let mut cov: Vec<(Covariate, Vec<f64>)> = [
        Covariate::WheelSpeed,
        Covariate::Accel,
        Covariate::Time,
        Covariate::TurnRate,
    ]
    .into_iter()
    .map(|c| (c, Vec::new()))
    .collect();
    for s in &rows {
        for wheel in 0..2 {
            t.push(s.t_s);
            y.push(if wheel == 0 { s.left_m } else { s.right_m });
            let v = speed(s.t_s, wheel);
            let a = (speed(s.t_s + 0.05, wheel) - speed(s.t_s - 0.05, wheel)) / 0.1;
            let values = [v, a.abs(), s.t_s, motion(tr, s.t_s)[2]];
            for ((_, col), v) in cov.iter_mut().zip(values) {
                col.push(v);
            }
        }
    }
    Ok(Some(SensorData {
        sensor: Sensor::Odometer,
        heldout: t.iter().map(|&t| split(t)).collect(),
        t,
        y,
        covariates: cov,
        queries: Queries::Odometer(times),
        epsilon: 1e-4,
        outlier_density: 1e-4 / 1.0,
        clusters: None,
    }))
}

/// The drive: the wheels' travel over 0.1 s windows along the aligned trajectory, against the
/// travel the commands give.
pub(crate) fn drive(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let commands = &ctx.recording.commands;
    if commands.is_empty() {
        return Ok(None);
    }
    let tr = ctx.trajectory;
    let travel = tr.wheel_travel(ctx.physics.declared().wheel_base_m);
    let n = (ctx.end_s / DRIVE_WINDOW_S).floor() as usize;
    let mut windows = Vec::with_capacity(n);
    let (mut t, mut y) = (Vec::new(), Vec::new());
    let mut cov: Vec<(Covariate, Vec<f64>)> = [
        Covariate::WheelSpeed,
        Covariate::SinceCommand,
        Covariate::Time,
        Covariate::TurnRate,
    ]
    .into_iter()
    .map(|c| (c, Vec::new()))
    .collect();
    let half_base = ctx.physics.declared().wheel_base_m / 2.0;
    // Where the robot touches an obstacle its wheels' travel is the contact's doing (and the
    // real run meets it a little earlier or later, or another simulator resolves it otherwise):
    // those windows, with a margin, are not the drive's evidence.
    let contacts = ctx.physics.drive_contacts(commands, ctx.end_s);
    let touching = |a: f64, b: f64| {
        contacts
            .iter()
            .any(|&(from, to)| a < to + CONTACT_MARGIN_S && b > from - CONTACT_MARGIN_S)
    };
    for k in 0..n {
        let (a, b) = (k as f64 * DRIVE_WINDOW_S, (k + 1) as f64 * DRIVE_WINDOW_S);
        if touching(a, b) {
            continue;
        }
        windows.push((a, b));
        let (wa, wb) = (tr.interpolate(&travel, a), tr.interpolate(&travel, b));
        // The command in force at the window's start, and how long it has been.
        let i = commands.partition_point(|c| c.t_s <= a + 1e-9);
        let (cmd, since) = match i.checked_sub(1).map(|j| commands[j]) {
            Some(c) => (c, a - c.t_s),
            None => (
                hilsim_recording::CommandSample {
                    t_s: 0.0,
                    left_mps: 0.0,
                    right_mps: 0.0,
                },
                a,
            ),
        };
        let turn = ((cmd.right_mps - cmd.left_mps) / (2.0 * half_base))
            .abs()
            .to_degrees();
        for wheel in 0..2 {
            t.push(a);
            y.push(wb[wheel] - wa[wheel]);
            let speed = if wheel == 0 {
                cmd.left_mps
            } else {
                cmd.right_mps
            };
            let values = [speed, since, a, turn];
            for ((_, col), v) in cov.iter_mut().zip(values) {
                col.push(v);
            }
        }
    }
    if windows.is_empty() {
        return Ok(None);
    }
    Ok(Some(SensorData {
        sensor: Sensor::Drive,
        heldout: t.iter().map(|&t| split(t)).collect(),
        t,
        y,
        covariates: cov,
        queries: Queries::Drive(windows),
        epsilon: 1e-4,
        outlier_density: 1e-4 / 0.5,
        clusters: None,
    }))
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_calibrator::landmarks::monte_carlo::Xoshiro256pp;
    use rand::Rng;
    use rand_distr::StandardNormal;

    /// A drive whose fixed scale error is 2 σ of the declared one (4 %): against the commands
    /// alone every moving window is biased the same way; the filter's innovations, standardised,
    /// are mean-zero unit-variance noise. 2,000 windows of two wheels: the standard error of the
    /// mean of 4,000 unit scores is 0.016, so 0.08 is 5 SE; of their mean square, 0.022, so the
    /// ±0.15 band is ~7 SE.
    #[test]
    fn the_drive_filter_whitens_a_declared_actuation_error() {
        let actuation = DeclaredActuation {
            scale_sd: 0.02,
            wander_sd: 0.01,
            wander_tau_s: 10.0,
        };
        let mut rng = Xoshiro256pp::seed_from_u64(3);
        let noise_sd = 0.001_f64;
        let (mut wander, a) = (0.0_f64, (-DRIVE_WINDOW_S / 10.0).exp());
        let (mut increments, mut y) = (Vec::new(), Vec::new());
        for k in 0..2000 {
            wander =
                a * wander + 0.01 * (1.0 - a * a).sqrt() * rng.sample::<f64, _>(StandardNormal);
            // Moving and standing in turns of 5 s; the wheels at 0.3 and 0.2 m/s.
            let moving = (k / 50) % 2 == 0;
            for speed in [0.03, 0.02] {
                let inc = if moving { speed } else { 0.0 };
                increments.push(inc);
                let noise: f64 = rng.sample(StandardNormal);
                y.push(inc * (1.0 + 0.04 + wander) + noise_sd * noise);
            }
        }
        let scores = |preds: &[Gaussian]| -> (f64, f64) {
            let z: Vec<f64> = preds
                .iter()
                .zip(&y)
                .map(|(g, y)| (y - g.mean_m) / g.sd_m)
                .collect();
            let n = z.len() as f64;
            (
                z.iter().sum::<f64>() / n,
                z.iter().map(|z| z * z).sum::<f64>() / n,
            )
        };
        let var = noise_sd * noise_sd;
        let starts: Vec<f64> = (0..2000).map(|k| f64::from(k) * DRIVE_WINDOW_S).collect();
        let (mean, msq) = scores(&drive_predictions(&increments, &y, &starts, actuation, var));
        assert!(mean.abs() < 0.08, "mean score {mean}");
        assert!((msq - 1.0).abs() < 0.15, "mean square {msq}");
        // The same data against the commands alone (an ideal drive declared): far from noise.
        let (mean, _) = scores(&drive_predictions(
            &increments,
            &y,
            &starts,
            DeclaredActuation::default(),
            var,
        ));
        assert!(mean > 0.3, "mean score against the commands alone {mean}");
    }
}
