//! The names of things in a dataset directory:
//!
//! ```text
//! DIR/dataset.toml                      the parameters
//! DIR/manifest.csv                      one row per run made or failed (whole dataset, or merged)
//! DIR/manifest-shard-I-of-K.csv         the same for the runs of shard I/K
//! DIR/run-000042/                       a complete run: a recording plus its scenario.toml
//! DIR/.run-000042.tmp.PID/              a run being written (renamed when complete)
//! ```

use std::fs;
use std::path::{Path, PathBuf};

use crate::{Error, Shard};

/// The parameters' file name.
pub const DATASET_FILE: &str = "dataset.toml";

/// The whole dataset's manifest.
pub const MANIFEST_FILE: &str = "manifest.csv";

/// The directory name of run `run`: `run-` and at least six digits.
#[must_use]
pub fn run_dir_name(run: u64) -> String {
    format!("run-{run:06}")
}

/// The run a directory name stands for, when it is exactly what [`run_dir_name`] writes.
#[must_use]
pub fn parse_run_dir_name(name: &str) -> Option<u64> {
    let digits = name.strip_prefix("run-")?;
    if digits.len() < 6 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let run: u64 = digits.parse().ok()?;
    (run_dir_name(run) == name).then_some(run)
}

/// The manifest a process making `shard` writes: `manifest.csv` for the whole dataset,
/// `manifest-shard-I-of-K.csv` for a shard (so shards sharing a directory never overwrite each
/// other's).
#[must_use]
pub fn manifest_name(shard: Shard) -> String {
    if shard.is_all() {
        MANIFEST_FILE.to_string()
    } else {
        format!("manifest-shard-{}-of-{}.csv", shard.index(), shard.count())
    }
}

/// Whether `name` is a manifest (whole or shard).
pub(crate) fn is_manifest(name: &str) -> bool {
    name == MANIFEST_FILE || is_shard_manifest(name)
}

pub(crate) fn is_shard_manifest(name: &str) -> bool {
    name.starts_with("manifest-shard-") && name.ends_with(".csv")
}

/// What a hidden leftover of an interrupted write in the dataset directory belongs to.
#[derive(Debug, PartialEq)]
pub(crate) enum Leftover {
    /// `.run-NNNNNN.tmp.PID` or `.run-NNNNNN.old.PID`: a run directory being written.
    Run(u64),
    /// `.NAME.tmp.PID`: the file `NAME` being written (a manifest, `dataset.toml`).
    File(String),
}

/// Parses the names [`hilsim_recording::replace_dir_atomically`] and
/// [`hilsim_recording::write_file_atomically`] give their temporaries: `.NAME.TAG.PID`.
pub(crate) fn leftover(name: &str) -> Option<Leftover> {
    let rest = name.strip_prefix('.')?;
    let (stem, pid) = rest.rsplit_once('.')?;
    if pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    if let Some(run) = stem.strip_suffix(".old") {
        return parse_run_dir_name(run).map(Leftover::Run);
    }
    let target = stem.strip_suffix(".tmp")?;
    match parse_run_dir_name(target) {
        Some(run) => Some(Leftover::Run(run)),
        None => Some(Leftover::File(target.to_string())),
    }
}

/// Removes the leftovers in `dir` that `owns` says are ours. Nothing else is touched.
pub(crate) fn remove_leftovers(dir: &Path, owns: impl Fn(&Leftover) -> bool) -> Result<u64, Error> {
    let mut removed = 0;
    for (name, path) in entries(dir)? {
        let Some(what) = leftover(&name) else {
            continue;
        };
        // A live process's temporary is its work in progress (another shard's, say).
        let pid = name.rsplit_once('.').and_then(|(_, pid)| pid.parse().ok());
        if !owns(&what) || pid.is_some_and(crate::lock::alive) {
            continue;
        }
        let result = if path.is_dir() {
            fs::remove_dir_all(&path)
        } else {
            fs::remove_file(&path)
        };
        match result {
            Ok(()) => removed += 1,
            Err(err) if err.kind() == std::io::ErrorKind::NotFound => {}
            Err(err) => return Err(Error::io(&path, err)),
        }
    }
    Ok(removed)
}

/// The run directories in `dir` (those named exactly `run-NNNNNN`, below `runs`), sorted.
pub(crate) fn run_dirs(dir: &Path, runs: u64) -> Result<Vec<u64>, Error> {
    let mut found = Vec::new();
    for (name, path) in entries(dir)? {
        let Some(run) = parse_run_dir_name(&name) else {
            continue;
        };
        if run >= runs {
            continue;
        }
        if !path.is_dir() {
            return Err(Error::corrupt(
                &path,
                "expected a run directory, found a file",
            ));
        }
        found.push(run);
    }
    found.sort_unstable();
    Ok(found)
}

/// The entries of `dir` as (name, path); names that are not UTF-8 are skipped (nothing of ours).
pub(crate) fn entries(dir: &Path) -> Result<Vec<(String, PathBuf)>, Error> {
    let mut out = Vec::new();
    for entry in fs::read_dir(dir).map_err(|err| Error::io(dir, err))? {
        let entry = entry.map_err(|err| Error::io(dir, err))?;
        if let Ok(name) = entry.file_name().into_string() {
            out.push((name, entry.path()));
        }
    }
    out.sort();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_names_round_trip_and_nothing_else_parses() {
        assert_eq!(run_dir_name(42), "run-000042");
        assert_eq!(run_dir_name(1_234_567), "run-1234567");
        for r in [0, 42, 999_999, 1_234_567] {
            assert_eq!(parse_run_dir_name(&run_dir_name(r)), Some(r));
        }
        for bad in [
            "run-42",
            "run-0000042",
            "run-00004a",
            "Run-000042",
            "run-000042x",
        ] {
            assert_eq!(parse_run_dir_name(bad), None, "{bad}");
        }
    }

    #[test]
    fn leftovers_are_recognised() {
        assert_eq!(leftover(".run-000042.tmp.123"), Some(Leftover::Run(42)));
        assert_eq!(leftover(".run-000042.old.9"), Some(Leftover::Run(42)));
        assert_eq!(
            leftover(".manifest.csv.tmp.77"),
            Some(Leftover::File("manifest.csv".to_string()))
        );
        assert_eq!(leftover("run-000042"), None);
        assert_eq!(leftover(".run-000042.tmp."), None);
        assert_eq!(leftover(".hidden"), None);
    }

    #[test]
    fn manifest_names_follow_the_shard() {
        assert_eq!(manifest_name(Shard::ALL), "manifest.csv");
        let s = Shard::new(2, 5).unwrap();
        assert_eq!(manifest_name(s), "manifest-shard-2-of-5.csv");
        assert!(is_manifest("manifest-shard-2-of-5.csv") && is_manifest("manifest.csv"));
    }
}
