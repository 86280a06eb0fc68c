//! `DIR/dataset.toml`: the parameters that define a dataset. Resuming or merging compares them,
//! so that runs of two different datasets are never mixed in one directory.

use std::fs;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::{Error, Vary};

/// The file's format name.
pub const FORMAT: &str = "hilsim-dataset/1";

/// The parameters of a dataset: every run is a function of these and its index alone.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// The base scenario's `name`.
    pub scenario_name: String,
    /// SHA-256 of the base scenario file's bytes, lowercase hex.
    pub scenario_sha256: String,
    /// The dataset's seed `S` (run `r`'s seed is [`crate::run_seed`]`(S, r)`).
    pub seed: u64,
    /// The number of runs `N`.
    pub runs: u64,
    /// The varied parameters, in the order given (the manifest's columns).
    pub varies: Vec<Vary>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    format: String,
    generator: String,
    scenario_name: String,
    scenario_sha256: String,
    seed: u64,
    runs: u64,
    #[serde(default)]
    vary: Vec<VaryEntry>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct VaryEntry {
    key: String,
    lo: f64,
    hi: f64,
}

impl Params {
    /// The text of `dataset.toml`.
    #[must_use]
    pub fn to_toml(&self) -> String {
        let file = File {
            format: FORMAT.to_string(),
            generator: format!("hilsim-dataset {}", env!("CARGO_PKG_VERSION")),
            scenario_name: self.scenario_name.clone(),
            scenario_sha256: self.scenario_sha256.clone(),
            seed: self.seed,
            runs: self.runs,
            vary: self
                .varies
                .iter()
                .map(|v| VaryEntry {
                    key: v.key().to_string(),
                    lo: v.lo(),
                    hi: v.hi(),
                })
                .collect(),
        };
        let body = toml::to_string(&file).unwrap_or_default();
        format!(
            "# A hilsim dataset (`hilsim dataset`): run r of it is a function of these parameters \
             and r alone.\n# Resuming or merging requires the same parameters.\n{body}"
        )
    }

    /// Reads `dataset.toml` at `path`.
    ///
    /// # Errors
    /// The file cannot be read or is not a `dataset.toml`.
    pub fn read(path: &Path) -> Result<Self, Error> {
        let text = fs::read_to_string(path).map_err(|err| Error::io(path, err))?;
        let file: File = toml::from_str(&text).map_err(|err| {
            Error::corrupt(
                path,
                format!("not a dataset.toml: {}", err.message().trim()),
            )
        })?;
        if file.format != FORMAT {
            return Err(Error::corrupt(
                path,
                format!("format `{}`, expected `{FORMAT}`", file.format),
            ));
        }
        let varies = file
            .vary
            .iter()
            .map(|v| Vary::new(&v.key, v.lo, v.hi))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|err| Error::corrupt(path, err.to_string()))?;
        Ok(Self {
            scenario_name: file.scenario_name,
            scenario_sha256: file.scenario_sha256,
            seed: file.seed,
            runs: file.runs,
            varies,
        })
    }

    /// What differs between the parameters stored at `path` (`self`) and `asked`, as one
    /// sentence; `None` when they are the same dataset.
    #[must_use]
    pub fn difference(&self, asked: &Params) -> Option<String> {
        let show = |v: &[Vary]| {
            if v.is_empty() {
                "no --vary".to_string()
            } else {
                v.iter()
                    .map(|v| format!("--vary {v}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            }
        };
        if self.scenario_sha256 != asked.scenario_sha256 {
            Some(format!(
                "made from another scenario file (`{}`, sha256 {}…; this one is `{}`, sha256 {}…)",
                self.scenario_name,
                &self.scenario_sha256[..self.scenario_sha256.len().min(12)],
                asked.scenario_name,
                &asked.scenario_sha256[..asked.scenario_sha256.len().min(12)],
            ))
        } else if self.seed != asked.seed {
            Some(format!(
                "made with --seed {}, not {}",
                self.seed, asked.seed
            ))
        } else if self.runs != asked.runs {
            Some(format!(
                "made with --runs {}, not {}",
                self.runs, asked.runs
            ))
        } else if self.varies != asked.varies {
            Some(format!(
                "made with {}, not {}",
                show(&self.varies),
                show(&asked.varies)
            ))
        } else {
            None
        }
    }
}
