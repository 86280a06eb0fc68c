//! The simulated world of hilsim: scenario files, a rapier2d world of walls, cylinders and
//! boards, a differential-drive robot on a fixed-step simulation clock, ground truth, and the
//! seeded random streams every component draws from.
//!
//! ```
//! use hilsim_sim::{Scenario, Simulation};
//! let scenario = Scenario::from_toml(
//!     r#"
//!     name = "one-metre"
//!     [robot]
//!     start = { x = 0.0, y = 0.0 }
//!     wheel_base_m = 0.23
//!     [[drive]]
//!     speed_mps = 0.5
//!     distance_m = 1.0
//!     "#,
//!     "inline.toml".as_ref(),
//! )
//! .unwrap();
//! let mut sim = Simulation::new(&scenario);
//! while sim.step().is_some() {}
//! assert!((sim.pose().x - 1.0).abs() < 1e-3);
//! ```
#![warn(missing_docs)]

mod actuation;
pub mod drive;
mod kinematics;
mod motor_lag;
mod numeric_csv;
pub mod occupancy;
pub mod recorded_path;
pub mod replay;
pub mod rng;
pub mod scan_schedule;
pub mod scenario;
mod simulation;
pub mod world;

pub use drive::{DriveProgram, WheelCommand};
pub use hilsim_recording::pose::{self, Pose};
pub use motor_lag::MotorLag;
pub use occupancy::{MapBuilder, MapError, MapHit, OccupancyMap};
pub use scenario::{Scenario, ScenarioError};
pub use simulation::{exact_time_s, Collision, Simulation, StepState};
pub use world::{Obstacle, RayHit, World};
