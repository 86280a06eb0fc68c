//! Merging the shards of a dataset: their run directories into one directory, and one manifest
//! rebuilt from what is there.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use hilsim_recording::{replace_dir_atomically, write_owned_file_atomically};
use rayon::prelude::*;

use crate::content::{scan_run, RunContent};
use crate::generate::build_pool;
use crate::layout::{
    entries, is_manifest, is_shard_manifest, leftover, remove_leftovers, run_dir_name, run_dirs,
    DATASET_FILE, MANIFEST_FILE,
};
use crate::manifest::{self, Outcome, Row};
use crate::params::{Params, MAX_PARAMS_BYTES};
use crate::{draw, run_seed, Error};

/// What a merge did.
#[derive(Debug, Clone, PartialEq)]
pub struct MergeSummary {
    /// Runs in the dataset (`N`).
    pub runs: u64,
    /// Runs whose directories are in the output (made).
    pub made: u64,
    /// Runs recorded as failed by a shard (and with no directory anywhere).
    pub failed: u64,
    /// Runs neither made nor recorded as failed (a shard has not finished, or was not given).
    pub missing: u64,
    /// Run directories brought into the output from the other directories.
    pub copied: u64,
    /// The manifest written.
    pub manifest: PathBuf,
}

/// Merges the dataset directories `sources` into `out` and rebuilds `out/manifest.csv`.
///
/// `out` may be new, or a dataset directory itself (then it is one of the sources: with no
/// `sources`, its own shards' runs and manifests are merged in place, when the shards shared one
/// directory). Every directory must hold the same dataset (`dataset.toml` parameters). Before
/// anything is written, every run is scanned where it is and checked against each content hash
/// the manifests of all the directories record for it: a run that differs (truncated, say) is
/// refused, and nothing is merged, so a refused run is never brought into `out`. Then the run
/// directories missing from `out` are brought in (files hard-linked when on the same file
/// system, else copied; each checked again and renamed into place when complete). The manifest
/// then has a row for each run directory in `out` (content hash recomputed) and for each run a
/// source's manifest records as failed; the shard manifests in `out` are removed (the merged
/// manifest holds their rows). Leftovers of interrupted writes in `out` are removed: merge after
/// every shard has finished.
///
/// # Errors
/// A directory is not a dataset or holds another one, a run differs between two directories or
/// from the content hash a source's manifest recorded, or a file cannot be read or written.
pub fn merge(
    out: &Path,
    sources: &[PathBuf],
    jobs: Option<NonZeroUsize>,
) -> Result<MergeSummary, Error> {
    let out_is_dataset = out.join(DATASET_FILE).is_file();
    let others = other_sources(out, sources)?;
    let mut all: Vec<PathBuf> = Vec::new();
    if out_is_dataset {
        all.push(out.to_path_buf());
    }
    all.extend(others.iter().cloned());
    if all.is_empty() {
        return Err(Error::mismatch(
            out,
            "not a dataset (no dataset.toml), and no dataset directories were given to merge \
             into it",
        ));
    }
    let (reference_file, params) = same_dataset(&all)?;
    if !out_is_dataset {
        check_output(out)?;
    }

    // First, reading only: where each run is (in `out`, else in the first source that has it;
    // the ones in more than one place noted), every run scanned there and checked against each
    // content hash the manifests record for it. Nothing is written unless every run passes, so
    // a run refused is never brought into `out`.
    let pool = build_pool(jobs)?;
    let in_out = if out_is_dataset {
        run_dirs(out, params.runs)?
    } else {
        Vec::new()
    };
    let (located, duplicates) = locate_runs(out, &in_out, &others, params.runs)?;
    let scanned: Vec<(PathBuf, u64, RunContent)> = pool.install(|| {
        located
            .par_iter()
            .map(|(dir, r)| scan_run(dir).map(|c| (dir.clone(), *r, c)))
            .collect::<Result<_, _>>()
    })?;
    let recorded = recorded_hashes(&all)?;
    for (dir, r, c) in &scanned {
        check_recorded(&recorded, *r, dir, c)?;
    }
    check_duplicates(&duplicates, &scanned, &pool)?;
    let mut rows: BTreeMap<u64, Row> = BTreeMap::new();
    let mut copies: Vec<(PathBuf, u64, String)> = Vec::new();
    for (dir, r, c) in scanned {
        if in_out.binary_search(&r).is_err() {
            copies.push((dir, r, c.sha256.clone()));
        }
        rows.insert(r, row(&params, r, Outcome::Made(c)));
    }
    let made = rows.len() as u64;
    let failures = recorded_failures(&all, &params, &rows)?;
    let failed = failures.len() as u64;
    for (r, reason) in failures {
        rows.insert(r, row(&params, r, Outcome::Failed(reason)));
    }

    // Then the writes: the runs `out` lacks, each checked again as it is brought in.
    if !out_is_dataset {
        start_output(out, &reference_file)?;
    }
    remove_leftovers(out, |_| true)?;
    pool.install(|| {
        copies
            .par_iter()
            .try_for_each(|(src, r, sha)| copy_run(src, &out.join(run_dir_name(*r)), sha))
    })?;
    let keys: Vec<&str> = params.varies.iter().map(|v| v.key()).collect();
    let manifest_path = out.join(MANIFEST_FILE);
    write_owned_file_atomically(&manifest_path, manifest::render(&keys, &rows).as_bytes())?;
    for (name, path) in entries(out)? {
        if is_shard_manifest(&name) {
            fs::remove_file(&path).map_err(|err| Error::io(&path, err))?;
        }
    }
    Ok(MergeSummary {
        runs: params.runs,
        made,
        failed,
        missing: params.runs - rows.len() as u64,
        copied: copies.len() as u64,
        manifest: manifest_path,
    })
}

