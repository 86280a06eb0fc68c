//! `DIR/dataset.toml`: the parameters that define a dataset. Resuming or merging compares them,
//! so that runs of two different datasets are never mixed in one directory.

use std::collections::hash_map::RandomState;
use std::fs;
use std::hash::BuildHasher;
use std::io::{ErrorKind, Write as _};
use std::path::{Path, PathBuf};
use std::time::Duration;

use serde::{Deserialize, Serialize};

use crate::{Error, Vary};

/// The file's format name.
pub const FORMAT: &str = "hilsim-dataset/1";

/// The largest `dataset.toml` read: one is a few hundred bytes (a `--vary` a line), and it is
/// read whole, as a scenario file (also at most 1 MiB) is.
pub const MAX_PARAMS_BYTES: u64 = 1 << 20;

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
        let text = hilsim_recording::read_small_text(path, MAX_PARAMS_BYTES, "a dataset.toml")?;
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

    /// Creates `DIR/dataset.toml` at `path` holding these parameters, whole or not at all, unless
    /// it exists: returns whether this call created it. Safe when several processes (shards
    /// started at the same instant, on one machine or many sharing a file system) try at once:
    /// exactly one creates it, the others find it.
    ///
    /// The text is written to a temporary file of a name no other writer uses, then hard-linked to
    /// `path` (which fails when `path` exists: create-new semantics, and a reader never sees it
    /// half-written). Where the file system has no hard links, `path` is created with
    /// create-new semantics and written in place; [`Params::read_settled`] waits for it.
    /// Temporaries of other writers are never touched.
    ///
    /// # Errors
    /// A file cannot be written.
    pub(crate) fn create_file(&self, path: &Path) -> Result<bool, Error> {
        let text = self.to_toml();
        let (tmp, mut file) = unique_temporary(path)?;
        let written = file
            .write_all(text.as_bytes())
            .and_then(|()| file.sync_all());
        drop(file);
        if let Err(err) = written {
            let _ = fs::remove_file(&tmp);
            return Err(Error::io(&tmp, err));
        }
        let linked = fs::hard_link(&tmp, path);
        let _ = fs::remove_file(&tmp);
        match linked {
            Ok(()) => Ok(true),
            Err(err) if err.kind() == ErrorKind::AlreadyExists => Ok(false),
            Err(_) => {
                // No hard links on this file system: create-new, then write in place.
                match fs::OpenOptions::new()
                    .write(true)
                    .create_new(true)
                    .open(path)
                {
                    Ok(mut file) => {
                        file.write_all(text.as_bytes())
                            .and_then(|()| file.sync_all())
                            .map_err(|err| Error::io(path, err))?;
                        Ok(true)
                    }
                    Err(err) if err.kind() == ErrorKind::AlreadyExists => Ok(false),
                    Err(err) => Err(Error::io(path, err)),
                }
            }
        }
    }

    /// [`Params::read`], waiting up to 2 s while the file does not parse: another process may
    /// be writing it in place (see [`Params::create_file`]). A complete file reads at once.
    ///
    /// # Errors
    /// As [`Params::read`], once the wait is over.
    pub(crate) fn read_settled(path: &Path) -> Result<Self, Error> {
        const TRIES: u32 = 40;
        const PAUSE: Duration = Duration::from_millis(50);
        let mut tries = 1;
        loop {
            match Self::read(path) {
                Err(Error::Corrupt { .. }) if tries < TRIES => {
                    tries += 1;
                    std::thread::sleep(PAUSE);
                }
                other => return other,
            }
        }
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

/// A new temporary file beside `path`, named `.NAME.tmp.DIGITS` (a leftover of writing `NAME`,
/// see [`crate::layout`]) with digits no other writer picks: a random number, and the file
/// created with create-new semantics (so a clash is seen, and another name tried).
fn unique_temporary(path: &Path) -> Result<(PathBuf, fs::File), Error> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // `RandomState` is seeded from the operating system's randomness (and differs per thread).
    let random = RandomState::new();
    let mut attempt = 0_u32;
    loop {
        let digits = random.hash_one((std::process::id(), attempt));
        let tmp = path.with_file_name(format!(".{name}.tmp.{digits}"));
        match fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(file) => return Ok((tmp, file)),
            Err(err) if err.kind() == ErrorKind::AlreadyExists && attempt < 100 => attempt += 1,
            Err(err) => return Err(Error::io(&tmp, err)),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Barrier;

    use super::*;

    fn params(seed: u64) -> Params {
        Params {
            scenario_name: "room".to_string(),
            scenario_sha256: "ab".repeat(32),
            seed,
            runs: 4,
            varies: vec![Vary::new("robot.start.x", -1.0, 1.0).unwrap()],
        }
    }

    #[test]
    fn writers_at_once_create_dataset_toml_exactly_once_and_whole() {
        const WRITERS: usize = 8;
        for round in 0..20 {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("dataset.toml");
            let barrier = Barrier::new(WRITERS);
            let created: Vec<bool> = std::thread::scope(|scope| {
                let handles: Vec<_> = (0..WRITERS)
                    .map(|_| {
                        scope.spawn(|| {
                            barrier.wait();
                            let p = params(7);
                            let created = p.create_file(&path).unwrap();
                            // Whoever created it, every writer reads it whole at once.
                            assert_eq!(Params::read(&path).unwrap(), p);
                            created
                        })
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().unwrap()).collect()
            });
            assert_eq!(created.iter().filter(|&&c| c).count(), 1, "round {round}");
            assert_eq!(fs::read_to_string(&path).unwrap(), params(7).to_toml());
            let names: Vec<_> = fs::read_dir(dir.path())
                .unwrap()
                .map(|e| e.unwrap().file_name())
                .collect();
            assert_eq!(names, ["dataset.toml"], "no temporaries left");
        }
        // An existing file is never replaced, whatever it holds.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("dataset.toml");
        assert!(params(1).create_file(&path).unwrap());
        assert!(!params(2).create_file(&path).unwrap());
        assert_eq!(Params::read(&path).unwrap(), params(1));
    }
}
