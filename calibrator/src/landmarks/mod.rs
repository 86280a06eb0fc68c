//! The landmark calibrator: the lidar's range model from cylinders in unknown positions, seen
//! from stand-still stops along the robot's path (Alhashimi, Magnusson, Knorn, Varagnolo,
//! "Calibrating Range Measurements of Lidars Using Fixed Landmarks in Unknown Positions",
//! Sensors 21(1):155, 2021).
//!
//! From a recording: [`stops`] finds where the robot stood still, [`scan`] averages each stop's
//! revolutions beam by beam, [`detection`] finds the cylinders (circle fits, walls and clutter
//! rejected) and measures each one's bearing and range, [`association`] matches them across
//! stops. Then the paper: [`positions`] places the landmarks by the weighted least-squares
//! intersection of bearings (eqs. (18)–(25)), [`regression`] fits the Vandermonde model for every
//! order, selects the order by AIC and by cross-validation and fits beta, [`inversion`] turns a
//! reading into a distance. Beyond the paper, [`estimate`] adds residual-variance weights and
//! heteroscedastic WLS, and [`joint`] refines the landmarks, stops and alpha together.
//!
//! ```no_run
//! use hilsim_calibrator::landmarks::{calibrate, Options};
//! use hilsim_recording::Recording;
//! let rec = Recording::read_dir("run".as_ref())?;
//! let cal = calibrate(&rec, &Options::default())?;
//! println!("order {:?}, landmarks {:?}", cal.order, cal.landmarks);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Method, and where we depart from the paper: `docs/landmark-calibration.md`.

pub mod association;
pub mod calibrate;
pub mod checks;
pub mod circle_fit;
pub mod detection;
pub mod estimate;
pub mod inversion;
pub mod joint;
pub mod options;
pub mod positions;
pub mod regression;
pub mod rest;
pub mod scan;
pub mod stops;

pub use calibrate::{analyse, calibrate, Analysis};
pub use inversion::Inverse;
pub use options::{
    AssociationOptions, DetectionOptions, Estimator, Nominal, Options, OrderSelection, StopOptions,
};
