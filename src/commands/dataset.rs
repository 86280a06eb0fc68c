//! `hilsim dataset SCENARIO --runs N --out DIR [--seed S] [--jobs J] [--shard I/K | --run R]
//! [--vary KEY=LO..HI]…` and `hilsim dataset merge --out DIR [SRC…]`.
//!
//! Glue: the arguments are validated into the library's types before anything is opened; the
//! library makes the runs; this prints progress (a bar on a terminal, plain lines otherwise) and
//! the summary. Exit codes: 0 all runs made, 1 a run failed (recorded in the manifest) or, for
//! merge, a run is failed or missing, 2 bad input.

use std::io::{IsTerminal, Write};
use std::process::ExitCode;

use anyhow::{anyhow, Result};
use hilsim_dataset::{merge, Dataset, Options, Plan, Progress, RunReport, Shard, Vary};

use crate::cli::{DatasetArgs, DatasetCommand, MergeArgs};

pub fn dataset(args: &DatasetArgs, out: &mut dyn Write) -> Result<ExitCode> {
    if let Some(DatasetCommand::Merge(m)) = &args.command {
        return merge_command(m, out);
    }
    // Validate everything before opening anything.
    let shard = args.shard.as_deref().map(str::parse::<Shard>).transpose()?;
    let varies = Vary::parse_all(&args.vary)?;
    let jobs = Options::jobs(args.jobs)?;
    let (Some(scenario), Some(runs), Some(dir)) = (&args.scenario, args.runs, &args.out) else {
        return Err(anyhow!("dataset: SCENARIO, --runs and --out are required"));
    };
    let dataset = Dataset::load(scenario, args.seed, runs, varies)?;
    let options = Options {
        jobs,
        shard: shard.unwrap_or(Shard::ALL),
        only: args.run,
    };
    let mut reporter = Reporter {
        out: &mut *out,
        bar: None,
        terminal: std::io::stdout().is_terminal(),
        done: 0,
        planned: 0,
    };
    let summary = dataset.generate(dir, &options, &mut reporter);
    drop(reporter.bar.take());
    let summary = summary?;
    writeln!(out, "{}", summary.line(dir))?;
    Ok(super::exit_code(summary.failed == 0))
}

fn merge_command(args: &MergeArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let s = merge(&args.out, &args.sources, Options::jobs(args.jobs)?)?;
    writeln!(out, "{}", s.line(&args.out))?;
    let complete = s.failed == 0 && s.missing == 0;
    Ok(super::exit_code(complete))
}

/// Progress on stdout: a bar when it is a terminal, else one line per run.
struct Reporter<'a> {
    out: &'a mut dyn Write,
    bar: Option<crate::progress::Progress>,
    terminal: bool,
    done: u64,
    planned: u64,
}

impl Progress for Reporter<'_> {
    fn planned(&mut self, plan: &Plan) {
        self.planned = plan.to_make;
        if self.terminal && plan.to_make > 0 {
            let template = "{bar:40} {pos}/{len} runs  {rate} runs/s  eta {eta}  {msg}";
            let bar = crate::progress::Progress::on_stdout(true, Some(plan.to_make), template);
            bar.println(plan.to_string());
            self.bar = Some(bar);
        } else {
            let _ = writeln!(self.out, "{plan}");
        }
    }

    fn run_finished(&mut self, run: &RunReport) {
        self.done += 1;
        let Some(bar) = &self.bar else {
            let _ = writeln!(self.out, "{}", run.line(self.done, self.planned));
            return;
        };
        if let Some(reason) = &run.failure {
            let name = hilsim_dataset::layout::run_dir_name(run.run);
            bar.println(format!("{name} failed: {reason}"));
            bar.message(format!("{name} failed"));
        }
        bar.inc();
    }
}
