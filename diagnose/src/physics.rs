//! The physics the diagnosis asks about, behind a small trait: what the scenario's sensors
//! should read from a trajectory, and where its robot goes under recorded commands — nominally,
//! or with one catalogued effect switched on with given parameters. `hilsim` implements it from
//! the simulator (`hilsim-sim`, `hilsim-lidar-emulator`); this crate never depends on them (or on
//! rapier), so the statistics here would work with any simulator that implements the trait.

use hilsim_recording::{CommandSample, TruthSample};

use crate::catalogue::Effect;
use crate::stats::{ln_normal_pdf, normal_cdf, normal_sf};
use crate::trajectory::{Pose2, Trajectory};

/// A model to predict with: the nominal one, or the nominal one with one effect switched on
/// with `params` (in the order of [`Effect::params`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Hypothesis {
    /// The effect switched on; `None`: the nominal model.
    pub effect: Option<Effect>,
    /// Its parameters.
    pub params: Vec<f64>,
}

impl Hypothesis {
    /// The scenario as declared.
    #[must_use]
    pub fn nominal() -> Self {
        Self {
            effect: None,
            params: Vec::new(),
        }
    }

    /// The scenario with `effect` switched on with `params`.
    #[must_use]
    pub fn with(effect: Effect, params: Vec<f64>) -> Self {
        Self {
            effect: Some(effect),
            params,
        }
    }

    /// The `i`-th parameter when `effect` is the one switched on.
    #[must_use]
    pub fn param_of(&self, effect: Effect, i: usize) -> Option<f64> {
        (self.effect == Some(effect))
            .then(|| self.params.get(i).copied())
            .flatten()
    }
}

/// What the scenario declares that the diagnosis needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Declared {
    /// The scenario's name.
    pub scenario: String,
    /// The robot's start pose.
    pub start: Pose2,
    /// The distance between the wheels, metres.
    pub wheel_base_m: f64,
    /// The lidar, when the robot has one.
    pub lidar: Option<DeclaredLidar>,
    /// The sonar's declared cone half-angle (degrees), when the robot has a sonar.
    pub sonar_half_angle_deg: Option<f64>,
    /// Whether the robot has wheel encoders.
    pub odometer: bool,
    /// The declared actuation error (zero for an ideal drive).
    pub actuation: DeclaredActuation,
}

/// The declared actuation error: the wheels turn at `command × (1 + scale + wander(t))`, one
/// factor for both, `scale` drawn once per run, `wander` an Ornstein–Uhlenbeck process.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DeclaredActuation {
    /// Standard deviation of the fixed scale error.
    pub scale_sd: f64,
    /// Stationary standard deviation of the wander.
    pub wander_sd: f64,
    /// The wander's correlation time, seconds.
    pub wander_tau_s: f64,
}

/// What the scenario declares about the lidar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeclaredLidar {
    /// Every reading of a revolution from the pose at its start (`timing = "per_revolution"`).
    pub snapshot: bool,
    /// The motor speed, rpm.
    pub rpm: f64,
    /// The farthest valid range, metres.
    pub max_range_m: f64,
}

/// One component of a predictive mixture: a normal distribution, truncated to the interval in
/// which the sensor reports a reading at all (a lidar's range limits: a reading beyond them is
/// reported invalid, so a valid one near a limit comes from the part of the normal inside it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaussian {
    /// Weight (a prediction's weights sum to 1).
    pub weight: f64,
    /// Mean of the untruncated normal, metres.
    pub mean_m: f64,
    /// Standard deviation of the untruncated normal, metres (> 0).
    pub sd_m: f64,
    /// The smallest reading reported (−∞: no limit).
    pub lower_m: f64,
    /// The largest reading reported (+∞: no limit).
    pub upper_m: f64,
}

impl Gaussian {
    /// An untruncated normal with weight `weight`.
    #[must_use]
    pub fn new(weight: f64, mean_m: f64, sd_m: f64) -> Self {
        Self {
            weight,
            mean_m,
            sd_m,
            lower_m: f64::NEG_INFINITY,
            upper_m: f64::INFINITY,
        }
    }

