//! `hilsim serve SCENARIO [--pty | --port PATH] [--realtime | --fast] [--wait-for-client]
//! [--seed N]`.

use std::io::Write;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::{Context, Result};
use hilsim_hil::serve::ServeReport;
use hilsim_hil::{serve_model, DeviceLink, Pacing, PtyLink, SerialLink, ServeOptions};
use hilsim_lidar_emulator::Emulation;

use crate::cli::ServeArgs;
use crate::progress::Progress;

pub fn serve(args: &ServeArgs, out: &mut dyn Write) -> Result<ExitCode> {
    let scenario = hilsim_scenarios::builtin::load_or_default(Some(&args.scenario), args.seed)?;
    let origin = args.scenario.display().to_string();
    let pacing = if args.fast {
        Pacing::Fast
    } else {
        Pacing::Realtime
    };
    let (mut options, emulation) = ServeOptions::for_scenario(&scenario, &origin, pacing)?;
    // Ctrl-C (or SIGTERM, SIGHUP) ends the stream and still prints what was sent; a second
    // one ends the process at once.
    let stop = Arc::new(AtomicBool::new(false));
    hilsim_hil::hil_run::stop_on_signals(Arc::clone(&stop))
        .context("cannot set up signal handling")?;
    let report = match &args.port {
        Some(path) => {
            let link = DeviceLink::open_named(path, options.model.spec().baud)?;
            writeln!(out, "serial: {}", path.display())?;
            out.flush()?;
            run(emulation, link, options, &stop)?
        }
        None => {
            let link = PtyLink::open().context("cannot create a pseudo-terminal")?;
            // The client's path on its own line, before any data: scripts wait for it.
            writeln!(out, "serial: {}", link.client_path())?;
            out.flush()?;
            options.client_connected = args.wait_for_client && link.wait_for_client(&stop);
            if options.client_connected {
                writeln!(out, "client connected: streaming")?;
                out.flush()?;
            }
            run(emulation, link, options, &stop)?
        }
    };
    if args.json {
        writeln!(out, "{}", report.to_json())?;
    } else {
        report.write_summary(out)?;
    }
    Ok(ExitCode::SUCCESS)
}

/// Serves the stream, what is sent shown as a status line on a terminal (stderr; stdout keeps
/// its lines for scripts).
fn run<L: SerialLink>(
    emulation: Emulation,
    link: L,
    options: ServeOptions,
    stop: &AtomicBool,
) -> Result<ServeReport> {
    let status = Progress::on_stderr(true, None, "{spinner} serve: {msg}");
    serve_model(emulation, link, options, stop, &mut |stats, t_s| {
        status.message(stats.describe(t_s));
    })
    .context("the serial link failed")
}
