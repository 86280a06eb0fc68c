//! Calibration of distance sensors from recordings (`hilsim_recording::Recording`): the
//! ground-truth-less EM calibrator with its Kalman/RTS smoother (Alhashimi et al., IEEE Sensors
//! J. 2017), the landmark calibrator (Alhashimi et al., Sensors 2021), the ground-truth baseline
//! and sim-to-real mismatch discovery.
//!
//! The methods arrive with their issues (#5, #6, #7); until then this crate holds no code. It
//! reads recordings only and must never depend on the physics (`hilsim-sim`, rapier).
#![warn(missing_docs)]