/// Run directories and the run each holds.
type RunPlaces = Vec<(PathBuf, u64)>;

/// Where each run is: in `out` (`in_out`), else in the first of `others` that has it; and the
/// copies of runs found in more than one place (to be compared).
fn locate_runs(
    out: &Path,
    in_out: &[u64],
    others: &[PathBuf],
    runs: u64,
) -> Result<(RunPlaces, RunPlaces), Error> {
    let mut present: BTreeSet<u64> = in_out.iter().copied().collect();
    let mut located: Vec<(PathBuf, u64)> = in_out
        .iter()
        .map(|&r| (out.join(run_dir_name(r)), r))
        .collect();
    let mut duplicates: Vec<(PathBuf, u64)> = Vec::new();
    for s in others {
        for r in run_dirs(s, runs)? {
            let src = s.join(run_dir_name(r));
            if present.insert(r) {
                located.push((src, r));
            } else {
                duplicates.push((src, r));
            }
        }
    }
    Ok((located, duplicates))
}

/// The sources other than `out`, each once.
fn other_sources(out: &Path, sources: &[PathBuf]) -> Result<Vec<PathBuf>, Error> {
    let out_canon = fs::canonicalize(out).ok();
    let mut others: Vec<PathBuf> = Vec::new();
    let mut seen: Vec<PathBuf> = Vec::new();
    for s in sources {
        let canon = fs::canonicalize(s).map_err(|err| Error::io(s, err))?;
        if Some(&canon) == out_canon.as_ref() || seen.contains(&canon) {
            continue;
        }
        seen.push(canon);
        others.push(s.clone());
    }
    Ok(others)
}

/// `out`, not a dataset, must be new or empty (leftovers of interrupted writes aside).
fn check_output(out: &Path) -> Result<(), Error> {
    if !out.exists() {
        return Ok(());
    }
    let clutter = entries(out)?
        .into_iter()
        .filter(|(name, _)| leftover(name).is_none())
        .count();
    if clutter > 0 {
        return Err(Error::mismatch(
            out,
            "exists and is not a dataset (no dataset.toml): choose a new or empty directory",
        ));
    }
    Ok(())
}

/// Makes `out`, new or empty ([`check_output`]), a dataset directory: a copy of
/// `reference_file`.
fn start_output(out: &Path, reference_file: &Path) -> Result<(), Error> {
    fs::create_dir_all(out).map_err(|err| Error::io(out, err))?;
    let text =
        hilsim_recording::read_small_text(reference_file, MAX_PARAMS_BYTES, "a dataset.toml")?;
    write_owned_file_atomically(&out.join(DATASET_FILE), text.as_bytes())?;
    Ok(())
}

/// Run `r`'s manifest row in the dataset `params`.
fn row(params: &Params, r: u64, outcome: Outcome) -> Row {
    Row {
        run: r,
        seed: run_seed(params.seed, r),
        values: params
            .varies
            .iter()
            .map(|v| draw(params.seed, r, v.key(), v.lo(), v.hi()))
            .collect(),
        outcome,
    }
}

