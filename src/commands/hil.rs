//! `hilsim hil SCENARIO --firmware 'CMD ARGS…' [--out DIR] [--duration S] [--watchdog S]
//! [--seed N]`: firmware in the loop.
//!
//! Exit codes: 0 the run ended on time or the firmware exited with status 0, and every
//! `[[expect]]` assertion held; 1 a firmware fault (crash, hang, flood, lidar never read), a
//! failed assertion or an interrupted run; 2 bad input, or the harness itself failed.

use std::io::{IsTerminal, Write};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::{Context, Result};
use hilsim_hil::firmware::Firmware;
use hilsim_hil::hil_run::{self, HilConfig, HilPorts, HilReport, HilWorld};
use hilsim_scenarios::{FirmwarePlan, FirmwareRequest, FirmwareRun};

use crate::cli::HilArgs;
use crate::progress::Progress;

pub fn hil(args: &HilArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let plan = FirmwarePlan::new(&FirmwareRequest {
        scenario: &args.scenario,
        firmware: &args.firmware,
        out: args.out.as_deref(),
        duration_s: args.duration,
        watchdog_s: args.watchdog,
        seed: args.seed,
    })?;
    // Ctrl-C must reach the harness, which then shuts the firmware down: the firmware is in a
    // process group of its own, out of the terminal's reach.
    let stop = Arc::new(AtomicBool::new(false));
    hil_run::stop_on_signals(Arc::clone(&stop)).context("cannot set up signal handling")?;
    let ports = HilPorts::open().context("cannot create the pseudo-terminals")?;
    writeln!(out, "lidar: {}", ports.lidar_path())?;
    writeln!(out, "robot: {}", ports.robot_path())?;
    out.flush()?;
    let firmware = plan.spawn(&ports)?;
    writeln!(out, "{}", plan.started_line(firmware.pid()))?;
    out.flush()?;
    let report = run_shown(plan.world, ports, firmware, &plan.config, &stop)?;
    let run = FirmwareRun::judge(report, &plan.scenario.expect);
    if let Some(dir) = &args.out {
        run.report.run.recording.write_dir(dir)?;
    }
    if args.json {
        writeln!(out, "{}", run.to_json())?;
    } else {
        run.write_summary(out)?;
        if let Some(dir) = &args.out {
            writeln!(out, "wrote {}", dir.display())?;
        }
    }
    Ok(super::exit_code(run.passed()))
}

/// Simulated seconds between two status lines on a terminal shared with the firmware's output.
const STATUS_LINE_EVERY_S: f64 = 5.0;

/// Runs the firmware in the loop, how far it has come on stderr when it is a terminal (stdout
/// keeps its lines for scripts): a status line redrawn in place, or, when stdout is that
/// terminal too, a whole line every 5 s, because the firmware's own output goes there and a
/// line redrawn in place would overwrite it.
fn run_shown(
    world: HilWorld,
    ports: HilPorts,
    firmware: Firmware,
    config: &HilConfig,
    stop: &AtomicBool,
) -> Result<HilReport> {
    let total_s = config.duration.as_secs_f64();
    let on_terminal = std::io::stderr().is_terminal();
    let status = Progress::on_stderr(
        !std::io::stdout().is_terminal(),
        None,
        "{spinner} hil: {msg}",
    );
    let mut next_line_s = STATUS_LINE_EVERY_S;
    hil_run::run_with_progress(world, ports, Some(firmware), config, stop, &mut |p| {
        let message = p.describe(total_s);
        if status.is_shown() {
            status.message(message);
        } else if on_terminal && p.t_s >= next_line_s {
            next_line_s += STATUS_LINE_EVERY_S;
            eprintln!("hil: {message}");
        }
    })
    .context("firmware in the loop")
}