    /// The same normal truncated to `[lower_m, upper_m]`.
    #[must_use]
    pub fn truncated(self, lower_m: f64, upper_m: f64) -> Self {
        Self {
            lower_m,
            upper_m,
            ..self
        }
    }

    fn bounds(&self) -> (f64, f64) {
        (
            (self.lower_m - self.mean_m) / self.sd_m,
            (self.upper_m - self.mean_m) / self.sd_m,
        )
    }

    /// The probability the untruncated normal puts inside the interval (computed on the side of
    /// the median that keeps its precision).
    fn mass(&self) -> f64 {
        let (a, b) = self.bounds();
        if a > 0.0 {
            normal_sf(a) - normal_sf(b)
        } else {
            normal_cdf(b) - normal_cdf(a)
        }
        .max(f64::MIN_POSITIVE)
    }

    /// `ln` of the density at `y` (−∞ outside the interval).
    #[must_use]
    pub fn ln_density(&self, y: f64) -> f64 {
        if y < self.lower_m || y > self.upper_m {
            return f64::NEG_INFINITY;
        }
        let z = (y - self.mean_m) / self.sd_m;
        ln_normal_pdf(z) - self.sd_m.ln() - self.truncation_ln_mass()
    }

    fn truncation_ln_mass(&self) -> f64 {
        if self.lower_m == f64::NEG_INFINITY && self.upper_m == f64::INFINITY {
            0.0
        } else {
            self.mass().ln()
        }
    }

    /// The distribution function at `y`.
    #[must_use]
    pub fn cdf(&self, y: f64) -> f64 {
        if self.lower_m == f64::NEG_INFINITY && self.upper_m == f64::INFINITY {
            return normal_cdf((y - self.mean_m) / self.sd_m);
        }
        let (a, _) = self.bounds();
        let z = (y - self.mean_m) / self.sd_m;
        let below = if a > 0.0 {
            normal_sf(a) - normal_sf(z)
        } else {
            normal_cdf(z) - normal_cdf(a)
        };
        (below / self.mass()).clamp(0.0, 1.0)
    }

    /// The mean and the standard deviation of the truncated distribution (the standard
    /// truncated-normal moments: Johnson, Kotz & Balakrishnan, *Continuous Univariate
    /// Distributions* 1, §10.1).
    #[must_use]
    pub fn moments(&self) -> (f64, f64) {
        if self.lower_m == f64::NEG_INFINITY && self.upper_m == f64::INFINITY {
            return (self.mean_m, self.sd_m);
        }
        let (a, b) = self.bounds();
        let z = self.mass();
        let pdf = |x: f64| {
            if x.is_finite() {
                ln_normal_pdf(x).exp()
            } else {
                0.0
            }
        };
        let x_pdf = |x: f64| if x.is_finite() { x * pdf(x) } else { 0.0 };
        let shift = (pdf(a) - pdf(b)) / z;
        let var = 1.0 + (x_pdf(a) - x_pdf(b)) / z - shift * shift;
        (
            self.mean_m + self.sd_m * shift,
            self.sd_m * var.max(1e-12).sqrt(),
        )
    }
}

/// One lidar reading to predict.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LidarQuery {
    /// Its timestamp, seconds.
    pub t_s: f64,
    /// When its revolution started (the timestamp of its reading 0), seconds.
    pub rev_start_s: f64,
    /// Its angle in the lidar's frame, degrees.
    pub angle_deg: f64,
}

/// The predictive distribution of one lidar reading, with its geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct LidarPrediction {
    /// The mixture a valid reading comes from; empty: no valid reading expected.
    pub components: Vec<Gaussian>,
    /// The centre ray's true range, metres.
    pub true_range_m: Option<f64>,
    /// The angle between the beam and the surface normal, degrees.
    pub incidence_deg: f64,
    /// What the beam hit (an index for [`Physics::object_name`]).
    pub object: Option<u32>,
    /// Its reflectivity.
    pub reflectivity: f64,
    /// Whether the beam's direction noise or footprint reaches another surface.
    pub near_edge: bool,
}

