//! What a twin's scenario declares from a calibration of the robot, and how close the twin
//! came to the log, as `hilsim world` reports it.

use hilsim_calibrator::{Calibration, Sensor};
use hilsim_recording::Mount;

use hilsim_sim::Scenario;

use crate::{compare, Declared, TwinError, TwinFiles, TwinFit, TwinWorld, COMPARED_WITHIN_M};

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

impl TwinWorld {
    /// Writes the twin declaring `declared`, with the lidar's noise measured unless
    /// `noise_calibrated`: the twin is first written noiseless and its readings set against the
    /// log's. Returns that fit and what was declared.
    ///
    /// # Errors
    /// As [`TwinWorld::write`] and [`compare`].
    pub fn write_measured(
        &self,
        files: &TwinFiles,
        mut declared: Declared,
        noise_calibrated: bool,
    ) -> Result<(TwinFit, Declared), TwinError> {
        let noiseless = Declared {
            lidar_noise: vec![0.0],
            ..declared.clone()
        };
        self.write(files, &noiseless)?;
        let toml = self.scenario_toml(files, &noiseless);
        let scenario = Scenario::from_toml(&toml, &files.scenario)?;
        let fit = compare(&scenario, &self.recording)?;
        if !noise_calibrated && fit.spread_m.is_finite() {
            // The spread of the log against its twin by range, as the papers' noise polynomial:
            // the map's quantisation taken out (the diagnosis carries it itself), what is left is
            // an upper bound of the lidar's noise.
            let map = scenario.files.map.as_ref();
            declared.lidar_noise = fit.noise_polynomial(map.map_or(0.0, |m| m.resolution_m()));
        }
        self.write(files, &declared)?;
        Ok((fit, declared))
    }
}

impl Declared {
    /// One line: the lidar's noise declared from the twin's spread.
    #[must_use]
    pub fn measured_noise_line(&self) -> String {
        format!(
            "declared the lidar's noise (its spread against the twin by range, less the map's \
             cells): {:?} (β₀, β₁, β₂ of σ = β₀ + β₁ d + β₂ d², metres)",
            self.lidar_noise
        )
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
