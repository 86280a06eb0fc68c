//! The physics of the mismatch catalogue on the sensor side: what a scenario's `[effects]`
//! tables switch on (`hilsim_sim::scenario::Effects`). Every effect is off by default, so the
//! nominal sensors are exactly the ones their tables declare. Each file derives its effect and
//! names its source; the range bias changes the range model's polynomial (`range_bias.rs`), the drive's motor lag lives in `hilsim-sim` (`MotorLag`), the lidar's motion
//! skew in its timing (`lidar.rs`), its dropout in which readings it reports (`dropout.rs`, drawn
//! by the lidar from a stream of its own), the sonar's beam width in its cone (`sonar.rs`).
//!
//! The functions are pure (no randomness, no clock), so `hilsim diagnose` evaluates exactly the
//! physics that made the data when it fits an effect's parameters.

mod dropout;
mod incidence;
mod lidar;
mod mixed_pixels;
mod mounting;
mod range_bias;
mod reflectivity;
mod speed_of_sound;
mod warmup;
mod wheel_slip;

pub use dropout::{dropout_probability, dropout_probability_of, ReturnLogs};
pub use incidence::{incidence_error_m, tan_incidence, MAX_INCIDENCE_DEG};
pub use lidar::{BeamReturn, LidarEffects};
pub use mixed_pixels::footprint_range_m;
pub use mounting::{real_mount, stamped_s};
pub use range_bias::real_bias;
pub use reflectivity::range_walk_m;
pub use speed_of_sound::{sonar_range_scale, speed_of_sound_mps};
pub use warmup::warmup_error_m;
pub use wheel_slip::{braking_change_mps, slip_travel_m};