/// The predictive distribution of one sonar ping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SonarPrediction {
    /// The expected reading; `None`: no echo within range expected.
    pub reading: Option<Gaussian>,
    /// The nearest echo's true range in the hypothesis's cone, metres.
    pub true_range_m: Option<f64>,
    /// The nearest echo within 30° of the axis, metres (where a wider cone would look).
    pub wide_cone_m: Option<f64>,
}

/// The predictive distribution of one odometer reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometryPrediction {
    /// Left and right wheels.
    pub wheels: [Gaussian; 2],
    /// The wheels' speeds then, m/s.
    pub speed_mps: [f64; 2],
}

/// The simulator, as the diagnosis sees it.
///
/// Every method is a pure function of its arguments: the same question gets the same answer
/// (the diagnosis asks many times while it fits). A `Hypothesis` whose effect does not concern
/// the sensor asked about leaves its predictions nominal.
///
/// ```
/// use hilsim_diagnose::*;
/// use hilsim_recording::{CommandSample, TruthSample};
///
/// /// A robot that never moves, in front of a wall 2 m ahead of its start.
/// struct Corridor(Declared);
/// impl Physics for Corridor {
///     fn declared(&self) -> &Declared { &self.0 }
///     fn object_name(&self, _: u32) -> String { "wall 0".into() }
///     fn drive(&self, _: &[CommandSample], end_s: f64, _: &Hypothesis) -> Vec<TruthSample> {
///         vec![TruthSample { t_s: 0.0, x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 },
///              TruthSample { t_s: end_s, x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 }]
///     }
///     fn lidar(&self, tr: &Trajectory, q: &[LidarQuery], _: &Hypothesis) -> Vec<LidarPrediction> {
///         q.iter().map(|q| {
///             let p = tr.pose_at(q.t_s);
///             let d = (2.0 - p.x) / (p.yaw + q.angle_deg.to_radians()).cos();
///             LidarPrediction {
///                 components: vec![Gaussian::new(1.0, d, 0.01)],
///                 true_range_m: Some(d), incidence_deg: q.angle_deg, object: Some(0),
///                 reflectivity: 0.8, near_edge: false,
///             }
///         }).collect()
///     }
///     fn sonar(&self, _: &Trajectory, t: &[f64], _: &Hypothesis) -> Vec<SonarPrediction> {
///         t.iter().map(|_| SonarPrediction { reading: None, true_range_m: None, wide_cone_m: None }).collect()
///     }
///     fn odometry(&self, _: &Trajectory, t: &[f64], _: &Hypothesis) -> Vec<OdometryPrediction> {
///         let g = Gaussian::new(1.0, 0.0, 0.001);
///         t.iter().map(|_| OdometryPrediction { wheels: [g, g], speed_mps: [0.0; 2] }).collect()
///     }
/// }
/// let physics = Corridor(Declared {
///     scenario: "corridor".into(), start: Pose2::default(), wheel_base_m: 0.23,
///     lidar: Some(DeclaredLidar { snapshot: false, rpm: 300.0, max_range_m: 6.0 }),
///     sonar_half_angle_deg: None, odometer: false,
///     actuation: Default::default(),
/// });
/// let still = Trajectory::new(&physics.drive(&[], 1.0, &Hypothesis::nominal()))?;
/// let ahead = physics.lidar(&still, &[LidarQuery { t_s: 0.5, rev_start_s: 0.4, angle_deg: 0.0 }],
///                           &Hypothesis::nominal());
/// assert_eq!(ahead[0].true_range_m, Some(2.0));
/// # Ok::<(), MismatchError>(())
/// ```
pub trait Physics: Sync {
    /// What the scenario declares.
    fn declared(&self) -> &Declared;

    /// A name for an object of [`LidarPrediction::object`], e.g. `board 1 (dark)`.
    fn object_name(&self, object: u32) -> String;

