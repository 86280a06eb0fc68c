//! The paper's simulation study (Sec. 4.1–4.2), the pure-maths model with no physics: landmarks
//! in random positions, the sensor placed at equally spaced nominal positions along a straight
//! line and actually off them by σs (eq. (8)), bearings off by σθ (eq. (5)), ranges from the
//! polynomial model with heteroscedastic noise (eq. (3)). Shared by the tests, the reproduction
//! example and the benchmark, so that all three run the same model.
//!
//! Each run draws its own landmarks and noise from its own seed, so a Monte Carlo is the same
//! on one core or many.

mod result;
mod rng;
mod run;
mod setup;
mod simulate;
mod summary;

pub use result::{MseRatios, RunResult};
pub use rng::{run_seed, Xoshiro256pp};
pub use run::{monte_carlo, run_one};
pub use setup::{paper_beta, Setup, PAPER_ALPHA};
pub use simulate::{simulate, Trial};
pub use summary::{summarise, PositionStats, Summary};
