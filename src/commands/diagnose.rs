//! `hilsim diagnose --sim SCENARIO --real RECORDING [--calibration FILE] [--json] [--report DIR]`
//! and
//! `hilsim diagnose --self-test N [--seed S] [--sim SCENARIO] [--json]`.
//!
//! Exit codes: 0 when a verdict is reached (`none`, an effect, or `unexplained`: each is an
//! answer; with `--fail-on-mismatch` only `none`, else 1); 2 on bad input, including a recording the diagnosis refuses (too short, no sensor in
//! common, not a run of the scenario), with one line naming the file and the reason. The
//! self-test exits 1 when it misses one of its goals.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicU64, Ordering};

use anyhow::{bail, Context, Result};
use hilsim_diagnose::self_test::{self, Plan, Reality};
use hilsim_diagnose::{show, Effect, Floors, Options, SimPhysics, Stage};
use hilsim_recording::{write_owned_file_atomically, Recording};
use hilsim_sim::Scenario;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Compare a simulation with a real recording: locate the mismatch, name the physics left out,
/// fit it, show the held-out improvement. Or prove it blind with `--self-test N`.
#[derive(Debug, clap::Args)]
pub struct DiagnoseArgs {
    /// The scenario the recording is a run of (for `--self-test`: the nominal scenario, default
    /// the built-in `scenarios/diagnose-room.toml`).
    #[arg(long, value_name = "SCENARIO")]
    pub sim: Option<PathBuf>,
    /// The real recording (a directory in the recording format).
    #[arg(long, value_name = "RECORDING", conflicts_with = "self_test")]
    pub real: Option<PathBuf>,
    /// Print the result as one JSON object (`interfaces.md`).
    #[arg(long)]
    pub json: bool,
    /// Write the evidence as SVG plots and an HTML page (`index.html`) into this directory.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Run N blind trials: each draws an effect (or none) and its parameters, records a "real"
    /// run with it, diagnoses it against the nominal scenario and scores the answer.
    // Wide enough for any count typed, so that the range check below says what is expected.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub self_test: Option<i128>,
    /// Seed of the self-test's draws (default 1).
    #[arg(long, value_name = "S", requires = "self_test")]
    pub seed: Option<u64>,
    /// Self-test: strength of the drawn effects, a factor on the documented moderate ranges.
    #[arg(
        long,
        value_name = "X",
        requires = "self_test",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    pub strength: f64,
    /// Self-test: conceal only this effect in every trial (a catalogue name, or `none`), to
    /// study one class.
    #[arg(long, value_name = "EFFECT", requires = "self_test")]
    pub only: Option<String>,
    /// Self-test: what makes the "real" recordings: `hilsim` (its own simulator with the drawn
    /// effect switched on) or `independent` (a generator that shares no model code with it,
    /// with random nuisances, two effects at once in a fifth of the trials and an effect
    /// outside the catalogue).
    #[arg(long, value_name = "REALITY", requires = "self_test", default_value = "hilsim",
          value_parser = ["hilsim", "independent"])]
    pub reality: String,
    /// Self-test: run only trial I (of the N), print its whole diagnosis and, with `--report`,
    /// write its report and its "real" recording (`DIR/recording`).
    #[arg(long, value_name = "I", requires = "self_test")]
    pub trial: Option<u64>,
    /// Self-test: remove each "real" recording's `truth.csv` before diagnosing it, as a robot's
    /// log without motion capture (the trajectory is then estimated from the lidar).
    #[arg(long, requires = "self_test")]
    pub without_truth: bool,
    /// Exit 1 when the verdict is not `none` (a mismatch was found), for CI jobs; the result is
    /// still printed.
    #[arg(long, conflicts_with = "self_test")]
    pub fail_on_mismatch: bool,
    /// A sensor's practical floor: a mismatch smaller than this many millimetres (and than
    /// `--floor-noise-share` of the declared noise) is not reported, however significant
    /// (`SENSOR=MM`, SENSOR one of lidar, sonar, odometer, drive; repeatable; defaults in
    /// docs/diagnose.md).
    #[arg(long = "floor", value_name = "SENSOR=MM", conflicts_with = "self_test")]
    pub floors: Vec<String>,
    /// The share of the declared noise's standard deviation below which a mismatch is not
    /// reported (default 0.25).
    #[arg(long, value_name = "X", conflicts_with = "self_test")]
    pub floor_noise_share: Option<f64>,
    /// A calibration of the robot (`hilsim calibrate --json`): the simulation takes what it
    /// found instead of the scenario's declared models (an odometry calibration's wheels and
    /// lidar mount; an em, landmarks or groundtruth calibration's range bias and noise), so that
    /// what is left is what the calibration did not explain.
    #[arg(long, value_name = "FILE", conflicts_with = "self_test")]
    pub calibration: Option<PathBuf>,
}

