//! The catalogue of effects `hilsim diagnose` knows (`interfaces.md`): each one a piece of
//! physics a simulation may leave out, the sensor it shows in, its parameters with the range the
//! fit searches and the range the self-test draws from (`params`), the scenario's
//! `[effects]` table that switches it on (`scenario`), and the sentence that says what was left
//! out (`sentences`). The one place in the diagnosis that knows an effect: adding one touches
//! its physics (`hilsim-sim`'s `[effects]`, `hilsim-lidar-emulator`'s `effects`) and its entry
//! here.

mod effect;
mod params;
mod scenario;
mod sensor;
mod sentences;

pub use effect::Effect;
pub(crate) use effect::MOUNT_YAW_RESOLUTION_DEG;
pub use params::{DrawSource, ParamSpec, SearchLimits, SelfTestRange};
pub(crate) use scenario::{mounted, range_bias, REFERENCE_REFLECTIVITY};
pub use sensor::Sensor;
