//! `hilsim diagnose [--sim SCENARIO] --real RECORDING [--calibration FILE] [--json] [--report DIR]`
//! (without `--sim`, in the world built from the recording's own scans) and `hilsim diagnose --self-test N [--seed S] [--sim SCENARIO] [--json]`.
//!
//! Exit codes: 0 when a verdict is reached (`none`, an effect, or `unexplained`: each is an
//! answer; with `--fail-on-mismatch` only `none`, else 1); 2 on bad input, including a recording
//! the diagnosis refuses (too short, no sensor in common, not a run of the scenario), with one
//! line naming the file and the reason. The self-test exits 1 when it misses one of its goals.

use std::io::Write;
use std::path::Path;
use std::process::ExitCode;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{anyhow, bail, Context, Result};
use hilsim_diagnose::self_test::{self, on_log, Plan};
use hilsim_diagnose::{own_world, show, Floors, Options, SimPhysics};
use hilsim_recording::Recording;
use hilsim_report::check_report_dir;
use hilsim_sim::Scenario;

use crate::cli::DiagnoseArgs;
use crate::progress::Progress;

pub fn diagnose(args: &DiagnoseArgs, out: &mut dyn Write) -> Result<ExitCode> {
    if let Some(n) = args.self_test {
        return self_test(args, n, out);
    }
    let Some(real) = &args.real else {
        bail!("expected --real RECORDING, with --sim SCENARIO or without (or --self-test N)");
    };
    let floors = Floors::from_flags(&args.floors, args.floor_noise_share)?;
    let options = Options {
        floors,
        ..Options::default()
    };
    if let Some(dir) = &args.report {
        check_report_dir(dir, &[show::MAP_FILE])?;
    }
    let Some(sim) = &args.sim else {
        return diagnose_in_own_world(args, real, &options, out);
    };
    let mut scenario = hilsim_scenarios::builtin::load_or_default(Some(sim), None)?;
    if let Some(path) = &args.calibration {
        let calibration = hilsim_calibrator::Calibration::read(path)?;
        scenario = hilsim_scenarios::calibrated::with_calibration(&scenario, &calibration)
            .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    }
    let recording = Recording::read_dir(real)?;
    let physics = SimPhysics::new(&scenario).with_context(|| sim.display().to_string())?;
    // The stages on a terminal only: stdout starts with the verdict and stderr holds one line
    // for an error, as scripts expect.
    let status = Progress::on_stderr(true, None, "{spinner} diagnose: {msg} ({elapsed})").ticking();
    let diagnosis =
        hilsim_diagnose::diagnose_with_progress(&physics, &recording, &options, &mut |stage| {
            status.message(stage.describe())
        })
        .with_context(|| real.display().to_string())?;
    drop(status);
    finish(args, (sim, &scenario), (real, &recording), &diagnosis, out)
}

/// What a report calls the world built from the log itself.
const BUILT_FROM_THE_LOG: &str = "<built from the log>";

/// `hilsim diagnose --real RECORDING` without a scenario: the world built from the recording's
/// own scans as `hilsim world` builds it, and built again under the lidar's named delay and
/// mount when its path is a truth's (`own_world::diagnosed_in`).
fn diagnose_in_own_world(
    args: &DiagnoseArgs,
    real: &Path,
    options: &Options,
    out: &mut dyn Write,
) -> Result<ExitCode> {
    if args.calibration.is_some() {
        bail!("--calibration needs --sim SCENARIO: the world built from the log declares what the log's meta.toml does");
    }
    let recording = Recording::read_dir(real)?;
    let status = Progress::on_stderr(true, None, "{spinner} diagnose: {msg} ({elapsed})").ticking();
    status.message("building the world from the log's scans and judging it".to_string());
    let (scenario, diagnosis) = own_world::diagnosed_in(
        &own_world::BuiltWorld::default(),
        &recording,
        &real.display().to_string(),
        options,
    )
    .map_err(|e| anyhow!("{e}"))?;
    drop(status);
    finish(
        args,
        (Path::new(BUILT_FROM_THE_LOG), &scenario),
        (real, &recording),
        &diagnosis,
        out,
    )
}

/// Writes `diagnosis` as the flags ask (its report, JSON or text) and gives the exit code.
fn finish(
    args: &DiagnoseArgs,
    sim: (&Path, &Scenario),
    real: (&Path, &Recording),
    diagnosis: &hilsim_diagnose::Diagnosis,
    out: &mut dyn Write,
) -> Result<ExitCode> {
    if let Some(dir) = &args.report {
        let files = show::report_files_of(diagnosis, sim, real);
        hilsim_report::write_report_files(dir, &files)?;
    }
    if args.json {
        writeln!(out, "{}", show::to_json(diagnosis))?;
    } else {
        out.write_all(show::summary(diagnosis).as_bytes())?;
        if let Some(dir) = &args.report {
            writeln!(out, "report: {}", dir.join("index.html").display())?;
        }
    }
    let mismatch = args.fail_on_mismatch && diagnosis.verdict.name() != "none";
    Ok(super::exit_code(!mismatch))
}

/// The self-test's plan, checked before its nominal scenario is read.
fn self_test_plan(args: &DiagnoseArgs, n: i128) -> Result<(Scenario, Plan)> {
    let plan = Plan::from_flags(&self_test::Flags {
        trials: n,
        seed: args.seed,
        strength: args.strength,
        only: args.only.as_deref(),
        reality: &args.reality,
        without_truth: args.without_truth,
        trial: args.trial,
        report: args.report.is_some(),
    })?;
    let scenario = match &args.sim {
        Some(path) => Scenario::load(path)?,
        None => hilsim_scenarios::builtin::diagnose_room()?,
    };
    Ok((scenario, plan))
}

