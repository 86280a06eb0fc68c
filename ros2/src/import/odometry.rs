//! Odometry into wheel travel: a recording's odometry is each wheel's cumulative travel, so an
//! `Odometry` (or TF's odom → base) pose is turned back into the travel that drives the last pose
//! to it ([`hilsim_recording::Pose::wheel_travel_to`]), and a `JointState`'s wheel angles into
//! travel by the wheel radius.

use hilsim_recording::{OdometrySample, SampleSink};

use super::{Converter, Fault};
use crate::msgs::{JointState, Pose};
use crate::topics::{self, Role};

/// The last pose (or wheel angles) and the wheel travel so far.
pub(super) enum OdometryState {
    Pose {
        /// As the message gave it (its heading not wrapped again).
        last: hilsim_recording::Pose,
        left_m: f64,
        right_m: f64,
    },
    Joints {
        /// The wheels' joint names, and their indices in the last message (a hint: messages
        /// may list different joints).
        names: [String; 2],
        at: [usize; 2],
        /// The angles at the first message, radians.
        start: [f64; 2],
    },
}

impl Converter {
    /// Wheel travel rebuilt from the pose increments: each step's travel is what drives the
    /// last pose to this one ([`hilsim_recording::Pose::wheel_travel_to`], the midpoint rule of
    /// differential-drive odometry).
    pub(super) fn odometry<S>(&mut self, ns: i64, pose: &Pose, sink: &mut S) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let (x, y, yaw) = (pose.position.x, pose.position.y, pose.orientation.yaw());
        if ![x, y, yaw].iter().all(|v| v.is_finite()) {
            self.not_finite(Role::Odometry);
            return Ok(());
        }
        // Not `Pose::new`: the heading is kept as the message gave it, unwrapped again.
        let planar = hilsim_recording::Pose { x, y, yaw };
        let (left_m, right_m) = match &mut self.odometry {
            Some(OdometryState::Pose {
                last,
                left_m,
                right_m,
            }) => {
                let (left_step, right_step) = last.wheel_travel_to(&planar, self.wheel_base_m);
                *left_m += left_step;
                *right_m += right_step;
                *last = planar;
                // To the nanometre, far below any encoder's tick: the rounding error of the
                // sums (1e-17 m a step) does not show, and a millimetre stays `0.002`. (Beyond
                // 1e290 m there are no nanometres to round to.)
                let nm = |m: f64| {
                    let scaled = m * 1e9;
                    if scaled.is_finite() {
                        scaled.round() / 1e9
                    } else {
                        m
                    }
                };
                (nm(*left_m), nm(*right_m))
            }
            _ => {
                let (left_m, right_m) = self.odometry_start_m;
                self.odometry = Some(OdometryState::Pose {
                    last: planar,
                    left_m,
                    right_m,
                });
                (left_m, right_m)
            }
        };
        if !(left_m.is_finite() && right_m.is_finite()) {
            // The poses are finite but so far apart that the travel between them is not a
            // number: the rows after it would all be wrong.
            return Err(Fault::Message(format!(
                "a pose at ({x:e}, {y:e}) m that puts the wheel travel beyond any number"
            )));
        }
        let t_s = self.seconds(Role::Odometry, ns, 0.0);
        self.count(Role::Odometry, 1);
        Ok(sink.odometry(&OdometrySample {
            t_s,
            left_m,
            right_m,
        })?)
    }

    /// Wheel travel from the wheel joints' angles: the angle turned since the first message
    /// times the radius. The wheels are the joints named with `--wheel-joints`, else the one
    /// joint whose name has `left` (`right`) in it, or the one of those with `wheel` too. A
    /// message without the wheels' positions (a driver may publish its joints in groups) is
    /// skipped and counted.
    pub(super) fn joints<S>(
        &mut self,
        ns: i64,
        joints: &JointState,
        sink: &mut S,
    ) -> Result<(), Fault>
    where
        S: SampleSink<Error = hilsim_recording::Error>,
    {
        let radius = self.wheel_radius_m.unwrap_or(0.0);
        if self.odometry.is_none() {
            let names = match &self.wheel_joints {
                Some(names) => names.clone(),
                None => match [
                    wheel_joint(&joints.name, "left")?,
                    wheel_joint(&joints.name, "right")?,
                ] {
                    [Some(left), Some(right)] => [left, right],
                    // Another group of joints (an arm's): the wheels may come in the next.
                    _ => {
                        self.joints_missing += 1;
                        if self.joints_seen.is_empty() {
                            self.joints_seen.clone_from(&joints.name);
                        }
                        return Ok(());
                    }
                },
            };
            self.odometry = Some(OdometryState::Joints {
                names,
                at: [0, 0],
                start: [f64::NAN; 2],
            });
        }
        let Some(OdometryState::Joints { names, at, start }) = &mut self.odometry else {
            return Ok(());
        };
        let mut angles = [0.0; 2];
        for side in 0..2 {
            let found = if joints.name.get(at[side]) == Some(&names[side]) {
                Some(at[side])
            } else {
                joints.name.iter().position(|n| *n == names[side])
            };
            match found.and_then(|i| Some((i, *joints.position.get(i)?))) {
                Some((i, angle)) if angle.is_finite() => {
                    at[side] = i;
                    angles[side] = angle;
                }
                _ => {
                    self.joints_missing += 1;
                    return Ok(());
                }
            }
        }
        if start[0].is_nan() {
            *start = angles;
        }
        let (left_m, right_m) = (
            (angles[0] - start[0]) * radius,
            (angles[1] - start[1]) * radius,
        );
        if !(left_m.is_finite() && right_m.is_finite()) {
            return Err(Fault::Message(format!(
                "wheel angles ({:e}, {:e}) rad so far from the first ones that the wheel travel \
                 is beyond any number",
                angles[0], angles[1]
            )));
        }
        let t_s = self.seconds(Role::Odometry, ns, 0.0);
        self.count(Role::Odometry, 1);
        Ok(sink.odometry(&OdometrySample {
            t_s,
            left_m,
            right_m,
        })?)
    }
}

/// The wheel joint of one `side` (`left`, `right`) among a JointState's names: the one whose
/// name has the side in it (any case), or, of several, the one that also has `wheel`.
/// `None` when no joint has the side in its name; an error when several do and not one of them
/// has `wheel`.
fn wheel_joint(names: &[String], side: &str) -> Result<Option<String>, Fault> {
    let has = |name: &str, word: &str| name.to_lowercase().contains(word);
    let sided: Vec<&String> = names.iter().filter(|n| has(n, side)).collect();
    let wheels: Vec<&String> = sided.iter().copied().filter(|n| has(n, "wheel")).collect();
    match (sided.as_slice(), wheels.as_slice()) {
        ([], _) => Ok(None),
        ([one], _) | (_, [one]) => Ok(Some((*one).clone())),
        _ => Err(Fault::Message(format!(
            "which joints are the wheels? several of the joints {} are named `{side}`; \
             name the wheels with --wheel-joints LEFT,RIGHT",
            topics::listing(names, ", ")
        ))),
    }
}
