//! Serving a scenario's lidar in its own unit's protocol, and what a served stream reports
//! (`hilsim serve`'s closing line and JSON object).

use std::io::{self, Write};
use std::sync::atomic::AtomicBool;

use hilsim_lidar_emulator::Emulation;
use hilsim_lidar_protocols::LidarModel;

use crate::faults::WireFaults;
use crate::serve::{serve_unit_with_progress, serve_with_progress, ServeReport};
use crate::{Pacing, SerialLink, StreamStats, Streamer, UnitStreamer};

/// How a unit is served: its protocol, the pace, the link's faults and whether a client has
/// already opened the link.
pub struct ServeOptions {
    /// The unit whose protocol is streamed.
    pub model: LidarModel,
    /// As a real unit would, or as fast as the reader takes it.
    pub pacing: Pacing,
    /// The scenario's `[link]` faults, if any.
    pub faults: Option<WireFaults>,
    /// A client is known to be reading from the start.
    pub client_connected: bool,
}

/// Streams the emulation's lidar in `options.model`'s protocol until the scenario ends or
/// `stop` is raised, telling `progress` what is sent (see [`serve_with_progress`]).
///
/// # Errors
/// The link failed.
pub fn serve_model<L: SerialLink>(
    emulation: Emulation,
    link: L,
    options: ServeOptions,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&StreamStats, f64),
) -> io::Result<ServeReport> {
    match hilsim_lidar_protocols::unit_for(options.model) {
        None => {
            let mut streamer = Streamer::new(link, options.pacing).with_faults(options.faults);
            if options.client_connected {
                streamer.reader_connected();
            }
            serve_with_progress(emulation, &mut streamer, stop, progress)
        }
        Some(unit) => {
            let mut streamer =
                UnitStreamer::new(link, unit, options.pacing).with_faults(options.faults);
            if options.client_connected {
                streamer.reader_connected();
            }
            serve_unit_with_progress(emulation, &mut streamer, stop, progress)
        }
    }
}

impl ServeReport {
    /// `hilsim serve --json`'s object: what was sent and dropped, the lateness, the faults.
    pub fn to_json(&self) -> serde_json::Value {
        let s = &self.stream;
        let ms = |q| s.lateness_quantile(q).map(|d| d.as_secs_f64() * 1e3);
        serde_json::json!({
            "served_s": self.simulated_s,
            "revolutions_sent": s.revolutions_sent,
            "revolutions_dropped": s.revolutions_dropped,
            "bytes_written": s.bytes_written,
            "bytes_discarded": s.bytes_discarded,
            "lateness_ms": { "median": ms(0.5), "p99": ms(0.99) },
            "link_faults": self.link_faults,
            "interrupted": self.interrupted,
        })
    }

    /// `hilsim serve`'s closing summary: a line, and the faults' when there were any.
    ///
    /// # Errors
    /// Writing to `w` failed.
    pub fn write_summary(&self, w: &mut dyn Write) -> io::Result<()> {
        let s = &self.stream;
        write!(
            w,
            "served {:.1} s: {} revolutions sent, {} dropped (no reader yet, or one that \
             stalled), {} bytes",
            self.simulated_s, s.revolutions_sent, s.revolutions_dropped, s.bytes_written
        )?;
        if let Some(lateness) = s.lateness_summary() {
            write!(w, "; {lateness}")?;
        }
        if self.interrupted {
            write!(w, " (interrupted)")?;
        }
        writeln!(w)?;
        if let Some(faults) = &self.link_faults {
            writeln!(w, "{}", faults.describe())?;
        }
        Ok(())
    }
}
