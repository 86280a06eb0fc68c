//! `hilsim serve`: the emulated lidar streamed over a serial link in its unit's format.

use std::io;
use std::sync::atomic::{AtomicBool, Ordering};

use hilsim_lidar_emulator::wire::{to_unit_reading, RevolutionCollector};
use hilsim_lidar_emulator::Emulation;

use crate::link::SerialLink;
use crate::streamer::{StreamStats, Streamer};
use crate::unit_streamer::UnitStreamer;

/// What a serve run did.
#[derive(Debug, Clone)]
pub struct ServeReport {
    /// The stream's counts and packet lateness.
    pub stream: StreamStats,
    /// Simulated seconds streamed.
    pub simulated_s: f64,
    /// Whether it ended because `stop` was raised.
    pub interrupted: bool,
    /// What the scenario's `[link]` faults did (`None`: it has none).
    pub link_faults: Option<crate::faults::FaultCounts>,
}

/// Streams the emulation's lidar until the scenario ends or `stop` is raised. Only whole
/// revolutions are sent; the simulation is never held up by the reader (see [`Streamer`]).
///
/// # Errors
/// The link failed.
pub fn serve<L: SerialLink>(
    emulation: Emulation,
    streamer: &mut Streamer<L>,
    stop: &AtomicBool,
) -> io::Result<ServeReport> {
    serve_with_progress(emulation, streamer, stop, &mut |_, _| {})
}

/// As [`serve`], telling `progress` the stream's counts and the simulated time after each
/// revolution (for a status line; the library prints nothing).
///
/// # Errors
/// The link failed.
pub fn serve_with_progress<L: SerialLink>(
    mut emulation: Emulation,
    streamer: &mut Streamer<L>,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&StreamStats, f64),
) -> io::Result<ServeReport> {
    let mut collector = RevolutionCollector::default();
    let mut readings = Vec::new();
    let mut interrupted = false;
    while let Some(samples) = emulation.step() {
        readings.clear();
        readings.extend_from_slice(&samples.lidar);
        for reading in &readings {
            let rpm = emulation
                .lidar()
                .map_or(0.0, |l| l.rpm_of_revolution(reading.rev));
            if let Some(frame) = collector.push(reading, rpm) {
                streamer.send(&frame)?;
                progress(streamer.stats(), frame.start_s);
            }
        }
        if stop.load(Ordering::Relaxed) {
            interrupted = true;
            break;
        }
    }
    if !interrupted {
        streamer.drain()?;
    }
    Ok(ServeReport {
        stream: streamer.stats().clone(),
        simulated_s: emulation.simulation().time_s(),
        interrupted,
        link_faults: streamer.fault_counts(),
    })
}

/// As [`serve_with_progress`], for a unit other than the XV-11 ([`UnitStreamer`]): each reading
/// handed to the unit at its instant, the host's commands answered as they come.
///
/// # Errors
/// The link failed.
pub fn serve_unit_with_progress<L: SerialLink>(
    mut emulation: Emulation,
    streamer: &mut UnitStreamer<L>,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&StreamStats, f64),
) -> io::Result<ServeReport> {
    let Some(spec) = emulation.lidar().map(|l| l.unit().spec()) else {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "the scenario has no lidar",
        ));
    };
    let mut readings = Vec::new();
    let mut interrupted = false;
    while let Some(samples) = emulation.step() {
        readings.clear();
        readings.extend_from_slice(&samples.lidar);
        for reading in &readings {
            streamer.take(&to_unit_reading(reading, spec), stop)?;
            if reading.index == 0 {
                progress(streamer.stats(), reading.t_s);
            }
            if stop.load(Ordering::Relaxed) {
                interrupted = true;
                break;
            }
        }
        if interrupted || stop.load(Ordering::Relaxed) {
            interrupted = true;
            break;
        }
    }
    if !interrupted {
        streamer.drain()?;
    }
    Ok(ServeReport {
        stream: streamer.stats().clone(),
        simulated_s: emulation.simulation().time_s(),
        interrupted,
        link_faults: streamer.fault_counts(),
    })
}
