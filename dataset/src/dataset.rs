//! A dataset's definition: the base scenario, the seed, the number of runs and the varied
//! parameters, and from them each run's own scenario.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hilsim_sim::Scenario;
use sha2::{Digest, Sha256};
use toml::{Table, Value};

use crate::params::Params;
use crate::seed::{draw, run_seed, MAX_SEED};
use crate::{Error, Vary};

/// The most runs a dataset holds: `run-NNNNNN` directories have six digits, and a million runs
/// of a minute's recording (~5 MB each) are already ~5 TB. A count is checked before anything
/// is allocated for it.
pub const MAX_RUNS: u64 = 1_000_000;

/// N runs of one scenario, each with its own seed and its own draw of the varied parameters.
///
/// ```
/// use hilsim_dataset::{Dataset, Options};
/// let scenario = r#"
///     name = "park"
///     duration_s = 0.2
///     [robot]
///     start = { x = 0.0, y = 0.0 }
///     wheel_base_m = 0.23
///     [sensors.odometer]
///     noise_m = 0.01
/// "#;
/// let varies = vec!["robot.start.x=-1..1".parse()?];
/// let dataset = Dataset::from_toml(scenario, "park.toml".as_ref(), None, 3, varies)?;
/// let dir = tempfile::tempdir()?;
/// let summary = dataset.generate(dir.path(), &Options::default(), &mut ())?;
/// assert_eq!((summary.made, summary.failed), (3, 0));
/// assert!(dir.path().join("run-000002/scenario.toml").is_file());
/// let manifest = std::fs::read_to_string(dir.path().join("manifest.csv"))?;
/// assert!(manifest.starts_with("run,seed,robot.start.x,status,"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Dataset {
    origin: PathBuf,
    base: Table,
    params: Params,
}

/// Why one run could not be made. Recorded in the manifest; the other runs go on.
#[derive(Debug, Clone, PartialEq)]
pub struct RunFailure {
    /// One line: what was wrong (e.g. the varied scenario's validation error).
    pub reason: String,
}

impl Dataset {
    /// Reads the base scenario file; see [`Dataset::from_toml`].
    ///
    /// # Errors
    /// As [`Dataset::from_toml`], or the file cannot be read.
    pub fn load(
        scenario: &Path,
        seed: Option<u64>,
        runs: u64,
        varies: Vec<Vary>,
    ) -> Result<Self, Error> {
        let text = hilsim_sim::scenario::read_scenario_text(scenario)?;
        Self::from_toml(&text, scenario, seed, runs, varies)
    }

    /// A dataset of `runs` runs of the scenario `text` (named `origin` in errors), seeded with
    /// `seed` (default: the scenario's own `seed`), drawing each of `varies` per run.
    ///
    /// Everything is checked before any run is made: the scenario (file:line errors), that each
    /// vary's key leads to a number the scenario format knows, and that neither of its bounds is
    /// out of range for its key (each bound checked with the other keys at the scenario's values).
    /// Combinations can still fail (e.g. a start position inside a cylinder): those runs are
    /// recorded as failed.
    ///
    /// # Errors
    /// The scenario is invalid, `runs` is 0 or above [`MAX_RUNS`], the seed is above 2^63 − 1 (the largest TOML
    /// integer), a key is given twice, or a vary is unusable as described.
    pub fn from_toml(
        text: &str,
        origin: &Path,
        seed: Option<u64>,
        runs: u64,
        varies: Vec<Vary>,
    ) -> Result<Self, Error> {
        let scenario = Scenario::from_toml(text, origin)?;
        let base: Table = toml::from_str(text).map_err(|err| hilsim_sim::ScenarioError {
            file: origin.to_path_buf(),
            line: None,
            message: err.message().trim().to_string(),
        })?;
        if runs > MAX_RUNS {
            return Err(Error::Parameter(format!(
                "--runs: expected at most {MAX_RUNS} runs, found {runs}"
            )));
        }
        if runs == 0 {
            return Err(Error::Parameter(
                "--runs: expected at least 1 run".to_string(),
            ));
        }
        let seed = seed.unwrap_or(scenario.seed);
        if seed > MAX_SEED {
            return Err(Error::Parameter(format!(
                "--seed {seed}: expected at most {MAX_SEED} (2^63 − 1, the largest TOML integer)"
            )));
        }
        for (i, v) in varies.iter().enumerate() {
            if varies[..i].iter().any(|w| w.key() == v.key()) {
                return Err(v.error("the key is varied twice"));
            }
        }
        let params = Params {
            scenario_name: scenario.name.clone(),
            scenario_sha256: hex(&Sha256::digest(text.as_bytes())),
            seed,
            runs,
            varies,
        };
        let dataset = Self {
            origin: origin.to_path_buf(),
            base,
            params,
        };
        for v in &dataset.params.varies {
            dataset.check_vary(v)?;
        }
        Ok(dataset)
    }

