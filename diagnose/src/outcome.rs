//! What a diagnosis takes and gives: its options, the verdict and the diagnosis.

use hilsim_recording::TruthSample;

use crate::align::Alignment;
use crate::catalogue::{Effect, Sensor};
use crate::explain::CandidateFit;
use crate::locate::{Evidence, Floors};
use crate::plot::PlotData;

/// Settings of the diagnosis. The defaults are the ones `docs/diagnose.md` derives and the
/// self-test measures.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Family-wise false-alarm level of the locate tests (Bonferroni over all of them).
    pub alpha: f64,
    /// Held-out log-likelihood gain over "none" (nats) an effect needs to be named.
    pub min_gain: f64,
    /// The practical-significance floors: a departure below them is no mismatch.
    pub floors: Floors,
    /// The effects tried (default: the whole catalogue).
    pub effects: Vec<Effect>,
    /// Training readings per sensor used to fit an effect (evenly thinned beyond this). The
    /// default, 6,000, fits a lidar effect's parameters to a standard error well under the
    /// self-test's 20 % (`--self-test 20 --seed 1 --reality independent`: median error 0.4 %,
    /// the same as with 15,000) in 2.2 times less time; the held-out score uses every reading.
    pub max_fit_rows: usize,
    /// Training readings per sensor the coarse grid of a fit is searched on (evenly thinned
    /// from the same half); the search goes on from the grid's best points on
    /// [`Options::max_fit_rows`]. The grid's points are far apart, and their log-likelihoods
    /// differ by far more than this thinning's noise: with 1,500 the varied reality's 40
    /// trials (`--self-test 40 --seed 1 --reality varied`) name the same effects, with the
    /// same false alarms and parameters within 20 %, as with the grid on every training
    /// reading.
    pub grid_fit_rows: usize,
    /// Share of a sensor's readings that are outliers to the simulation (the outlier component
    /// explains them better than the prediction) above which the recording "does not align".
    pub misaligned_share: f64,
    /// The timing the trajectory the sonar and the encoders are judged along is known to,
    /// seconds: a delay of theirs (or of the lidar it was estimated from), or a wheel slip's
    /// gain (encoders leading it by `g v`, a delay's mirror), within it is not told from the
    /// trajectory's own. 0 against
    /// `truth.csv`; the diagnosis sets [`ESTIMATED_PATH_TIMING_S`] against a path estimated
    /// from the lidar.
    pub path_timing_s: f64,
    /// How well the encoders' stamps give when each reading was counted, seconds: a delay of
    /// theirs, or a wheel slip's gain, within it is not told from the stamps' own scatter (see
    /// `stamps.rs`). 0 by default; the diagnosis raises it to the recording's measured scatter
    /// of its encoders' stamps.
    pub encoder_timing_s: f64,
    /// The least offset of its position a lidar mount must have to be named, metres: 0 against
    /// `truth.csv` (the mount's own departure decides); the diagnosis sets
    /// [`ESTIMATED_MOUNT_MIN_M`] against a path estimated from the lidar.
    pub mount_min_m: f64,
    /// The least share of readings a lidar dropout must lose, beyond those lost at random,
    /// over the tenth of the readings it loses most, to be named: a unit whose far or grazing
    /// readings a scan matcher or a map builder gets a twentieth fewer of is not a different
    /// unit to them, and two simulators' validity rules near a range limit differ by that.
    pub dropout_min_share: f64,
}

/// How well the timing of a path estimated from the lidar is known, seconds. Each revolution's
/// correction is held at the revolution's middle and the dead reckoning follows the commands
/// between them, so the path lags or leads the robot by a few milliseconds wherever the
/// robot's response to its commands or a lidar effect bends it: beside a motor lag, an incidence
/// or a speed of sound the encoders' delay fits up to about 12 ms, in faithful runs a few
/// milliseconds (`--self-test 100 --only none --without-truth`); the self-test's concealed
/// delays are 20–80 ms.
pub const ESTIMATED_PATH_TIMING_S: f64 = 0.015;

