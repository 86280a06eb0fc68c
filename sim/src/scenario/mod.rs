//! Scenario files: the world, the robot, what it does, its sensors, and what must hold.
//!
//! [`Scenario::load`] parses a TOML file into typed structs and validates it before anything
//! runs. Every error is one line naming the file, the line and what was expected.
//!
//! ```
//! use hilsim_sim::Scenario;
//! let s = Scenario::from_toml(
//!     r#"
//!     name = "park"
//!     duration_s = 1.0
//!     [robot]
//!     start = { x = 0.0, y = 0.0 }
//!     wheel_base_m = 0.23
//!     "#,
//!     "inline.toml".as_ref(),
//! )
//! .unwrap();
//! assert_eq!(s.physics.step_hz, 100.0);
//! let err = Scenario::from_toml("name = 1", "bad.toml".as_ref()).unwrap_err();
//! assert!(err.to_string().starts_with("bad.toml:1: "));
//! ```

mod check;
mod clearance;
mod effects;
mod error;
mod files;
mod link;
mod load;
mod locate;
pub mod metrics;
mod schema;
mod validate;
mod validate_effects;

pub use clearance::Overlap;
pub use effects::*;
pub use error::ScenarioError;
pub use files::beside;
pub use link::{Link, LinkFaults, SPARSE_BELOW_RPM, SPIN_UP_FROM_RPM, XV11_CAPTURE};
pub use load::read_scenario_text;
pub use schema::*;
pub use validate::{MAX_ANGLE_DEG, MAX_RUN_S, MAX_SENSOR_RATE_HZ, MAX_WORLD_M};

#[cfg(test)]
mod tests;