/// `--self-test N`: the whole self-test, or with `--trial I` one trial's diagnosis.
fn self_test(args: &DiagnoseArgs, n: i128, out: &mut dyn Write) -> Result<ExitCode> {
    if let Some(log) = &args.on {
        return self_test_on_log(args, n, log, out);
    }
    let (scenario, plan) = self_test_plan(args, n)?;
    let n = plan.trials;
    if let Some(i) = args.trial {
        let run = self_test::one(&scenario, plan, i)?;
        if let Some(dir) = args.report.as_deref() {
            let rec_dir = dir.join("recording");
            run.recording.write_dir(&rec_dir)?;
            let origin = format!("<built-in {}>", scenario.name);
            let sim = (Path::new(&origin), &scenario);
            let files = show::report_files_of(&run.diagnosis, sim, (&rec_dir, &run.recording));
            hilsim_report::write_report_files(dir, &files)?;
        }
        if args.json {
            writeln!(out, "{}", run.to_json())?;
        } else {
            out.write_all(run.to_text().as_bytes())?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    // The trials: a bar on a terminal, else (without `--json`) a line at every tenth.
    let started = std::time::Instant::now();
    let bar = Progress::on_stderr(true, Some(n), "{bar:40} {pos}/{len} trials  eta {eta}");
    let lines = !bar.is_shown() && !args.json;
    let done = AtomicU64::new(0);
    let result = self_test::run_with_progress(&scenario, plan, &|| {
        bar.inc();
        let done = done.fetch_add(1, Ordering::Relaxed) + 1;
        if lines && (done % (n / 10).max(1) == 0 || done == n) {
            eprintln!("self-test: {done}/{n} trials");
        }
    })?;
    drop(bar);
    let wall_s = started.elapsed().as_secs_f64();
    let command = plan.command(args.sim.as_deref());
    if args.json {
        writeln!(out, "{}", result.to_json(&command, wall_s))?;
    } else {
        out.write_all(result.to_text(&command, wall_s).as_bytes())?;
    }
    Ok(super::exit_code(result.passed()))
}

/// `--self-test N --on REC`: blind trials on a real log, or with `--trial I` one trial's
/// diagnosis.
fn self_test_on_log(
    args: &DiagnoseArgs,
    n: i128,
    log: &Path,
    out: &mut dyn Write,
) -> Result<ExitCode> {
    let plan = Plan::from_flags(&self_test::Flags {
        trials: n,
        seed: args.seed,
        strength: args.strength,
        only: None,
        reality: "hilsim",
        without_truth: args.without_truth,
        trial: args.trial,
        report: args.report.is_some(),
    })?;
    let plan = on_log::LogPlan {
        trials: plan.trials,
        seed: plan.seed,
        strength: plan.strength,
        options: Options::default(),
    };
    let mut recording = Recording::read_dir(log)?;
    if args.without_truth {
        recording.truth = None;
    }
    let world: Box<dyn own_world::LogWorld> = match &args.sim {
        Some(path) => Box::new(own_world::GivenWorld(Scenario::load(path)?)),
        None => Box::new(own_world::BuiltWorld::default()),
    };
    if let Some(i) = args.trial {
        let on_log::LogTrialRun {
            concealed,
            real,
            scenario,
            diagnosis,
        } = on_log::trial_run(&recording, world.as_ref(), &plan, i)
            .map_err(|e| anyhow!("{}: {e}", log.display()))?;
        if let Some(dir) = args.report.as_deref() {
            let rec_dir = dir.join("recording");
            real.write_dir(&rec_dir)?;
            let sim = (
                args.sim.as_deref().unwrap_or(Path::new(BUILT_FROM_THE_LOG)),
                &scenario,
            );
            let files = show::report_files_of(&diagnosis, sim, (&rec_dir, &real));
            hilsim_report::write_report_files(dir, &files)?;
        }
        if args.json {
            let mut j = show::to_json(&diagnosis);
            j["trial"] = serde_json::json!({
                "index": i,
                "concealed": concealed.iter().map(|c| c.effect().name()).collect::<Vec<_>>(),
            });
            writeln!(out, "{j}")?;
        } else {
            let text = self_test::trial_text(i, plan.seed, &concealed, &show::summary(&diagnosis));
            out.write_all(text.as_bytes())?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    let started = std::time::Instant::now();
    let n = plan.trials;
    let bar = Progress::on_stderr(true, Some(n), "{bar:40} {pos}/{len} trials  eta {eta}");
    let lines = !bar.is_shown() && !args.json;
    let done = AtomicU64::new(0);
    let result = on_log::run_on_log(&recording, world.as_ref(), &plan, &|| {
        bar.inc();
        let done = done.fetch_add(1, Ordering::Relaxed) + 1;
        if lines && (done % (n / 10).max(1) == 0 || done == n) {
            eprintln!("self-test: {done}/{n} trials");
        }
    })
    .with_context(|| log.display().to_string())?;
    drop(bar);
    let wall_s = started.elapsed().as_secs_f64();
    let mut command = format!(
        "hilsim diagnose --self-test {n} --seed {} --on {}",
        plan.seed,
        log.display()
    );
    if let Some(sim) = &args.sim {
        command += &format!(" --sim {}", sim.display());
    }
    if plan.strength != 1.0 {
        command += &format!(" --strength {}", plan.strength);
    }
    if args.without_truth {
        command += " --without-truth";
    }
    if args.json {
        writeln!(out, "{}", result.to_json(&command, wall_s))?;
    } else {
        out.write_all(result.to_text(&command, wall_s).as_bytes())?;
    }
    Ok(super::exit_code(result.passed()))
}
