//! Making a dataset, or the share of it one machine makes: on all cores, resumable, each run
//! written to a temporary directory and renamed when complete.

use std::collections::BTreeMap;
use std::fs;
use std::num::NonZeroUsize;
use std::panic::AssertUnwindSafe;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{
    write_file_atomically, write_owned_file_atomically, Recording, RecordingStream,
};
use rayon::prelude::*;

use crate::content::{scan_run, RunContent};
use crate::dataset::RunFailure;
use crate::layout::{
    entries, leftover, manifest_name, remove_leftovers, run_dir_name, run_dirs, Leftover,
    DATASET_FILE,
};
use crate::lock::WriterLock;
use crate::manifest::{self, Outcome, Row};
use crate::params::Params;
use crate::progress::{Plan, Progress, RunReport, Summary};
use crate::{Dataset, Error, Shard};

/// The manifest is rewritten at most this often while runs complete (and always at the end): an
/// interruption loses at most this much of it, and the next call rebuilds it from the run
/// directories. A large manifest is rewritten less often: at most a tenth of the time goes to it.
const MANIFEST_INTERVAL: Duration = Duration::from_millis(500);

/// How to make a dataset: how many threads, and which share of the runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Options {
    /// Worker threads; `None`: one per core.
    pub jobs: Option<NonZeroUsize>,
    /// The share of the runs to make (default: all).
    pub shard: Shard,
    /// Make only this run (in the shard's manifest, with the others already there).
    pub only: Option<u64>,
}

impl Options {
    /// Worker threads as `--jobs` asks for them (`None`: one per core).
    ///
    /// # Errors
    /// Zero threads.
    pub fn jobs(jobs: Option<usize>) -> Result<Option<NonZeroUsize>, Error> {
        let zero = || Error::Parameter("--jobs 0: expected at least 1".into());
        jobs.map(|j| NonZeroUsize::new(j).ok_or_else(zero))
            .transpose()
    }
}

impl Default for Options {
    fn default() -> Self {
        Self {
            jobs: None,
            shard: Shard::ALL,
            only: None,
        }
    }
}

/// What one worker sends back: the run, how it ended (or an error that stops the dataset), and
/// its wall time.
type Finished = (u64, Result<Result<RunContent, RunFailure>, Error>, Duration);

/// Rewrites the manifest from the rows.
type WriteManifest<'a> = dyn Fn(&BTreeMap<u64, Row>) -> Result<(), Error> + 'a;

impl Dataset {
    /// Makes the dataset's runs in `dir`, or the share `options` selects, skipping those already
    /// made; see the crate docs for the layout.
    ///
    /// In order: `dir` is created, or checked to hold this dataset (its `dataset.toml`, else it
    /// must be empty); leftovers of interrupted writes of this share are removed; the runs already
    /// made are rescanned (hashes recomputed), those whose files differ from the content hash a
    /// manifest recorded for them (truncated, say) removed, and the manifest rebuilt from the
    /// others; then the missing (and removed) runs are made on `options.jobs` threads in index
    /// order. The manifest is rewritten as runs complete (at most every 0.5 s) and at the end. A
    /// run that fails is recorded with its reason and the others go on; runs that failed before
    /// are tried again.
    ///
    /// # Errors
    /// `dir` holds something else, a run directory no manifest vouches for is not a complete run,
    /// a run other than `options.only` differs from its manifest, `options` name a run outside
    /// the dataset or shard, or a file cannot be written (the runs made so far stay, and the
    /// manifest is written for them).
    pub fn generate(
        &self,
        dir: &Path,
        options: &Options,
        progress: &mut dyn Progress,
    ) -> Result<Summary, Error> {
        let start = Instant::now();
        let p = self.params();
        let shard = options.shard;
        check_only(options, p)?;
        let pool = build_pool(options.jobs)?;
        let jobs = pool.current_num_threads();
        open_dir(dir, p)?;
        let manifest_file = manifest_name(shard);
        let manifest_path = dir.join(&manifest_file);
        let _lock = WriterLock::take(dir, &manifest_file)?;
        remove_leftovers(dir, |l| match l {
            Leftover::Run(r) => *r < p.runs && shard.contains(*r),
            Leftover::File(name) => *name == manifest_file,
        })?;

        let (mut rows, damaged) = self.rows_made_before(dir, &pool, shard)?;
        if options.only.is_some() {
            if let Some(&r) = damaged.iter().find(|&&r| Some(r) != options.only) {
                return Err(Error::corrupt(
                    &dir.join(run_dir_name(r)),
                    "its files differ from the content hash its manifest recorded: resume \
                     without --run to make it again",
                ));
            }
        }
        // Removed before the manifest loses their rows (so an interruption now cannot leave a
        // damaged run that no manifest vouches for); they are made again below.
        for &r in &damaged {
            let path = dir.join(run_dir_name(r));
            fs::remove_dir_all(&path).map_err(|err| Error::io(&path, err))?;
        }
        let to_make: Vec<u64> = match options.only {
            Some(r) if rows.contains_key(&r) => Vec::new(),
            Some(r) => vec![r],
            None => (0..p.runs)
                .filter(|&r| shard.contains(r) && !rows.contains_key(&r))
                .collect(),
        };
        // Failures recorded before, of runs not tried again now (only with `only`).
        if let Some(only) = options.only {
            self.keep_failures_recorded(&manifest_path, shard, only, &mut rows)?;
        }
        let keys: Vec<&str> = p.varies.iter().map(|v| v.key()).collect();
        let write_manifest = |rows: &BTreeMap<u64, Row>| {
            write_owned_file_atomically(&manifest_path, manifest::render(&keys, rows).as_bytes())
                .map_err(Error::from)
        };
        write_manifest(&rows)?;
        let share = match options.only {
            Some(_) => 1,
            None => (0..p.runs).filter(|&r| shard.contains(r)).count() as u64,
        };
        let skipped = share - to_make.len() as u64;
        progress.planned(&Plan {
            share,
            skipped,
            to_make: to_make.len() as u64,
            remade: damaged.len() as u64,
            jobs,
        });
        let (made, failed) =
            self.make_runs(dir, &pool, &to_make, &mut rows, &write_manifest, progress)?;
        Ok(Summary {
            share,
            made,
            skipped,
            failed,
            elapsed: start.elapsed(),
            manifest: manifest_path,
        })
    }