/// The least offset of a lidar mount's position named against a path estimated from the lidar,
/// metres, whether the mount is fitted in the lidar or through the sonar and the encoders. The
/// path takes up most of a mount, and it is bent systematically by a lidar effect the matching
/// does not model (an incidence, a reflectivity walk, motion skew), which a mount of a few
/// millimetres mimics: 2–8 mm "mounts", with a meaningless yaw, fit beside an incidence, a motion
/// skew, a reflectivity walk or a sonar delay. The self-test conceals 1–3 cm in each of x and y.
pub const ESTIMATED_MOUNT_MIN_M: f64 = 0.01;

impl Default for Options {
    fn default() -> Self {
        Self {
            alpha: 0.01,
            min_gain: 10.0,
            floors: Floors::default(),
            effects: Effect::ALL.to_vec(),
            max_fit_rows: 6_000,
            grid_fit_rows: 1_500,
            misaligned_share: 0.5,
            path_timing_s: 0.0,
            encoder_timing_s: 0.0,
            mount_min_m: 0.0,
            dropout_min_share: 0.05,
        }
    }
}

/// The answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The recording agrees with the simulation within its noise.
    None,
    /// A catalogued effect explains the mismatch.
    Effect(Effect),
    /// A mismatch is located but no catalogued effect explains it.
    Unexplained,
    /// A mismatch is located within what the world's own error can make (a map's cells): the
    /// world is as likely off there as the sensor.
    WorldMismatch,
}

impl Verdict {
    /// The name in the JSON's `effect` key.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Verdict::None => "none",
            Verdict::Effect(e) => e.name(),
            Verdict::Unexplained => "unexplained",
            Verdict::WorldMismatch => "world_mismatch",
        }
    }
}

/// A named effect: its fit and where its sensor departs from the simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedEffect {
    /// The fit.
    pub fit: CandidateFit,
    /// Where the mismatch it explains is located (its sensor's strongest structure under the
    /// nominal model).
    pub located: Option<Evidence>,
}

/// One sensor's held-out residuals under the nominal model.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorSummary {
    /// The sensor.
    pub sensor: Sensor,
    /// Readings compared (both halves).
    pub readings: usize,
    /// Held-out RMSE of the nominal residuals, metres.
    pub heldout_rmse_m: f64,
    /// The noise floor there, metres.
    pub noise_floor_m: f64,
    /// The strongest test's normal score.
    pub strongest: f64,
    /// What its readings were judged against: `truth.csv`, a lidar-estimated path, or (the
    /// drive's) the commands against one of those.
    pub reference: &'static str,
}

/// The diagnosis of one recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnosis {
    /// The answer.
    pub verdict: Verdict,
    /// Where the residuals stop being noise (the strongest evidence), when they do.
    pub located: Option<Evidence>,
    /// One sentence: what physics was left out (or why none or no effect is named).
    pub explanation: String,
    /// The primary named effect's fit (the first of `effects`).
    pub fitted: Option<CandidateFit>,
    /// Every effect named, strongest held-out gain first (each scored against the others of
    /// its sensor), with where its sensor's mismatch is located.
    pub effects: Vec<NamedEffect>,
    /// Every located mismatch no named effect explains (at most one a sensor: the strongest
    /// structure left in its residuals under its named effects), with its size.
    pub unexplained: Vec<Evidence>,
    /// Every located mismatch within what the world's own error can make (an occupancy map's
    /// cells): the world as likely off there as the sensor (at most one a sensor).
    pub world: Vec<Evidence>,
    /// Every candidate tried, best held-out score first.
    pub candidates: Vec<CandidateFit>,
    /// Each sensor compared.
    pub sensors: Vec<SensorSummary>,
    /// The significant evidence under the nominal model, strongest first.
    pub evidence: Vec<Evidence>,
    /// The score a test had to reach.
    pub threshold: f64,
    /// Where the real trajectory came from.
    pub alignment: Alignment,
    /// What else the user should know.
    pub notes: Vec<String>,
    /// Residuals against the located variable, before and after the fix (held-out half).
    pub plots: Vec<PlotData>,
    /// The trajectory every sensor was judged against when it was estimated from the lidar
    /// (the recording has no `truth.csv`): the last one, under the named lidar effects and
    /// put back by a mount or delay seen through the path; `None` against `truth.csv`.
    pub estimated_path: Option<Vec<TruthSample>>,
}

impl Diagnosis {
    /// Whether a mismatch was found.
    #[must_use]
    pub fn mismatch(&self) -> bool {
        self.verdict != Verdict::None
    }
}
