//! `hilsim serve SCENARIO [--pty | --port PATH] [--realtime | --fast] [--wait-for-client]
//! [--seed N]`.

use std::io::{IsTerminal, Write};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use anyhow::{Context, Result};
use hilsim_hil::faults::WireFaults;
use hilsim_hil::serve::{serve_unit_with_progress, serve_with_progress, ServeReport};
use hilsim_hil::{DeviceLink, Pacing, PtyLink, SerialLink, StreamStats, Streamer, UnitStreamer};
use hilsim_lidar_emulator::Emulation;
use hilsim_sim::scenario::LidarModel;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::cli::ServeArgs;

pub fn serve(args: &ServeArgs, out: &mut dyn Write) -> Result<()> {
    let scenario = super::load_scenario(Some(&args.scenario), args.seed)?;
    if scenario.sensors.lidar.is_none() {
        anyhow::bail!(
            "{}: the scenario has no [sensors.lidar] to serve",
            args.scenario.display()
        );
    }
    if scenario.files.schedule.is_some() {
        anyhow::bail!(
            "{}: the lidar replays a log's scans (`schedule`), which have no unit's packets to \
             serve; `hilsim record` makes its twin",
            args.scenario.display()
        );
    }
    let pacing = if args.fast {
        Pacing::Fast
    } else {
        Pacing::Realtime
    };
    let model = scenario
        .sensors
        .lidar
        .as_ref()
        .map(|l| l.model)
        .unwrap_or_default();
    let emulation = Emulation::new(&scenario, scenario.seed)
        .with_context(|| format!("{}: sensor model", args.scenario.display()))?;
    // Ctrl-C (or SIGTERM, SIGHUP) ends the stream and still prints what was sent; a second
    // one ends the process at once.
    let stop = Arc::new(AtomicBool::new(false));
    hilsim_hil::hil_run::stop_on_signals(Arc::clone(&stop))
        .context("cannot set up signal handling")?;
    // Validation has checked the table: its faults resolve.
    let link_faults = scenario.link.faults().unwrap_or_default();
    let wire_faults = || WireFaults::new(&link_faults, scenario.seed);
    let report = match &args.port {
        Some(path) => {
            let link =
                DeviceLink::open_at(&path.to_string_lossy(), model.spec().baud).map_err(|err| {
                    let path = path.display();
                    match err.kind() {
                        std::io::ErrorKind::InvalidInput => anyhow::anyhow!("{path}: {err}"),
                        _ => anyhow::anyhow!("{path}: cannot open: {err}"),
                    }
                })?;
            writeln!(out, "serial: {}", path.display())?;
            out.flush()?;
            run(emulation, link, pacing, &stop, false, wire_faults(), model)?
        }
        None => {
            let link = PtyLink::open().context("cannot create a pseudo-terminal")?;
            // The client's path on its own line, before any data: scripts wait for it.
            writeln!(out, "serial: {}", link.client_path())?;
            out.flush()?;
            let connected = args.wait_for_client && link.wait_for_client(&stop);
            if connected {
                writeln!(out, "client connected: streaming")?;
                out.flush()?;
            }
            run(
                emulation,
                link,
                pacing,
                &stop,
                connected,
                wire_faults(),
                model,
            )?
        }
    };
    let s = &report.stream;
    if args.json {
        let json = serde_json::json!({
            "served_s": report.simulated_s,
            "revolutions_sent": s.revolutions_sent,
            "revolutions_dropped": s.revolutions_dropped,
            "bytes_written": s.bytes_written,
            "bytes_discarded": s.bytes_discarded,
            "lateness_ms": {
                "median": s.lateness_quantile(0.5).map(|d| d.as_secs_f64() * 1e3),
                "p99": s.lateness_quantile(0.99).map(|d| d.as_secs_f64() * 1e3),
            },
            "link_faults": report.link_faults,
            "interrupted": report.interrupted,
        });
        writeln!(out, "{json}")?;
        return Ok(());
    }
    write!(
        out,
        "served {:.1} s: {} revolutions sent, {} dropped (no reader yet, or one that stalled), {} bytes",
        report.simulated_s, s.revolutions_sent, s.revolutions_dropped, s.bytes_written
    )?;
    if let Some(lateness) = s.lateness_summary() {
        write!(out, "; {lateness}")?;
    }
    if report.interrupted {
        write!(out, " (interrupted)")?;
    }
    writeln!(out)?;
    if let Some(faults) = &report.link_faults {
        writeln!(out, "{}", faults.describe())?;
    }
    Ok(())
}

fn run<L: SerialLink>(
    emulation: Emulation,
    link: L,
    pacing: Pacing,
    stop: &AtomicBool,
    client_connected: bool,
    faults: Option<WireFaults>,
    model: LidarModel,
) -> Result<ServeReport> {
    // What is sent, as a status line on a terminal (stderr; stdout keeps its lines for scripts).
    let status = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template("{spinner} serve: {msg}") {
            bar.set_style(style);
        }
        bar
    });
    let mut progress = |stats: &StreamStats, t_s: f64| {
        if let Some(bar) = &status {
            bar.set_message(format!(
                "{:.1} s simulated, {} revolutions sent, {} dropped",
                t_s, stats.revolutions_sent, stats.revolutions_dropped
            ));
            bar.tick();
        }
    };
    let report = match hilsim_lidar_protocols::unit_for(model) {
        None => {
            let mut streamer = Streamer::new(link, pacing).with_faults(faults);
            if client_connected {
                streamer.reader_connected();
            }
            serve_with_progress(emulation, &mut streamer, stop, &mut progress)
        }
        Some(unit) => {
            let mut streamer = UnitStreamer::new(link, unit, pacing).with_faults(faults);
            if client_connected {
                streamer.reader_connected();
            }
            serve_unit_with_progress(emulation, &mut streamer, stop, &mut progress)
        }
    };
    if let Some(bar) = &status {
        bar.finish_and_clear();
    }
    report.context("the serial link failed")
}