    /// The rows of the shard's runs made before, as their files say now (hashes recomputed), and
    /// the runs whose files differ from the content hash a manifest in `dir` recorded for them
    /// (truncated, say, or unreadable as a run): those are to be made again. A run directory no
    /// manifest vouches for is trusted when it reads as a complete run (it was renamed into
    /// place only when complete), and named as an error when it does not.
    fn rows_made_before(
        &self,
        dir: &Path,
        pool: &rayon::ThreadPool,
        shard: Shard,
    ) -> Result<(BTreeMap<u64, Row>, Vec<u64>), Error> {
        let made: Vec<u64> = run_dirs(dir, self.params().runs)?
            .into_iter()
            .filter(|&r| shard.contains(r))
            .collect();
        let recorded = manifest::recorded_hashes(dir)?;
        let scanned: Vec<(u64, Result<RunContent, Error>)> = pool.install(|| {
            made.par_iter()
                .map(|&r| (r, scan_run(&dir.join(run_dir_name(r)))))
                .collect()
        });
        let mut rows = BTreeMap::new();
        let mut damaged = Vec::new();
        for (r, scan) in scanned {
            let vouched = recorded.get(&r);
            match (scan, vouched) {
                (Ok(c), None) => {
                    rows.insert(r, self.row(r, Outcome::Made(c)));
                }
                (Ok(c), Some(hashes)) if hashes.iter().all(|(_, h)| *h == c.sha256) => {
                    rows.insert(r, self.row(r, Outcome::Made(c)));
                }
                (Ok(_) | Err(Error::Corrupt { .. }), Some(_)) => damaged.push(r),
                (Err(err), _) => return Err(err),
            }
        }
        Ok((rows, damaged))
    }

    /// Adds to `rows` the failures the shard's manifest recorded, of runs other than `only` and
    /// not made since.
    fn keep_failures_recorded(
        &self,
        manifest_path: &Path,
        shard: Shard,
        only: u64,
        rows: &mut BTreeMap<u64, Row>,
    ) -> Result<(), Error> {
        if !manifest_path.is_file() {
            return Ok(());
        }
        for e in manifest::read(manifest_path)? {
            if e.sha256.is_none()
                && e.run != only
                && e.run < self.params().runs
                && shard.contains(e.run)
                && !rows.contains_key(&e.run)
            {
                rows.insert(e.run, self.row(e.run, Outcome::Failed(e.reason)));
            }
        }
        Ok(())
    }

