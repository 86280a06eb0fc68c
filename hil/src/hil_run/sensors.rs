//! The sensor samples taken so far, and the robot as the command port sees it from them.

use std::collections::VecDeque;

use hilsim_lidar_emulator::wire::RevolutionFrame;
use hilsim_recording::{LidarSample, OdometrySample, SonarSample};

use crate::command_port::{Robot, Unavailable};
use crate::motion::{MotionController, MotorRequest};

/// The sensor samples taken so far: the recording's rows and what the command port answers
/// from.
pub(super) struct Sensors {
    pub(super) lidar: Option<Vec<LidarSample>>,
    pub(super) sonar: Option<Vec<SonarSample>>,
    pub(super) odometry: Option<Vec<OdometrySample>>,
    pub(super) sonar_period_s: f64,
    /// Recent complete revolutions with the instant each was complete, oldest first.
    pub(super) frames: VecDeque<(f64, RevolutionFrame)>,
    pub(super) lidar_rpm: Option<f64>,
    /// Whether the lidar is the XV-11, whose revolutions `GetLDSScan` reports (another unit's
    /// readings reach the firmware only on its own port).
    pub(super) xv11: bool,
}

/// The robot as the command port sees it at `now_s` (simulation seconds).
pub(super) struct RobotView<'a> {
    pub(super) now_s: f64,
    pub(super) sensors: &'a Sensors,
    pub(super) motion: &'a mut MotionController,
}

impl Robot for RobotView<'_> {
    fn set_motor(&mut self, request: MotorRequest) {
        self.motion.start(request);
    }

    fn stop_motors(&mut self) {
        self.motion.stop();
    }

    fn wheel_positions_mm(&self) -> Option<[i64; 2]> {
        let odometry = self.sensors.odometry.as_ref()?;
        let latest = odometry.iter().rev().find(|s| s.t_s <= self.now_s);
        Some(latest.map_or([0, 0], |s| {
            [
                (s.left_m * 1000.0).round() as i64,
                (s.right_m * 1000.0).round() as i64,
            ]
        }))
    }

    fn lds_rpm(&self) -> Option<f64> {
        self.sensors.lidar_rpm
    }

    fn lds_scan(&self) -> Result<&RevolutionFrame, Unavailable> {
        if self.sensors.lidar.is_none() || !self.sensors.xv11 {
            return Err(Unavailable::NoSensor);
        }
        self.sensors
            .frames
            .iter()
            .rev()
            .find(|(complete_s, _)| *complete_s <= self.now_s)
            .map(|(_, frame)| frame)
            .ok_or(Unavailable::NotYet)
    }

    fn sonar_mm(&self) -> Result<Option<u32>, Unavailable> {
        let sonar = self.sensors.sonar.as_ref().ok_or(Unavailable::NoSensor)?;
        // Pings with no echo leave no sample: the latest ping had an echo only if the latest
        // sample is less than a ping period old.
        Ok(sonar
            .iter()
            .rev()
            .find(|s| s.t_s <= self.now_s)
            .filter(|s| self.now_s - s.t_s < self.sensors.sonar_period_s)
            .map(|s| (s.range_m * 1000.0).round() as u32))
    }
}
