//! Ground-truth-less calibration of a lidar (and optionally an odometer and a sonar) by
//! approximate Expectation–Maximisation over a Kalman/RTS smoother.
//!
//! The robot drives along a line towards or away from a fixed target; the commands it issued
//! are known, its actual speed is not. Each sensor follows the paper's eq. (2),
//! `y = Σ α_i d^i + (Σ β_i d^i) e`; the distance follows `d_{k+1} = d_k + u_k + ν_k` (eq. 3)
//! from a known start. EM alternates a smoother over the redundant state `[1, d, d²]` (E-step)
//! with closed-form per-sensor fits (M-step) until the parameters and the log-likelihood
//! settle.
//!
//! # Requirements
//! - a lidar table whose beam at [`EmOptions::beam_deg`] sees the target in at least
//!   [`MIN_LIDAR_READINGS`] revolutions;
//! - the commands, and the start distance (`meta.world.target_start_distance_m` or
//!   [`EmOptions::start_distance_m`]);
//! - motion: the commanded distance must span at least [`MIN_SPAN_M`].
//!
//! # Reference
//! A. Alhashimi, D. Varagnolo, T. Gustafsson, "Calibrating distance sensors for terrestrial
//! applications without groundtruth information", IEEE Sensors J. 17(12), 2017: model eqs.
//! (2)–(5), E-step Algorithm 1, M-step Sec. IV-C. The filter, smoother and M-step are derived
//! anew from Shumway & Stoffer (1982); where this implementation departs from the paper (and
//! why) is in `docs/em-calibration.md`.
//!
//! ```no_run
//! use hilsim_calibrator::em::{self, EmOptions};
//! use hilsim_recording::Recording;
//! let rec = Recording::read_dir("run".as_ref())?;
//! let calibration = em::calibrate(&rec, &EmOptions::default())?;
//! println!("{}", calibration.to_json());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod engine;
mod estep;
mod estimate;
mod information;
mod model;
mod mstep;
mod options;
mod prior;
mod run;
#[cfg(test)]
mod tests;

pub use estimate::Estimate;
pub use options::{EStep, EmOptions, MIN_AUX_READINGS, MIN_LIDAR_READINGS, MIN_SPAN_M};
pub use prior::{Prior, Priors};
pub use run::{calibrate, run, run_samples, EmOutcome};

pub(crate) use estep::{build_data, e_step};
pub(crate) use estimate::estimates;
pub(crate) use model::{Lin, Params, SensorParams};
pub(crate) use model::{LIDAR, ODOMETER, SONAR};
pub(crate) use run::lidar_innovations;