/// Each run directory found in more than one place must hold what the one merged (`located`,
/// scanned) holds.
fn check_duplicates(
    duplicates: &[(PathBuf, u64)],
    located: &[(PathBuf, u64, RunContent)],
    pool: &rayon::ThreadPool,
) -> Result<(), Error> {
    let dup_hashes: Vec<(PathBuf, u64, RunContent)> = pool.install(|| {
        duplicates
            .par_iter()
            .map(|(src, r)| scan_run(src).map(|c| (src.clone(), *r, c)))
            .collect::<Result<_, _>>()
    })?;
    let by_run: BTreeMap<u64, &(PathBuf, u64, RunContent)> =
        located.iter().map(|l| (l.1, l)).collect();
    for (src, r, c) in dup_hashes {
        let Some((dir, _, merged)) = by_run.get(&r) else {
            continue;
        };
        if merged.sha256 != c.sha256 {
            return Err(Error::mismatch(
                &src,
                format!(
                    "differs from {} (content hash {}): the same run made twice differently",
                    dir.display(),
                    merged.sha256
                ),
            ));
        }
    }
    Ok(())
}

/// The content hashes the manifests of `dirs` record, by run: each manifest with the hash.
fn recorded_hashes(dirs: &[PathBuf]) -> Result<BTreeMap<u64, Vec<(PathBuf, String)>>, Error> {
    let mut all: BTreeMap<u64, Vec<(PathBuf, String)>> = BTreeMap::new();
    for d in dirs {
        for (r, mut hashes) in manifest::recorded_hashes(d)? {
            all.entry(r).or_default().append(&mut hashes);
        }
    }
    Ok(all)
}

/// Run `r`, found in `dir` with content `c`, must have the content hash every manifest that
/// records one gives it.
fn check_recorded(
    recorded: &BTreeMap<u64, Vec<(PathBuf, String)>>,
    r: u64,
    dir: &Path,
    c: &RunContent,
) -> Result<(), Error> {
    for (manifest, sha) in recorded.get(&r).into_iter().flatten() {
        if *sha != c.sha256 {
            return Err(Error::mismatch(
                manifest,
                format!(
                    "run {r} has content hash {sha} here, but {} has {}: the run's files changed \
                     after it was made; nothing was merged (resume its shard to make it again)",
                    dir.display(),
                    c.sha256
                ),
            ));
        }
    }
    Ok(())
}

/// The failures the manifests of `dirs` record, of runs made nowhere.
fn recorded_failures(
    dirs: &[PathBuf],
    params: &Params,
    rows: &BTreeMap<u64, Row>,
) -> Result<BTreeMap<u64, String>, Error> {
    let mut failures: BTreeMap<u64, String> = BTreeMap::new();
    for d in dirs {
        for (name, path) in entries(d)? {
            if !is_manifest(&name) {
                continue;
            }
            for e in manifest::read(&path)? {
                if e.run < params.runs && e.sha256.is_none() && !rows.contains_key(&e.run) {
                    failures.entry(e.run).or_insert(e.reason);
                }
            }
        }
    }
    Ok(failures)
}

/// Reads every directory's `dataset.toml`; all must define the same dataset. Returns the first
/// file and its parameters.
fn same_dataset(dirs: &[PathBuf]) -> Result<(PathBuf, Params), Error> {
    let mut reference: Option<(PathBuf, Params)> = None;
    for d in dirs {
        let file = d.join(DATASET_FILE);
        // `exists`, not `is_file`: a dataset.toml that is a device is refused by its reader, which
        // says so.
        if !file.exists() {
            return Err(Error::mismatch(
                d,
                "not a dataset directory (no dataset.toml)",
            ));
        }
        let p = Params::read(&file)?;
        match &reference {
            None => reference = Some((file, p)),
            Some((first, q)) => {
                if let Some(diff) = q.difference(&p) {
                    return Err(Error::mismatch(
                        &file,
                        format!(
                            "another dataset than {}: that one was {diff}",
                            first.display()
                        ),
                    ));
                }
            }
        }
    }
    reference.ok_or_else(|| Error::Parameter("no dataset directories to merge".to_string()))
}

/// Brings run directory `src` to `dst`: its files hard-linked (never modified in place, so
/// sharing them is safe) or, across file systems, copied; checked to have the content hash `sha`
/// (what `src` had when it was checked: it may not change meanwhile); renamed into place when
/// complete, and not at all when the check fails.
fn copy_run(src: &Path, dst: &Path, sha: &str) -> Result<(), Error> {
    replace_dir_atomically(dst, |tmp| -> Result<(), Error> {
        for (name, path) in entries(src)? {
            if !path.is_file() {
                return Err(Error::corrupt(
                    src,
                    format!("`{name}` is not a file: a run directory holds only files"),
                ));
            }
            let to = tmp.join(&name);
            if fs::hard_link(&path, &to).is_err() {
                fs::copy(&path, &to).map_err(|err| Error::io(&to, err))?;
            }
        }
        let now = scan_run(tmp)?.sha256;
        if now != sha {
            return Err(Error::mismatch(
                src,
                format!(
                    "changed while it was being merged (content hash {sha}, now {now}); nothing \
                     of it was merged"
                ),
            ));
        }
        Ok(())
    })
}