    /// The intervals `(from, to)`, seconds, in which the robot replaying `commands` under the
    /// nominal model touches an obstacle (its wheels' travel there is the contact's doing, not
    /// the drive's). Default: none (a physics without contacts).
    fn drive_contacts(&self, _commands: &[CommandSample], _end_s: f64) -> Vec<(f64, f64)> {
        Vec::new()
    }

    /// The robot's trajectory from t = 0 to `end_s` when its wheels are commanded by `commands`
    /// (the recording's `commands.csv`), under `hypothesis` (motor lag; any other effect leaves
    /// the drive nominal). The declared actuation error is left out: it is noise to the
    /// diagnosis, not a prediction.
    fn drive(
        &self,
        commands: &[CommandSample],
        end_s: f64,
        hypothesis: &Hypothesis,
    ) -> Vec<TruthSample>;

    /// The lidar readings `queries` from the robot on `trajectory`, under `hypothesis`. When
    /// each reading's geometry is taken (its timestamp, its revolution's start, or in between
    /// under motion skew) is the physics' to decide.
    fn lidar(
        &self,
        trajectory: &Trajectory,
        queries: &[LidarQuery],
        hypothesis: &Hypothesis,
    ) -> Vec<LidarPrediction>;

    /// The sonar pings at `times` from the robot on `trajectory`, under `hypothesis`.
    fn sonar(
        &self,
        trajectory: &Trajectory,
        times: &[f64],
        hypothesis: &Hypothesis,
    ) -> Vec<SonarPrediction>;

    /// The odometer readings at `times` from the robot on `trajectory`, under `hypothesis`.
    fn odometry(
        &self,
        trajectory: &Trajectory,
        times: &[f64],
        hypothesis: &Hypothesis,
    ) -> Vec<OdometryPrediction>;
}

#[cfg(test)]
mod tests {
    use super::Gaussian;

    /// The truncated component against a midpoint-rule integration of the normal density over
    /// the interval (10⁵ steps: the rule's error is ~1e-10 here, far below the tolerances).
    #[test]
    fn a_truncated_component_is_the_normal_renormalised_inside_its_interval() {
        let g = Gaussian::new(1.0, 5.9, 0.1).truncated(0.2, 6.0);
        let (lo, hi, steps) = (0.2_f64, 6.0_f64, 100_000);
        let dx = (hi - lo) / f64::from(steps);
        let (mut mass, mut first, mut second, mut below) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..steps {
            let x = lo + (f64::from(i) + 0.5) * dx;
            let p = g.ln_density(x).exp() * dx;
            mass += p;
            first += x * p;
            second += x * x * p;
            if i < 98_276 {
                below += p;
            }
        }
        assert!((mass - 1.0).abs() < 1e-6, "density integrates to {mass}");
        let (mean, sd) = g.moments();
        assert!((mean - first).abs() < 1e-6, "{mean} vs {first}");
        // Central, normalised: Σx²p − (Σxp)² would multiply the mass's rounding by ~34 m².
        let numeric_sd = (second / mass - (first / mass).powi(2)).sqrt();
        assert!((sd - numeric_sd).abs() < 1e-6, "{sd} vs {numeric_sd}");
        // Cut at 1 σ above the mean: the valid readings' mean is 0.29 σ below it.
        assert!((5.9 - mean - 0.1 * 0.2876).abs() < 1e-4, "{mean}");
        // At the cell edge nearest the normal's mean (5.9 m).
        let edge = lo + 98_276.0 * dx;
        assert!(
            (g.cdf(edge) - below).abs() < 1e-6,
            "{} vs {below}",
            g.cdf(edge)
        );
        assert_eq!(g.cdf(6.0), 1.0);
        assert_eq!(g.cdf(0.1), 0.0);
        assert_eq!(g.ln_density(6.001), f64::NEG_INFINITY);
        // Untruncated: the plain normal.
        let n = Gaussian::new(1.0, 1.0, 0.5);
        assert_eq!(n.moments(), (1.0, 0.5));
        // (`normal_cdf` is good to 1.2e-7.)
        assert!((n.cdf(1.0) - 0.5).abs() < 2e-7);
    }
}
