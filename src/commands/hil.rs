//! `hilsim hil SCENARIO --firmware 'CMD ARGS…' [--out DIR] [--duration S] [--watchdog S]
//! [--seed N]`: firmware in the loop.
//!
//! Exit codes: 0 the run ended on time or the firmware exited with status 0, and every
//! `[[expect]]` assertion held; 1 a firmware fault (crash, hang, flood, lidar never read), a
//! failed assertion or an interrupted run; 2 bad input, or the harness itself failed.

use std::io::IsTerminal as _;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{anyhow, bail, Context, Result};
use hilsim_hil::firmware::{split_command_line, Ended, Firmware};
use hilsim_hil::hil_run::{self, Ending, HilConfig, HilPorts, HilWorld};
use hilsim_scenarios::metrics;
use hilsim_sim::scenario::MAX_RUN_S;
use hilsim_sim::Scenario;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

#[derive(Debug, clap::Args)]
pub struct HilArgs {
    /// Scenario file; its drive program is not run (the firmware drives).
    pub scenario: PathBuf,
    /// The firmware's command line, split into words as a shell would (no shell runs): it gets
    /// HILSIM_LIDAR_PORT and HILSIM_ROBOT_PORT in its environment.
    #[arg(long, value_name = "'CMD ARGS…'")]
    pub firmware: String,
    /// Write the run as a recording (truth included) into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The run's length in seconds, overriding the scenario's `duration_s`.
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Seconds the firmware may go without a request before it counts as hung; also the time
    /// it has to start reading the lidar.
    #[arg(long, value_name = "S", default_value_t = 5.0)]
    pub watchdog: f64,
    /// Seed of every random stream (default: the scenario's `seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// End with one JSON object on its own line (how it ended, the metrics, the assertions, the
    /// stream and the firmware) instead of the summary.
    #[arg(long)]
    pub json: bool,
}

fn seconds(flag: &str, value: f64) -> Result<Duration> {
    if !value.is_finite() {
        bail!("{flag} must be a number of seconds in (0, {MAX_RUN_S}], got a non-finite value");
    }
    if !(value > 0.0 && value <= MAX_RUN_S) {
        bail!("{flag} must be a number of seconds in (0, {MAX_RUN_S}], got {value}");
    }
    Ok(Duration::from_secs_f64(value))
}

/// Simulated seconds between two status lines on a terminal shared with the firmware's output.
const STATUS_LINE_EVERY_S: f64 = 5.0;

