//! What the report computes from its inputs before drawing: the paths, the pose at any time,
//! each reading's true distance (from the recording, else by ray casting the scenario's world
//! from the true path) and the calibrated ranges.

use hilsim_calibrator::{Calibration, Sensor};
use hilsim_recording::{LidarSample, Pose, Recording, TimedPath};
use hilsim_sim::{Scenario, World};

/// The inputs of a report.
#[derive(Debug, Clone, Copy)]
pub struct Inputs<'a> {
    /// The page's title.
    pub title: &'a str,
    /// The recording (its source named in the page's header).
    pub recording: &'a Recording,
    /// Where the recording came from, for the header.
    pub recording_name: &'a str,
    /// The scenario the recording is a run of: the world, the declared sensor models.
    pub scenario: Option<&'a Scenario>,
    /// Calibrations of the recording, in the order they are shown.
    pub calibrations: &'a [Calibration],
    /// Whether the recording's truth is a path estimated from its own lidar (a diagnosis of a
    /// recording without `truth.csv`), not measured: the page calls it so.
    pub truth_estimated: bool,
}

/// A reading with its true distance, for the error plots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scored {
    /// When, seconds.
    pub t_s: f64,
    /// The lidar revolution (0 for the sonar).
    pub rev: u64,
    /// The beam's angle in the sensor's frame, degrees (0 for the sonar).
    pub angle_deg: f64,
    /// The reading, metres.
    pub reading_m: f64,
    /// The true distance, metres (NaN when unknown).
    pub true_m: f64,
}

/// One lidar revolution's counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Revolution {
    /// Its number.
    pub rev: u64,
    /// When its first reading was taken, seconds.
    pub t_s: f64,
    /// Its readings.
    pub readings: usize,
    /// Its valid readings.
    pub valid: usize,
}

/// The derived data of a report.
#[derive(Debug)]
pub struct View<'a> {
    /// The inputs.
    pub inputs: Inputs<'a>,
    /// The true path (truth.csv), empty without one.
    pub truth: TimedPath,
    /// The path dead-reckoned from the odometry, from the true start (else the scenario's
    /// start, else the origin); empty without odometry.
    pub odometry: TimedPath,
    /// The same dead-reckoned with an odometry calibration's wheels (the first calibration
    /// that has them); empty without one.
    pub calibrated_odometry: TimedPath,
    /// What a reading's world position is computed from: "truth", "odometry" or "none".
    pub reference: &'static str,
    /// Each valid lidar reading with its true distance.
    pub lidar: Vec<Scored>,
    /// Each valid sonar reading with its true distance.
    pub sonar: Vec<Scored>,
    /// Where the true distances came from, for the page.
    pub true_distance_source: &'static str,
    /// The lidar's revolutions in order (consecutive readings of one `rev`); `None` without a
    /// lidar.
    pub revolutions: Option<Vec<Revolution>>,
}

impl<'a> View<'a> {
    /// Derives what the page draws.
    #[must_use]
    pub fn new(inputs: Inputs<'a>) -> Self {
        let rec = inputs.recording;
        let truth = TimedPath::from_truth(rec.truth.as_deref().unwrap_or_default());
        let start = truth.first().map(|p| p.1).or_else(|| {
            inputs.scenario.map(|s| {
                let p = &s.robot.start;
                Pose::new(p.x, p.y, p.yaw_deg.to_radians())
            })
        });
        let origin = start.unwrap_or(Pose::new(0.0, 0.0, 0.0));
        let odometry = dead_reckoning(rec, origin, Wheels::declared(rec));
        let calibrated_odometry = inputs
            .calibrations
            .iter()
            .find_map(|c| c.odometry.as_ref())
            .and_then(|o| Wheels::calibrated(rec, o))
            .map_or_else(TimedPath::new, |wheels| dead_reckoning(rec, origin, wheels));
        let reference = if !truth.is_empty() {
            "truth"
        } else if !odometry.is_empty() {
            "odometry"
        } else {
            "none"
        };
        let world = inputs.scenario.map(World::new);
        let has_column = rec.lidar.iter().flatten().any(|s| s.true_range_m.is_some())
            || rec.sonar.iter().flatten().any(|s| s.true_range_m.is_some());
        let true_distance_source = if has_column {
            "the recording's true_range_m columns"
        } else if world.is_some() && !truth.is_empty() {
            if inputs.truth_estimated {
                "rays cast in the scenario's world from the path estimated from the lidar"
            } else {
                "rays cast in the scenario's world from the true path"
            }
        } else {
            "none (the recording has no true_range_m and no truth with a scenario)"
        };
        let max_range = inputs
            .scenario
            .and_then(|s| s.sensors.lidar.as_ref())
            .map_or(6.0, |l| l.max_range_m);
        let lidar = rec
            .lidar
            .iter()
            .flatten()
            .filter(|s| !s.invalid)
            .map(|s| Scored {
                t_s: s.t_s,
                rev: s.rev,
                angle_deg: s.angle_deg,
                reading_m: s.range_m,
                true_m: s.true_range_m.unwrap_or_else(|| {
                    cast(
                        world.as_ref(),
                        &truth,
                        rec.meta
                            .lidar
                            .as_ref()
                            .map_or(Pose::new(0.0, 0.0, 0.0), |m| {
                                Pose::new(m.x_m, m.y_m, m.yaw_rad())
                            }),
                        s.t_s,
                        beam_rad(s),
                        max_range,
                    )
                }),
            })
            .collect();
        let sonar_max = inputs
            .scenario
            .and_then(|s| s.sensors.sonar.as_ref())
            .map_or(6.0, |s| s.max_range_m);
        let sonar_mount = rec
            .meta
            .sonar
            .as_ref()
            .map_or(Pose::new(0.0, 0.0, 0.0), |m| {
                Pose::new(m.x_m, m.y_m, m.yaw_deg.to_radians())
            });
        let sonar = rec
            .sonar
            .iter()
            .flatten()
            .filter(|s| s.range_m.is_finite() && s.range_m > 0.0)
            .map(|s| Scored {
                t_s: s.t_s,
                rev: 0,
                angle_deg: 0.0,
                reading_m: s.range_m,
                true_m: s.true_range_m.unwrap_or_else(|| {
                    cast(world.as_ref(), &truth, sonar_mount, s.t_s, 0.0, sonar_max)
                }),
            })
            .collect();
        Self {
            inputs,
            truth,
            odometry,
            calibrated_odometry,
            reference,
            lidar,
            sonar,
            true_distance_source,
            revolutions: rec.lidar.as_deref().map(revolutions),
        }
    }