    /// Makes the runs `to_make` on the pool's threads in index order, adding their rows to
    /// `rows` and rewriting the manifest as they complete and at the end. Returns the numbers of
    /// runs made and failed; the first error stops the workers.
    fn make_runs(
        &self,
        dir: &Path,
        pool: &rayon::ThreadPool,
        to_make: &[u64],
        rows: &mut BTreeMap<u64, Row>,
        write_manifest: &WriteManifest<'_>,
        progress: &mut dyn Progress,
    ) -> Result<(u64, u64), Error> {
        let jobs = pool.current_num_threads();
        let next = AtomicUsize::new(0);
        let stop = AtomicBool::new(false);
        let (tx, rx) = mpsc::channel::<Finished>();
        let mut fatal: Option<Error> = None;
        let (mut made_now, mut failed_now) = (0, 0);
        let mut pacer = ManifestPacer::new();
        pool.in_place_scope(|scope| {
            for _ in 0..jobs.min(to_make.len()) {
                let tx = tx.clone();
                let (next, stop) = (&next, &stop);
                scope.spawn(move |_| {
                    while !stop.load(Ordering::Relaxed) {
                        let Some(&r) = to_make.get(next.fetch_add(1, Ordering::Relaxed)) else {
                            break;
                        };
                        let t = Instant::now();
                        let result = self.make_run(dir, r);
                        if tx.send((r, result, t.elapsed())).is_err() {
                            break;
                        }
                    }
                });
            }
            drop(tx);
            for (r, result, elapsed) in rx {
                let outcome = match result {
                    Ok(Ok(content)) => {
                        made_now += 1;
                        Outcome::Made(content)
                    }
                    Ok(Err(failure)) => {
                        failed_now += 1;
                        Outcome::Failed(failure.reason)
                    }
                    Err(err) => {
                        stop.store(true, Ordering::Relaxed);
                        fatal.get_or_insert(err);
                        continue;
                    }
                };
                let report = RunReport {
                    run: r,
                    seed: self.run_seed(r),
                    failure: match &outcome {
                        Outcome::Failed(reason) => Some(reason.clone()),
                        Outcome::Made(_) => None,
                    },
                    elapsed,
                };
                rows.insert(r, self.row(r, outcome));
                if let Err(err) = pacer.changed(rows, write_manifest) {
                    stop.store(true, Ordering::Relaxed);
                    fatal.get_or_insert(err);
                }
                progress.run_finished(&report);
            }
        });
        if pacer.dirty {
            let written = write_manifest(rows);
            if fatal.is_none() {
                written?;
            }
        }
        match fatal {
            Some(err) => Err(err),
            None => Ok((made_now, failed_now)),
        }
    }

    /// Run `run`'s recording and scenario file text, in memory (nothing is written).
    ///
    /// # Errors
    /// The run's varied scenario is invalid, or its sensor model makes no sense.
    pub fn emulate(&self, run: u64) -> Result<(String, Recording), RunFailure> {
        let (text, scenario) = self.scenario(run)?;
        let emulation = Emulation::new(&scenario, scenario.seed).map_err(|err| RunFailure {
            reason: format!("sensor model: {err}"),
        })?;
        Ok((text, emulation.run().recording))
    }

