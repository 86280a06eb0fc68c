//! Residuals: every sensor's readings against the simulation's prediction, under the scenario's
//! declared noise model. Each reading gets a predictive distribution (a Gaussian, or a mixture
//! where the lidar's direction noise reaches an edge), a small uniform outlier component, and
//! from them a log-likelihood, a residual in metres and a normal score (the probability integral
//! transform: `z = Φ⁻¹(F(y))`, standard normal when the prediction is right).
//!
//! The readings are split in time into training and held-out halves: alternate 2 s blocks (a
//! lidar revolution goes with the block its start falls in), so both halves see the whole run
//! (the warm-up, every manoeuvre) and the held-out half is never fitted.

mod clusters;
mod data;
mod drive_filter;
mod dropout_rows;
mod likelihood;
mod path_error;
mod predict;
mod sensors;

pub(crate) use self::clusters::shared_error_clusters;
pub use self::data::Covariate;
#[cfg(test)]
pub(crate) use self::data::Queries;
pub(crate) use self::data::{Context, Predictive, SensorData};
pub(crate) use self::dropout_rows::{dropout_rows, DropoutRows};
pub(crate) use self::likelihood::{fits, log_likelihood, rmse, Fit};
pub(crate) use self::sensors::{drive, lidar, odometer, sonar};