    /// The robot's pose at `t` on the reference path (truth, else odometry), interpolated.
    #[must_use]
    pub fn pose_at(&self, t: f64) -> Option<Pose> {
        let path = if self.truth.is_empty() {
            &self.odometry
        } else {
            &self.truth
        };
        path.pose_at(t)
    }

    /// The first calibration with a model of `sensor`.
    #[must_use]
    pub fn calibrated(&self, sensor: Sensor) -> Option<(&Calibration, &[f64])> {
        self.inputs
            .calibrations
            .iter()
            .find_map(|c| c.sensors.get(&sensor).map(|m| (c, m.alpha.as_slice())))
    }
}

/// The revolutions of `lidar`: runs of consecutive readings with one `rev`.
fn revolutions(lidar: &[LidarSample]) -> Vec<Revolution> {
    let mut out: Vec<Revolution> = Vec::new();
    for s in lidar {
        let valid = usize::from(!s.invalid);
        match out.last_mut() {
            Some(r) if r.rev == s.rev => {
                r.readings += 1;
                r.valid += valid;
            }
            _ => out.push(Revolution {
                rev: s.rev,
                t_s: s.t_s,
                readings: 1,
                valid,
            }),
        }
    }
    out
}

/// The beam's direction in the lidar's frame, radians.
#[must_use]
pub fn beam_rad(s: &LidarSample) -> f64 {
    s.angle_deg.to_radians()
}

/// The distance along a beam at `beam_rad` in the frame of a sensor mounted at `mount`, from
/// the true pose at `t`, to the first obstacle of `world` (NaN when either is unknown or
/// nothing is hit within `max_m`).
fn cast(
    world: Option<&World>,
    truth: &TimedPath,
    mount: Pose,
    t: f64,
    beam_rad: f64,
    max_m: f64,
) -> f64 {
    let (Some(world), Some(pose)) = (world, truth.pose_at(t)) else {
        return f64::NAN;
    };
    let sensor = pose.compose(mount.x, mount.y, mount.yaw);
    world
        .cast_ray([sensor.x, sensor.y], sensor.yaw + beam_rad, max_m)
        .map_or(f64::NAN, |hit| hit.distance)
}

/// How the encoders' travel becomes the wheels': each wheel's travel times its scale, the
/// wheels `base_m` apart.
#[derive(Debug, Clone, Copy)]
struct Wheels {
    scale: [f64; 2],
    base_m: f64,
}

impl Wheels {
    /// As the recording declares them.
    fn declared(rec: &Recording) -> Self {
        Self {
            scale: [1.0, 1.0],
            base_m: rec.meta.robot.wheel_base_m,
        }
    }

    /// As an odometry calibration found them; `None` when it does not say how its radii
    /// compare with the recording's travel (a calibration of tuples, and the recording gives
    /// no nominal radius).
    fn calibrated(rec: &Recording, o: &hilsim_calibrator::OdometryModel) -> Option<Self> {
        let scale = o.wheel_scale.or_else(|| {
            let nominal = rec.meta.robot.wheel_radius_m?;
            Some([
                o.left_wheel_radius_m / nominal,
                o.right_wheel_radius_m / nominal,
            ])
        })?;
        Some(Self {
            scale,
            base_m: o.wheel_base_m,
        })
    }
}

/// The odometry dead-reckoned from `start` ([`Pose::drive`] between readings).
fn dead_reckoning(rec: &Recording, start: Pose, wheels: Wheels) -> TimedPath {
    let Some(odometry) = rec.odometry.as_deref() else {
        return TimedPath::new();
    };
    let Wheels {
        scale: [left, right],
        base_m: base,
    } = wheels;
    let mut path = TimedPath::with_capacity(odometry.len());
    let mut pose = start;
    let mut last: Option<(f64, f64)> = None;
    for o in odometry {
        if let Some((l, r)) = last {
            pose = pose.drive((o.left_m - l) * left, (o.right_m - r) * right, base);
        }
        last = Some((o.left_m, o.right_m));
        path.push(o.t_s, pose);
    }
    path
}