    /// Makes run `run` in `dir/run-NNNNNN`: its recording (streamed to disk as it is taken) and
    /// `scenario.toml`, written into a temporary directory that is renamed when complete. A
    /// panic in the models is a failure of this run, not of the dataset.
    fn make_run(&self, dir: &Path, run: u64) -> Result<Result<RunContent, RunFailure>, Error> {
        let target = dir.join(run_dir_name(run));
        match std::panic::catch_unwind(AssertUnwindSafe(|| self.record_run(&target, run))) {
            Ok(made) => made,
            Err(payload) => {
                let what = payload
                    .downcast_ref::<&str>()
                    .map(|s| (*s).to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                Ok(Err(RunFailure {
                    reason: format!("internal error: the run panicked: {what}"),
                }))
            }
        }
    }

    /// Records run `run` at `target` (see [`Dataset::make_run`]); its content, scanned before
    /// the directory is put in place.
    fn record_run(&self, target: &Path, run: u64) -> Result<Result<RunContent, RunFailure>, Error> {
        let (text, scenario) = match self.scenario(run) {
            Ok(made) => made,
            Err(failure) => return Ok(Err(failure)),
        };
        let emulation = match Emulation::new(&scenario, scenario.seed) {
            Ok(emulation) => emulation,
            Err(err) => {
                return Ok(Err(RunFailure {
                    reason: format!("sensor model: {err}"),
                }))
            }
        };
        let mut stream =
            RecordingStream::create(target, emulation.meta().clone(), emulation.tables())?;
        emulation.record_into(&mut stream)?;
        let mut content = None;
        stream.finish_with(|tmp| -> Result<(), Error> {
            write_file_atomically(&tmp.join("scenario.toml"), text.as_bytes())?;
            content = Some(scan_run(tmp)?);
            Ok(())
        })?;
        let content = content.ok_or_else(|| Error::corrupt(target, "the run was not scanned"))?;
        Ok(Ok(content))
    }

    /// Run `run`'s manifest row.
    pub(crate) fn row(&self, run: u64, outcome: Outcome) -> Row {
        Row {
            run,
            seed: self.run_seed(run),
            values: self.values(run),
            outcome,
        }
    }
}

/// `options.only`, when given, must name a run of the dataset and of the shard.
fn check_only(options: &Options, p: &Params) -> Result<(), Error> {
    let shard = options.shard;
    if let Some(r) = options.only {
        if r >= p.runs {
            return Err(Error::Parameter(format!(
                "--run {r}: the dataset's runs are 0 to {}",
                p.runs - 1
            )));
        }
        if !shard.contains(r) {
            return Err(Error::Parameter(format!(
                "--run {r} is not in shard {shard}"
            )));
        }
    }
    Ok(())
}

/// When to rewrite the manifest while runs complete: at most every [`MANIFEST_INTERVAL`], or
/// ten times the last rewrite's cost when that is longer.
struct ManifestPacer {
    last_write: Instant,
    write_cost: Duration,
    /// Rows changed since the last rewrite.
    dirty: bool,
}

impl ManifestPacer {
    fn new() -> Self {
        Self {
            last_write: Instant::now(),
            write_cost: Duration::ZERO,
            dirty: false,
        }
    }

    /// A row changed: rewrites the manifest if its time has come.
    fn changed(
        &mut self,
        rows: &BTreeMap<u64, Row>,
        write_manifest: &WriteManifest<'_>,
    ) -> Result<(), Error> {
        self.dirty = true;
        if self.last_write.elapsed() < MANIFEST_INTERVAL.max(self.write_cost * 10) {
            return Ok(());
        }
        let t = Instant::now();
        let written = write_manifest(rows);
        if written.is_ok() {
            self.dirty = false;
        }
        self.write_cost = t.elapsed();
        self.last_write = Instant::now();
        written
    }
}

/// A thread pool of `jobs` threads (default: one per core).
pub(crate) fn build_pool(jobs: Option<NonZeroUsize>) -> Result<rayon::ThreadPool, Error> {
    let n = jobs.map_or(0, NonZeroUsize::get);
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .thread_name(|i| format!("dataset-{i}"))
        .build()
        .map_err(|err| Error::Parameter(format!("cannot start {n} worker threads: {err}")))
}

/// Creates `dir` for the dataset `params`, or checks that it holds this dataset.
///
/// Shards may start at the same instant on a fresh directory (a Slurm job array): one of them
/// creates `dataset.toml` (whole, with create-new semantics) and the others find it and check it;
/// none removes another's temporaries.
fn open_dir(dir: &Path, params: &Params) -> Result<(), Error> {
    match fs::metadata(dir) {
        Ok(m) if !m.is_dir() => return Err(Error::mismatch(dir, "not a directory")),
        Ok(_) => {}
        Err(err) if err.kind() == std::io::ErrorKind::NotFound => {
            fs::create_dir_all(dir).map_err(|err| Error::io(dir, err))?;
        }
        Err(err) => return Err(Error::io(dir, err)),
    }
    let file = dir.join(DATASET_FILE);
    if !file.exists() {
        // Only an empty directory becomes a dataset (leftovers of writing dataset.toml aside).
        // Listed before looking for dataset.toml again: whatever a shard writes, it writes after
        // dataset.toml exists, so what was listed while there was none is not a shard's.
        let others = entries(dir)?
            .into_iter()
            .filter(|(name, _)| leftover(name) != Some(Leftover::File(DATASET_FILE.to_string())))
            .count();
        if !file.exists() {
            if others > 0 {
                return Err(Error::mismatch(
                    dir,
                    "exists and is not a dataset (no dataset.toml): choose a new or empty \
                     directory",
                ));
            }
            if params.create_file(&file)? {
                return Ok(());
            }
        }
    }
    let stored = Params::read_settled(&file)?;
    match stored.difference(params) {
        None => Ok(()),
        Some(diff) => Err(Error::mismatch(
            &file,
            format!(
                "this directory holds another dataset: it was {diff}; give the same \
                 parameters to resume it, or choose another --out"
            ),
        )),
    }
}