pub fn hil(args: &HilArgs, out: &mut dyn Write) -> Result<ExitCode> {
    // Everything is checked before a port is opened or the firmware started.
    if let Some(d) = args.duration {
        seconds("--duration", d)?;
    }
    let watchdog = seconds("--watchdog", args.watchdog)?;
    let argv = split_command_line(&args.firmware).map_err(|e| anyhow!("--firmware: {e}"))?;
    let origin = args.scenario.display().to_string();
    let mut scenario = Scenario::load_with_duration(&args.scenario, args.duration)?;
    if let Some(seed) = args.seed {
        scenario.seed = seed;
    }
    if scenario.files.schedule.is_some() || scenario.files.path.is_some() {
        bail!(
            "{origin}: the scenario replays a log's run (`[robot] path`, `[sensors.lidar] \
             schedule`): under `hil` the firmware drives and the lidar turns as its unit does; `hilsim \
             record` makes the run's twin"
        );
    }
    let duration_s = scenario.duration_s.ok_or_else(|| {
        anyhow!("{origin}: under `hil` the firmware drives: set `duration_s` or pass --duration")
    })?;
    let duration = seconds("duration_s", duration_s).with_context(|| origin.clone())?;
    if let Some(dir) = &args.out {
        // Refused before the run rather than after it; a missing parent is created when the
        // recording is written, as `record` does.
        hilsim_recording::check_replaceable_recording(dir)?;
    }
    let world = HilWorld::new(&scenario, scenario.seed)
        .with_context(|| format!("{origin}: sensor model"))?;
    let config = HilConfig {
        watchdog,
        ..HilConfig::new(duration)
    };

    // Ctrl-C must reach the harness, which then shuts the firmware down: the firmware is in a
    // process group of its own, out of the terminal's reach.
    let stop = Arc::new(AtomicBool::new(false));
    hil_run::stop_on_signals(Arc::clone(&stop)).context("cannot set up signal handling")?;
    let ports = HilPorts::open().context("cannot create the pseudo-terminals")?;
    writeln!(out, "lidar: {}", ports.lidar_path())?;
    writeln!(out, "robot: {}", ports.robot_path())?;
    out.flush()?;
    let env = [
        ("HILSIM_LIDAR_PORT", ports.lidar_path()),
        ("HILSIM_ROBOT_PORT", ports.robot_path()),
    ];
    let firmware = Firmware::spawn(&argv, &env)
        .with_context(|| format!("--firmware: cannot start `{}`", argv[0]))?;
    writeln!(
        out,
        "firmware: pid {} `{}`; {} ({}) for {:.1} s in real time",
        firmware.pid(),
        // On one line, whatever the command's own line breaks.
        args.firmware
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" "),
        hilsim_recording::printable(&scenario.name),
        hilsim_recording::printable(&origin),
        duration.as_secs_f64()
    )?;
    out.flush()?;
    // How far the run has come, on stderr when it is a terminal (stdout keeps its lines for
    // scripts): a status line redrawn in place, or, when stdout is that terminal too, a whole
    // line every 5 s, because the firmware's own output goes there and a line redrawn in place
    // would overwrite it.
    let total_s = duration.as_secs_f64();
    let on_terminal = std::io::stderr().is_terminal();
    let status = (on_terminal && !std::io::stdout().is_terminal()).then(|| {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template("{spinner} hil: {msg}") {
            bar.set_style(style);
        }
        bar
    });
    let mut next_line_s = STATUS_LINE_EVERY_S;
    let report =
        hil_run::run_with_progress(world, ports, Some(firmware), &config, &stop, &mut |p| {
            let message = format!(
                "{:.1} of {total_s:.1} s, {} requests, {} lidar revolutions sent, {} dropped",
                p.t_s, p.requests, p.revolutions_sent, p.revolutions_dropped
            );
            if let Some(bar) = &status {
                bar.set_message(message);
                bar.tick();
            } else if on_terminal && p.t_s >= next_line_s {
                next_line_s += STATUS_LINE_EVERY_S;
                eprintln!("hil: {message}");
            }
        });
    if let Some(bar) = &status {
        bar.finish_and_clear();
    }
    let report = report.context("firmware in the loop")?;
    // The scenario's assertions, on the metrics a firmware's run has.
    let hil_metrics = metrics::of_hil(&report);
    let outcomes = metrics::check(
        &scenario.expect,
        &hil_metrics,
        metrics::RunKind::FirmwareInTheLoop,
    );
    let failed: Vec<&str> = outcomes
        .iter()
        .filter(|o| !o.passed)
        .map(|o| o.metric.as_str())
        .collect();
    if let Some(dir) = &args.out {
        report.run.recording.write_dir(dir)?;
    }
    if args.json {
        let json = report_json(&report, &hil_metrics, &outcomes);
        writeln!(out, "{json}")?;
    } else {
        out.write_all(report.summary().as_bytes())?;
        for outcome in &outcomes {
            writeln!(out, "  {}", outcome.describe())?;
        }
        if !failed.is_empty() {
            writeln!(
                out,
                "{} of {} assertion(s) failed: {}",
                failed.len(),
                outcomes.len(),
                failed.join(", ")
            )?;
        }
        if let Some(dir) = &args.out {
            writeln!(out, "wrote {}", dir.display())?;
        }
    }
    Ok(match report.ending {
        Ending::TimeUp | Ending::FirmwareExited if failed.is_empty() => ExitCode::SUCCESS,
        Ending::TimeUp | Ending::FirmwareExited | Ending::Fault(_) | Ending::Stopped => {
            ExitCode::from(1)
        }
    })
}

/// `hil --json`: how the run ended, its metrics and assertions, the stream and the firmware.
fn report_json(
    report: &hil_run::HilReport,
    metrics: &metrics::Metrics,
    outcomes: &[metrics::Outcome],
) -> serde_json::Value {
    let ending = match &report.ending {
        Ending::TimeUp => "time_up",
        Ending::FirmwareExited => "firmware_exited",
        Ending::Fault(_) => "fault",
        Ending::Stopped => "stopped",
    };
    let firmware = report.firmware.as_ref().map(|f| {
        serde_json::json!({
            "status": hilsim_hil::firmware::describe_status(f.status),
            "exit_code": f.status.code(),
            "ended": match f.ended {
                Ended::ByItself => "by_itself",
                Ended::Terminated => "terminated",
                Ended::Killed => "killed",
            },
            "shrugged_off_sigterm": f.shrugged_off_sigterm,
            "escaped": f.escaped.iter().map(|p| serde_json::json!({"pid": p.pid, "command": p.command})).collect::<Vec<_>>(),
        })
    });
    let s = &report.stream;
    serde_json::json!({
        "ending": ending,
        "fault": report.fault().map(ToString::to_string),
        "ended_at_s": report.ended_at_s,
        "simulated_s": report.simulated_s,
        "passed": matches!(report.ending, Ending::TimeUp | Ending::FirmwareExited)
            && outcomes.iter().all(|o| o.passed),
        "metrics": metrics,
        "expectations": outcomes,
        "stream": {
            "revolutions_sent": s.revolutions_sent,
            "revolutions_dropped": s.revolutions_dropped,
            "bytes_written": s.bytes_written,
            "lidar_bytes_read": report.lidar_bytes_read,
        },
        "link_faults": report.link_faults,
        "firmware": firmware,
    })
}
