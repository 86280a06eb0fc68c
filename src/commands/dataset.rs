//! `hilsim dataset SCENARIO --runs N --out DIR [--seed S] [--jobs J] [--shard I/K | --run R]
//! [--vary KEY=LO..HI]…` and `hilsim dataset merge --out DIR [SRC…]`.
//!
//! Glue: the arguments are validated into the library's types before anything is opened; the
//! library makes the runs; this prints progress (a bar on a terminal, plain lines otherwise) and
//! the summary. Exit codes: 0 all runs made, 1 a run failed (recorded in the manifest) or, for
//! merge, a run is failed or missing, 2 bad input.

use std::io::{IsTerminal, Write};
use std::num::NonZeroUsize;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{anyhow, Result};
use clap::Subcommand;
use hilsim_dataset::{merge, Dataset, Options, Plan, Progress, RunReport, Shard, Vary};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};

/// `hilsim dataset`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct DatasetArgs {
    #[command(subcommand)]
    pub command: Option<DatasetCommand>,
    /// Scenario file: the base of every run.
    #[arg(required = true)]
    pub scenario: Option<PathBuf>,
    /// Number of runs N (runs 0 to N-1).
    #[arg(long, required = true, value_name = "N")]
    pub runs: Option<u64>,
    /// The dataset directory: created, or resumed when it holds this dataset.
    #[arg(long, required = true, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The dataset's seed S (default: the scenario's `seed`); run r's seed derives from (S, r).
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "J")]
    pub jobs: Option<usize>,
    /// Make only shard I of K: the runs r with r mod K = I-1 (I counts from 1).
    #[arg(long, value_name = "I/K", conflicts_with = "run")]
    pub shard: Option<String>,
    /// Make only run R (e.g. to make one run again on its own).
    #[arg(long, value_name = "R")]
    pub run: Option<u64>,
    /// Draw this scenario number per run, uniformly in [LO, HI] (repeatable), e.g.
    /// `robot.start.x=0.5..1.5`.
    #[arg(long, value_name = "KEY=LO..HI")]
    pub vary: Vec<String>,
}

#[derive(Debug, Subcommand)]
pub enum DatasetCommand {
    /// Merge dataset directories (the shards of one dataset) into one, and rebuild its manifest.
    Merge(MergeArgs),
}

#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// The merged dataset directory (new or empty, or one of the shards' own directory).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Dataset directories to bring into DIR (none: merge DIR's own shards in place).
    pub sources: Vec<PathBuf>,
    /// Worker threads for hashing and copying (default: one per core).
    #[arg(long, value_name = "J")]
    pub jobs: Option<usize>,
}

pub fn dataset(args: &DatasetArgs, out: &mut dyn Write) -> Result<ExitCode> {
    if let Some(DatasetCommand::Merge(m)) = &args.command {
        return merge_command(m, out);
    }
    // Validate everything before opening anything.
    let shard = args
        .shard
        .as_deref()
        .map(str::parse::<Shard>)
        .transpose()?
        .unwrap_or(Shard::ALL);
    let varies = args
        .vary
        .iter()
        .map(|s| s.parse::<Vary>())
        .collect::<Result<Vec<_>, _>>()?;
    let jobs = jobs(args.jobs)?;
    let (Some(scenario), Some(runs), Some(dir)) = (&args.scenario, args.runs, &args.out) else {
        return Err(anyhow!("dataset: SCENARIO, --runs and --out are required"));
    };
    let dataset = Dataset::load(scenario, args.seed, runs, varies)?;
    let options = Options {
        jobs,
        shard,
        only: args.run,
    };
    let terminal = std::io::stdout().is_terminal();
    let mut reporter = Reporter {
        out: &mut *out,
        bar: None,
        terminal,
        done: 0,
        planned: 0,
    };
    let summary = dataset.generate(dir, &options, &mut reporter);
    if let Some(bar) = reporter.bar.take() {
        bar.finish_and_clear();
    }
    let summary = summary?;
    writeln!(
        out,
        "dataset {}: {} made, {} skipped (made before), {} failed, in {:.1} s ({:.2} runs/s); \
         manifest {}",
        dir.display(),
        summary.made,
        summary.skipped,
        summary.failed,
        summary.elapsed.as_secs_f64(),
        summary.runs_per_s(),
        summary.manifest.display()
    )?;
    Ok(if summary.failed == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn merge_command(args: &MergeArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let jobs = jobs(args.jobs)?;
    let s = merge(&args.out, &args.sources, jobs)?;
    writeln!(
        out,
        "merged {}: {} runs: {} made, {} failed, {} missing ({} run directories brought in); \
         manifest {}",
        args.out.display(),
        s.runs,
        s.made,
        s.failed,
        s.missing,
        s.copied,
        s.manifest.display()
    )?;
    Ok(if s.failed == 0 && s.missing == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn jobs(jobs: Option<usize>) -> Result<Option<NonZeroUsize>> {
    jobs.map(|j| NonZeroUsize::new(j).ok_or_else(|| anyhow!("--jobs 0: expected at least 1")))
        .transpose()
}

/// Progress on stdout: a bar when it is a terminal, else one line per run.
struct Reporter<'a> {
    out: &'a mut dyn Write,
    bar: Option<ProgressBar>,
    terminal: bool,
    done: u64,
    planned: u64,
}

impl Progress for Reporter<'_> {
    fn planned(&mut self, plan: &Plan) {
        self.planned = plan.to_make;
        let mut line = format!(
            "{} runs in this share: {} made before, {} to make on {} thread(s)",
            plan.share, plan.skipped, plan.to_make, plan.jobs
        );
        if plan.remade > 0 {
            line += &format!(
                " ({} of them made before but damaged since: their files differ from the \
                 manifest's hash)",
                plan.remade
            );
        }
        if self.terminal && plan.to_make > 0 {
            let bar =
                ProgressBar::with_draw_target(Some(plan.to_make), ProgressDrawTarget::stdout());
            if let Ok(style) =
                ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {rate}  eta {eta}  {msg}")
            {
                bar.set_style(style.with_key(
                    "rate",
                    |state: &ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = write!(w, "{:.2} runs/s", state.per_sec());
                    },
                ));
            }
            bar.println(line);
            self.bar = Some(bar);
        } else {
            let _ = writeln!(self.out, "{line}");
        }
    }

    fn run_finished(&mut self, run: &RunReport) {
        self.done += 1;
        let name = hilsim_dataset::layout::run_dir_name(run.run);
        if let Some(bar) = &self.bar {
            if let Some(reason) = &run.failure {
                bar.println(format!("{name} failed: {reason}"));
                bar.set_message(format!("{name} failed"));
            }
            bar.inc(1);
            return;
        }
        let status = match &run.failure {
            None => format!("made in {}", seconds(run.elapsed)),
            Some(reason) => format!("failed: {reason}"),
        };
        let _ = writeln!(
            self.out,
            "[{}/{}] {name} (seed {}) {status}",
            self.done, self.planned, run.seed
        );
    }
}

fn seconds(d: Duration) -> String {
    format!("{:.2} s", d.as_secs_f64())
}