    /// Sets `v` to each of its bounds in the base scenario: the key must be one the scenario
    /// format knows, with a number there, and neither bound may be refused for the key itself.
    fn check_vary(&self, v: &Vary) -> Result<(), Error> {
        for bound in [v.lo(), v.hi()] {
            let mut doc = self.base.clone();
            v.set(&mut doc, bound).map_err(|message| v.error(message))?;
            let text = toml::to_string(&doc).map_err(|err| v.error(err.to_string()))?;
            // The format first (unknown keys, wrong types): a key error, whatever the value.
            if let Err(err) = toml::from_str::<Scenario>(&text) {
                return Err(v.error(err.message().trim().replace('\n', " ")));
            }
            if let Err(err) = Scenario::from_toml(&text, &self.origin) {
                if err.message.starts_with(&format!("{}: ", v.key())) {
                    return Err(v.error(format!("at {bound}: {}", err.message)));
                }
            }
        }
        Ok(())
    }

    /// The parameters (what `dataset.toml` holds).
    #[must_use]
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The base scenario file, as given.
    #[must_use]
    pub fn origin(&self) -> &Path {
        &self.origin
    }

    /// Run `run`'s seed.
    #[must_use]
    pub fn run_seed(&self, run: u64) -> u64 {
        run_seed(self.params.seed, run)
    }

    /// Run `run`'s value of each varied key, in the order of the varies.
    #[must_use]
    pub fn values(&self, run: u64) -> Vec<f64> {
        self.params
            .varies
            .iter()
            .map(|v| draw(self.params.seed, run, v.key(), v.lo(), v.hi()))
            .collect()
    }

    /// Run `run`'s scenario file (`run-NNNNNN/scenario.toml`): the base scenario with the run's
    /// seed and varied values, and a comment saying where it came from. `hilsim record` of this
    /// file makes the run's recording again, byte for byte.
    ///
    /// # Errors
    /// Cannot happen for a dataset that [`Dataset::from_toml`] accepted (the keys were checked);
    /// reported as a run failure all the same.
    pub fn scenario_text(&self, run: u64) -> Result<String, RunFailure> {
        let seed = self.run_seed(run);
        let values = self.values(run);
        let mut doc = self.base.clone();
        doc.insert("seed".to_string(), Value::Integer(seed as i64));
        for (v, &x) in self.params.varies.iter().zip(&values) {
            v.set(&mut doc, x).map_err(|reason| RunFailure { reason })?;
        }
        let body = toml::to_string(&doc).map_err(|err| RunFailure {
            reason: err.to_string(),
        })?;
        let mut text = format!(
            "# Run {run} of a hilsim dataset of scenario `{}` (sha256 {}), dataset seed {}:\n\
             # this run's seed is {seed}",
            self.params.scenario_name, self.params.scenario_sha256, self.params.seed
        );
        for (v, x) in self.params.varies.iter().zip(&values) {
            let _ = write!(text, ", {} = {x}", v.key());
        }
        text.push_str(
            ".\n# `hilsim record scenario.toml --out DIR` makes this run's recording again, byte \
             for byte.\n\n",
        );
        text.push_str(&body);
        Ok(text)
    }

    /// Run `run`'s scenario, validated: its file text and the parsed scenario.
    ///
    /// # Errors
    /// The varied scenario is invalid (e.g. the robot starts inside a cylinder): the reason is
    /// the scenario check's message, which names the key.
    pub fn scenario(&self, run: u64) -> Result<(String, Scenario), RunFailure> {
        let text = self.scenario_text(run)?;
        let name = crate::layout::run_dir_name(run);
        let origin = PathBuf::from(name).join("scenario.toml");
        match Scenario::from_toml(&text, &origin) {
            Ok(s) => Ok((text, s)),
            Err(err) => Err(RunFailure {
                reason: err.message.replace('\n', " "),
            }),
        }
    }
}

/// Lowercase hex.
pub(crate) fn hex(bytes: &[u8]) -> String {
    let mut s = String::with_capacity(bytes.len() * 2);
    for b in bytes {
        let _ = write!(s, "{b:02x}");
    }
    s
}
