//! A recording as ROS 2 messages in an MCAP file, with what only a scenario or a calibration
//! knows: the scenario's world drawn as markers, and each lidar reading inverted through a
//! calibration's lidar model (`/scan_calibrated`).

use std::path::{Path, PathBuf};

use hilsim_calibrator::landmarks::Inverse;
use hilsim_calibrator::{Calibration, CalibrationError, Sensor};
use hilsim_recording::{check_output_file, LidarSample, Recording, RecordingDir};
use hilsim_ros2::{ExportOptions, ExportReport, World};
use hilsim_sim::scenario::ScenarioError;
use hilsim_sim::Scenario;

/// A scenario's obstacles as the exporter draws them.
#[must_use]
pub fn drawn_world(scenario: &Scenario) -> World {
    let w = &scenario.world;
    World {
        walls: w.walls.iter().map(|wall| [wall.from, wall.to]).collect(),
        cylinders: w.cylinders.iter().map(|c| (c.center, c.radius)).collect(),
        boards: w
            .boards
            .iter()
            .map(|b| (b.center, b.length, b.thickness, b.yaw_deg.to_radians()))
            .collect(),
    }
}

/// What to export, as asked for.
#[derive(Debug, Clone, Copy)]
pub struct ExportRequest<'a> {
    /// The recording directory.
    pub recording: &'a Path,
    /// The MCAP file to write.
    pub mcap: &'a Path,
    /// The scenario the recording ran, whose world is drawn.
    pub scenario: Option<&'a Path>,
    /// A calibration whose lidar model inverts the readings.
    pub calibration: Option<&'a Path>,
}

/// Why an export cannot start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The output is refused, or the recording cannot be read.
    #[error(transparent)]
    Recording(#[from] hilsim_recording::Error),
    /// The scenario file is unreadable or invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The calibration file is unreadable or invalid.
    #[error(transparent)]
    Calibration(#[from] CalibrationError),
    /// The calibration's method fits no lidar model.
    #[error(
        "{path}: no lidar model (the {method} method's calibration; the calibrated scans need \
         em's, landmarks' or groundtruth's)"
    )]
    NoLidarModel {
        /// The calibration file.
        path: String,
        /// Its method's name.
        method: &'static str,
    },
    /// The calibration's lidar model cannot be inverted.
    #[error("{path}: the lidar model")]
    LidarModel {
        /// The calibration file.
        path: String,
        /// Why.
        #[source]
        source: CalibrationError,
    },
}

/// An export with its inputs read and checked, its output not yet opened.
pub struct McapExport {
    recording: RecordingDir,
    world: Option<World>,
    inverse: Option<Inverse>,
}

impl McapExport {
    /// Checks that the MCAP file may be written (never over an input), then reads the scenario
    /// and the calibration and checks the recording, so that bad input fails before the output
    /// is opened.
    ///
    /// # Errors
    /// The first input found wrong, naming its file.
    pub fn prepare(request: &ExportRequest<'_>) -> Result<Self, ExportError> {
        let mut inputs: Vec<PathBuf> = Recording::files_in(request.recording);
        inputs.extend(
            request
                .scenario
                .iter()
                .chain(&request.calibration)
                .map(|p| p.to_path_buf()),
        );
        let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        check_output_file(request.mcap, hilsim_ros2::MCAP_FILE, &inputs)?;
        let world = match request.scenario {
            Some(path) => Some(drawn_world(&Scenario::load(path)?)),
            None => None,
        };
        let calibration = request.calibration.map(Calibration::read).transpose()?;
        let recording = RecordingDir::open(request.recording)?;
        let inverse = match (&calibration, request.calibration) {
            (Some(calibration), Some(path)) => {
                Some(calibrated_ranges(&recording, calibration, path)?)
            }
            _ => None,
        };
        Ok(Self {
            recording,
            world,
            inverse,
        })
    }

    /// The recording directory `dir` with `world` drawn, nothing inverted.
    ///
    /// # Errors
    /// `dir` is not a recording.
    pub fn of_dir(dir: &Path, world: Option<World>) -> Result<Self, hilsim_recording::Error> {
        Ok(Self {
            recording: RecordingDir::open(dir)?,
            world,
            inverse: None,
        })
    }

    /// Writes the MCAP file at `mcap`, reading the recording as streams.
    ///
    /// # Errors
    /// The recording cannot be read or the file written.
    pub fn write(&self, mcap: &Path) -> Result<ExportReport, hilsim_ros2::Error> {
        // An invalid reading has no calibrated range.
        let calibrated = self.inverse.as_ref().map(|inverse| {
            move |s: &LidarSample| {
                if s.invalid {
                    f64::NAN
                } else {
                    inverse.distance(s.range_m)
                }
            }
        });
        let options = ExportOptions {
            world: self.world.as_ref(),
            calibrated: calibrated
                .as_ref()
                .map(|f| f as &dyn Fn(&LidarSample) -> f64),
            ..ExportOptions::default()
        };
        hilsim_ros2::export_dir(&self.recording, &options, mcap)
    }
}

/// The calibration's lidar model inverted: a reading's distance (the distance whose mean
/// reading it is), searched up to past the farthest reading of the recording.
fn calibrated_ranges(
    recording: &RecordingDir,
    calibration: &Calibration,
    path: &Path,
) -> Result<Inverse, ExportError> {
    // The recording is checked (as a whole read would, its errors first) on the way.
    let farthest = recording.farthest_lidar_range_m(1.0)?;
    let path = path.display().to_string();
    let Some(model) = calibration.sensors.get(&Sensor::Lidar) else {
        return Err(ExportError::NoLidarModel {
            path,
            method: calibration.method.name(),
        });
    };
    // Search up to past the farthest reading: a lidar model is fitted below 100 m.
    Inverse::new(&model.alpha, [0.0, 2.0 * farthest + 100.0])
        .map_err(|source| ExportError::LidarModel { path, source })
}