/// The diagnosis's options from `--floor` and `--floor-noise-share`.
fn options(args: &DiagnoseArgs) -> Result<Options> {
    let mut floors = Floors::default();
    for f in &args.floors {
        let Some((sensor, mm)) = f.split_once('=') else {
            bail!("--floor: expected SENSOR=MM, found `{f}`");
        };
        let mm: f64 = match mm.trim().parse() {
            Ok(v) if v >= 0.0 && f64::is_finite(v) => v,
            _ => bail!("--floor: expected a size in millimetres ≥ 0, found `{mm}`"),
        };
        let slot = match sensor.trim() {
            "lidar" => &mut floors.lidar_m,
            "sonar" => &mut floors.sonar_m,
            "odometer" => &mut floors.odometer_m,
            "drive" => &mut floors.drive_m,
            other => {
                bail!("--floor: expected a sensor (lidar, sonar, odometer, drive), found `{other}`")
            }
        };
        *slot = mm / 1000.0;
    }
    if let Some(x) = args.floor_noise_share {
        if !(x.is_finite() && x >= 0.0) {
            bail!("--floor-noise-share: expected a share ≥ 0, found {x}");
        }
        floors.noise_share = x;
    }
    Ok(Options {
        floors,
        ..Options::default()
    })
}

pub fn diagnose(args: &DiagnoseArgs, out: &mut dyn Write) -> Result<ExitCode> {
    if let Some(n) = args.self_test {
        if n < 1 {
            bail!("--self-test: expected at least one trial, found {n}");
        }
        let n = match u64::try_from(n) {
            Ok(n) if n <= self_test::MAX_TRIALS => n,
            _ => bail!(
                "--self-test: expected at most {} trials, found {n}",
                self_test::MAX_TRIALS
            ),
        };
        if !(args.strength.is_finite() && args.strength > 0.0 && args.strength <= 5.0) {
            bail!(
                "--strength: expected a factor in (0, 5], found {:?}",
                args.strength
            );
        }
        if args.report.is_some() && args.trial.is_none() {
            bail!("--report with --self-test needs --trial I: the report is of one trial");
        }
        let scenario = match &args.sim {
            Some(path) => hilsim_sim::Scenario::load(path)?,
            None => hilsim_scenarios::builtin::diagnose_room()?,
        };
        let seed = args.seed.unwrap_or(1);
        let reality = if args.reality == "independent" {
            Reality::Independent
        } else {
            Reality::Hilsim
        };
        let only = match args.only.as_deref() {
            None => None,
            Some("none") => Some(0),
            Some(name) if name == self_test::OUTSIDE && reality == Reality::Independent => {
                Some(1 + Effect::entries().len())
            }
            Some(name) => match Effect::entries().iter().position(|x| *x == name) {
                Some(k) => Some(1 + k),
                None => bail!("--only: expected `none` or a catalogued effect, found `{name}`"),
            },
        };
        let plan = Plan {
            trials: n,
            seed,
            strength: args.strength,
            only,
            reality,
            without_truth: args.without_truth,
        };
        if let Some(i) = args.trial {
            if i >= n {
                bail!("--trial: expected a trial below --self-test {n}, found {i}");
            }
            let run = self_test::one(&scenario, plan, i)?;
            if let Some(dir) = args.report.as_deref() {
                let rec_dir = dir.join("recording");
                run.recording.write_dir(&rec_dir)?;
                let origin = format!("<built-in {}>", scenario.name);
                write_report(
                    dir,
                    &run.diagnosis,
                    (Path::new(&origin), &scenario),
                    (&rec_dir, &run.recording),
                )?;
            }
            if args.json {
                writeln!(out, "{}", run.to_json())?;
            } else {
                out.write_all(run.to_text().as_bytes())?;
            }
            return Ok(ExitCode::SUCCESS);
        }
        // The command that reproduces this self-test.
        let mut command = format!("hilsim diagnose --self-test {n} --seed {seed}");
        if let Some(sim) = &args.sim {
            command += &format!(" --sim {}", sim.display());
        }
        if let Some(only) = &args.only {
            command += &format!(" --only {only}");
        }
        if args.strength != 1.0 {
            command += &format!(" --strength {}", args.strength);
        }
        if reality != Reality::Hilsim {
            command += &format!(" --reality {}", reality.name());
        }
        if args.without_truth {
            command += " --without-truth";
        }
        let started = std::time::Instant::now();
        let progress = TrialProgress::new(n, !args.json);
        let result = self_test::run_with_progress(&scenario, plan, &|| progress.trial_done())?;
        drop(progress);
        let wall_s = started.elapsed().as_secs_f64();
        if args.json {
            writeln!(out, "{}", result.to_json(&command, wall_s))?;
        } else {
            out.write_all(result.to_text(&command, wall_s).as_bytes())?;
        }
        return Ok(if result.passed() {
            ExitCode::SUCCESS
        } else {
            ExitCode::from(1)
        });
    }
    let (Some(sim), Some(real)) = (&args.sim, &args.real) else {
        bail!("expected --sim SCENARIO and --real RECORDING (or --self-test N)");
    };
    let options = options(args)?;
    if let Some(dir) = &args.report {
        super::report_dir::check_report_dir(dir, &[MAP_FILE])?;
    }
    let mut scenario = super::load_scenario(Some(sim), None)?;
    if let Some(path) = &args.calibration {
        let calibration = super::read_calibration(path)?;
        scenario = hilsim_scenarios::calibrated::with_calibration(&scenario, &calibration)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    }
    let recording = Recording::read_dir(real)?;
    let physics = SimPhysics::new(&scenario).with_context(|| sim.display().to_string())?;
    // The stages on a terminal only: stdout starts with the verdict and stderr holds one line
    // for an error, as scripts expect.
    let status = StageStatus::new();
    let diagnosis =
        hilsim_diagnose::diagnose_with_progress(&physics, &recording, &options, &mut |stage| {
            status.stage(stage)
        })
        .with_context(|| real.display().to_string())?;
    drop(status);
    if let Some(dir) = &args.report {
        write_report(dir, &diagnosis, (sim, &scenario), (real, &recording))?;
    }
    if args.json {
        writeln!(out, "{}", show::to_json(&diagnosis))?;
    } else {
        out.write_all(show::summary(&diagnosis).as_bytes())?;
        if let Some(dir) = &args.report {
            writeln!(out, "report: {}", dir.join("index.html").display())?;
        }
    }
    if args.fail_on_mismatch && diagnosis.verdict.name() != "none" {
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// The map's file beside a diagnosis's page.
const MAP_FILE: &str = "map.svg";

/// Writes `index.html`, its plots and the map into `dir` (created if needed), each file
/// atomically.
fn write_report(
    dir: &Path,
    d: &hilsim_diagnose::Diagnosis,
    (sim, scenario): (&Path, &Scenario),
    (real, recording): (&Path, &Recording),
) -> Result<()> {
    let files: Vec<String> = d
        .plots
        .iter()
        .enumerate()
        .map(|(i, p)| {
            format!(
                "residuals-{}-{}.svg",
                i + 1,
                p.variable.name().replace(' ', "-")
            )
        })
        .collect();
    let mut own: Vec<&str> = files.iter().map(String::as_str).collect();
    own.push(MAP_FILE);
    super::report_dir::check_report_dir(dir, &own)?;
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    for (name, p) in files.iter().zip(&d.plots) {
        write_owned_file_atomically(&dir.join(name), show::svg(p).as_bytes())?;
    }
    let title = format!(
        "hilsim diagnose: {} against {}",
        real.display(),
        sim.display()
    );
    let name = real.display().to_string();
    // Without truth.csv the map draws the path the diagnosis estimated from the lidar (the
    // sensors were judged against it) and places the scans on it, not on dead reckoning.
    let with_estimate = d.estimated_path.as_ref().map(|path| Recording {
        truth: Some(path.clone()),
        ..recording.clone()
    });
    let map = hilsim_report::map_svg(
        hilsim_report::Inputs {
            title: &title,
            recording: with_estimate.as_ref().unwrap_or(recording),
            recording_name: &name,
            scenario: Some(scenario),
            calibrations: &[],
            truth_estimated: with_estimate.is_some(),
        },
        located_overlay(d).as_ref(),
    );
    write_owned_file_atomically(&dir.join(MAP_FILE), map.as_bytes())?;
    write_owned_file_atomically(
        &dir.join("index.html"),
        show::html(d, &title, &files, Some(MAP_FILE)).as_bytes(),
    )?;
    Ok(())
}

/// The held-out readings where the mismatch was located, in the world, for the map: those of
/// the first plot (the located variable's) inside its highlighted range.
fn located_overlay(d: &hilsim_diagnose::Diagnosis) -> Option<hilsim_report::Overlay> {
    let located = d.located.as_ref()?;
    let plot = d.plots.first()?;
    let (lo, hi) = plot.highlight?;
    let points: Vec<(f64, f64)> = plot
        .x
        .iter()
        .zip(&plot.positions)
        .filter(|(x, p)| (lo..=hi).contains(*x) && p[0].is_finite() && p[1].is_finite())
        .map(|(_, p)| (p[0], p[1]))
        .collect();
    (!points.is_empty()).then(|| hilsim_report::Overlay {
        points,
        label: format!(
            "{} readings where the mismatch was located ({})",
            located.sensor, located.place
        ),
    })
}

/// The diagnosis's stages: a spinner on stderr when it is a terminal (cleared when done, or on
/// an error).
struct StageStatus {
    spinner: Option<ProgressBar>,
}

impl StageStatus {
    fn new() -> Self {
        let spinner = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template("{spinner} diagnose: {msg} ({elapsed})")
            {
                bar.set_style(style);
            }
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
            bar
        });
        Self { spinner }
    }

    fn stage(&self, stage: Stage) {
        if let Some(bar) = &self.spinner {
            bar.set_message(stage.describe());
        }
    }
}

impl Drop for StageStatus {
    fn drop(&mut self) {
        if let Some(bar) = &self.spinner {
            bar.finish_and_clear();
        }
    }
}

/// The self-test's trials: a bar on stderr when it is a terminal, else (without `--json`) a
/// line on stderr at every tenth.
struct TrialProgress {
    bar: Option<ProgressBar>,
    lines: bool,
    total: u64,
    done: AtomicU64,
}

impl TrialProgress {
    fn new(total: u64, lines: bool) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            if let Ok(style) =
                ProgressStyle::with_template("{bar:40} {pos}/{len} trials  eta {eta}")
            {
                bar.set_style(style);
            }
            bar
        });
        Self {
            bar,
            lines,
            total,
            done: AtomicU64::new(0),
        }
    }

    fn trial_done(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        match &self.bar {
            Some(bar) => bar.inc(1),
            None if self.lines => {
                let tenth = (self.total / 10).max(1);
                if done % tenth == 0 || done == self.total {
                    eprintln!("self-test: {done}/{} trials", self.total);
                }
            }
            None => {}
        }
    }
}

impl Drop for TrialProgress {
    fn drop(&mut self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
