//! Mismatch discovery (`hilsim diagnose`): hold a real recording against the simulation of the
//! scenario it is a run of, locate where the two disagree beyond the sensors' noise, name the
//! physics the simulation left out from a catalogue of effects, fit it, and show the fit improve
//! on held-out data.
//!
//! One module per stage:
//! 1. [`align`]: the real trajectory, from `truth.csv` or estimated; the recording must be
//!    a run of the scenario.
//! 2. `residuals`: every reading against its prediction under the declared noise model.
//! 3. [`locate`]: tests of bias, spread and whiteness against range, bearing, incidence
//!    angle, object, time, speed, acceleration, turn rate…; the strongest is the location.
//! 4. [`explain`], `select`: each catalogued effect fitted by maximum likelihood on the
//!    training half and scored on the held-out half; effects named by forward selection on
//!    held-out data, several at once, then refitted jointly.
//! 5. [`show`]: the verdict as JSON and text, the held-out fit before and after, plots.
//!
//! The physics is behind the [`Physics`] trait, which `hilsim` implements from the simulator:
//! this crate never depends on it. Design and figures: `docs/diagnose.md`.

pub mod align;
mod catalogue;
mod conclude;
mod crab;
mod crisp_map;
mod diagnosis;
mod dropout;
mod error;
mod estimate;
pub mod explain;
mod floor;
mod health;
pub mod locate;
mod optimize;
mod outcome;
pub mod own_world;
mod physics;
mod plot;
mod residuals;
mod select;
pub mod self_test;
pub mod show;
mod sim_physics;
mod sparse_truth;
mod stamps;
pub mod stats;
mod trajectory;
mod wheel_spans;

pub use align::Alignment;
pub use catalogue::{
    DrawSource, Effect, Entry, ParamSpec, SearchLimits, SelfTestRange, Sensor, Variable,
};
pub use diagnosis::{diagnose, diagnose_with_progress, Stage};
pub use error::MismatchError;
pub use explain::{CandidateFit, RmseOver};
pub use floor::{ParseFloorError, SensorFloor};
pub use hilsim_recording::Pose;
pub use locate::{Evidence, Floors, TestKind};
pub use outcome::{
    Diagnosis, NamedEffect, Options, SensorSummary, Verdict, ESTIMATED_PATH_TIMING_S,
};
pub use physics::{
    Declared, DeclaredActuation, DeclaredLidar, Gaussian, Hypothesis, LidarPrediction, LidarQuery,
    Mixture, OdometryPrediction, Physics, SonarPrediction,
};
pub use plot::PlotData;
pub use residuals::Covariate;
pub use sim_physics::SimPhysics;
pub use trajectory::{wrap, Trajectory};
