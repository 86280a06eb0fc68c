//! What the residuals are computed from: one sensor's readings, the variables they are tested
//! against, and the context the diagnosis holds while it works.

use hilsim_recording::{Mount, Recording};

use crate::align::Estimates;
use crate::catalogue::{mounted, Effect, Sensor};
use crate::locate::Floors;
use crate::physics::{Gaussian, Hypothesis, LidarQuery, Mixture, Physics};
use crate::sparse_truth::IntervalNoise;
use crate::trajectory::Trajectory;

/// Length of the alternating training / held-out blocks, seconds.
pub const SPLIT_BLOCK_S: f64 = 2.0;
/// Window of the drive's residuals (wheel travel increments), seconds.
pub const DRIVE_WINDOW_S: f64 = 0.1;
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
            Covariate::OffAxisNearer => "nearness of an off-axis echo",
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
    /// One span between two poses of a sparse truth per pair of rows: the wheels' mean travel
    /// over it and their difference (right − left), and how far the truth's departs from each
    /// beyond any effect. Apart: a pose's error along the path (a stamp off at speed) is both
    /// wheels' alike, so their difference, the turn, is known far better.
    OdometerSpans {
        spans: Vec<(f64, f64)>,
        noise: [IntervalNoise; 2],
    },
    /// One window per pair of rows (left, right).
    Drive(Vec<(f64, f64)>),
}

impl Queries {
    /// The data's rows per reading: two for the encoders and the drive, one for the others.
    #[must_use]
    pub(crate) fn rows_per_reading(&self) -> usize {
        match self {
            Queries::Lidar(_) | Queries::Sonar(_) => 1,
            Queries::Odometer(_) | Queries::OdometerSpans { .. } | Queries::Drive(_) => 2,
        }
    }
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
    /// How far the world's own error can move each reading, metres, by row: a map's surface
    /// anywhere across its cell, carried along the beam (`DeclaredLidar::world_uncertainty_m`
    /// over |cos θ|); empty when the world is drawn exactly.
    pub world_reach_m: Vec<f64>,
}

/// One reading's predictive distribution (empty: no reading expected).
pub(crate) type Predictive = Mixture;

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

    /// How far the world's own error can move reading `row`, metres (0 in an exact world).
    pub fn world_reach(&self, row: usize) -> f64 {
        self.world_reach_m.get(row).copied().unwrap_or(0.0)
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
    /// The recording's trajectories estimated so far under hypotheses.
    pub estimates: &'a Estimates,
    pub end_s: f64,
    /// The trajectory's position noise, metres (widens the drive's and encoders' residuals,
    /// and those of the lidar and sonar when the trajectory is estimated).
    pub position_sd_m: f64,
    /// The trajectory's heading noise, radians (0 for a recorded one).
    pub yaw_sd_rad: f64,
    /// Whether the trajectory is estimated (its errors then widen every range).
    pub estimated: bool,
    /// The mount the trajectory was found through by placing the lidar, when the sensors that
    /// look from the robot (the sonar, the encoders) are to see a hypothesised lidar mount as
    /// the robot's path it implies (`Trajectory::under_mount`); `None`: the path is the
    /// robot's under every hypothesis.
    pub placed_through: Option<Mount>,
    /// The practical floors an effect's change of the readings is measured against.
    pub floors: Floors,
}

impl Context<'_> {
    /// The robot's path under `h` when it differs from [`Context::trajectory`]: with
    /// [`Context::placed_through`] set (the trajectory was found by matching the lidar), the
    /// path that a lidar mount offset in `h` implies, and a lidar delay in `h` (its stamps late,
    /// the matched poses late with them).
    pub(super) fn robot_path(&self, h: &Hypothesis) -> Option<Trajectory> {
        let through = self.placed_through?;
        let offset: Option<Vec<f64>> = (0..3)
            .map(|i| h.param_of(Effect::LidarMountOffset, i))
            .collect();
        let mounted = offset.map(|o| {
            self.trajectory
                .under_mount(&through, &mounted(&through, &o))
        });
        match h.param_of(Effect::SensorLatency(Sensor::Lidar), 0) {
            Some(delay_s) => Some(mounted.as_ref().unwrap_or(self.trajectory).delayed(delay_s)),
            None => mounted,
        }
    }

    /// Widens range predictions by the estimated trajectory's uncertainty: its position error
    /// along the beam and its heading error times the range.
    pub(super) fn widen(&self, mut g: Gaussian) -> Gaussian {
        if self.estimated {
            let extra = self.position_sd_m.powi(2) + (g.mean_m * self.yaw_sd_rad).powi(2);
            g.sd_m = (g.sd_m * g.sd_m + extra).sqrt();
        }
        g
    }
}
