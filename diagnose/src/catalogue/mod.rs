//! The catalogue of effects `hilsim diagnose` knows (`interfaces.md`): each one a piece of
//! physics a simulation may leave out. [`Effect`] names them; each one's [`Entry`] (a file in
//! `entries/`) says the sensor it shows in, the variables its mechanism acts through, its
//! parameters with the range the fit searches and the range the self-test draws from
//! (`params`), the least departure from its absence that names it, the scenario's `[effects]`
//! table that switches it on, and the sentence that says what was left out. The one place in
//! the diagnosis that knows an effect: adding one touches its physics (`hilsim-sim`'s
//! `[effects]`, `hilsim-lidar-emulator`'s `effects`), its entry file (listed in
//! `entries/mod.rs`), its variant of [`Effect`] with its place in [`Effect::ALL`], and the
//! match in [`Effect::entry`].

mod effect;
mod entries;
mod entry;
mod params;
mod sensor;

pub use effect::Effect;
pub(crate) use entries::{mounted, range_bias, MOUNT_YAW_RESOLUTION_DEG, REFERENCE_REFLECTIVITY};
pub use entry::{Entry, Variable};
pub use params::{DrawSource, ParamSpec, SearchLimits, SelfTestRange};
pub use sensor::Sensor;
