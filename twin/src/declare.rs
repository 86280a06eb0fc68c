//! What a twin's scenario declares from a calibration of the robot, and how close the twin
//! came to the log, as `hilsim world` reports it.

use hilsim_calibrator::{Calibration, Sensor};
use hilsim_recording::Mount;

use crate::{Declared, TwinError, TwinFit, COMPARED_WITHIN_M};

impl Declared {
    /// Takes what `calibration` (read from `origin`) found: an em, landmarks or groundtruth
    /// calibration's lidar bias and noise; an odometry calibration's wheel base and lidar
    /// mount. Returns whether the lidar's noise came from it.
    ///
    /// # Errors
    /// The calibration has none of these.
    pub fn calibrate(
        &mut self,
        calibration: &Calibration,
        origin: &str,
    ) -> Result<bool, TwinError> {
        let lidar = calibration.sensors.get(&Sensor::Lidar);
        if let Some(model) = lidar {
            self.lidar_bias.clone_from(&model.alpha);
            self.lidar_noise.clone_from(&model.beta);
        }
        if let Some(o) = &calibration.odometry {
            self.wheel_base_m = o.wheel_base_m;
            self.lidar_mount = Mount {
                x_m: o.lidar_x_m,
                y_m: o.lidar_y_m,
                yaw_deg: o.lidar_yaw_rad.to_degrees(),
            };
        }
        if lidar.is_none() && calibration.odometry.is_none() {
            return Err(TwinError::Input(format!(
                "{origin}: the {} method's calibration has no lidar model, no wheels and no \
                 lidar mount for the scenario to declare",
                calibration.method.name()
            )));
        }
        Ok(lidar.is_some())
    }
}

impl TwinFit {
    /// One line: the readings paired, and how far the twin's are from the log's.
    #[must_use]
    pub fn summary(&self) -> String {
        format!(
            "twin: {} of {} readings within {COMPARED_WITHIN_M} m paired ({:.1} %); |twin − log| \
             median {:.1} mm, 90th percentile {:.1} mm; log − twin median {:+.1} mm, spread \
             {:.1} mm",
            self.paired,
            self.compared,
            100.0 * self.paired_share(),
            1000.0 * self.median_abs_m,
            1000.0 * self.p90_abs_m,
            1000.0 * self.median_m,
            1000.0 * self.spread_m,
        )
    }
}
