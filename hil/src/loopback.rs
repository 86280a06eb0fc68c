//! The lidar's real path inside one process, for `hilsim run --via serial`: the emulator's
//! readings are encoded as Neato packets, written to a pseudo-terminal, read back from the
//! client side as a driver would, decoded, and rebuilt into the recording's lidar table.

use std::io::{self, ErrorKind, Read};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::Duration;

use hilsim_lidar_emulator::neato_packet::{Decoder, DecoderStats, RevolutionAssembler};
use hilsim_lidar_emulator::wire::{RevolutionCollector, WireTimeline};
use hilsim_lidar_emulator::{Emulation, Run};
use hilsim_recording::LidarSample;

use crate::device::XV11_BAUD;
use crate::pty::PtyLink;
use crate::streamer::{Pacing, StreamStats, Streamer};

/// What crossed the wire.
#[derive(Debug, Clone)]
pub struct LoopbackReport {
    /// The writer's side.
    pub stream: StreamStats,
    /// The decoder's side.
    pub decoder: DecoderStats,
    /// The pty's client path that was read.
    pub client_path: String,
}

/// Runs the emulation with its lidar readings taking the serial path. The returned run's lidar
/// table is what the decoder rebuilt; the true ranges, which are not on the wire, are the
/// simulator's, attached by revolution and angle for scoring. The other tables are the
/// emulation's own.
///
/// # Errors
/// The pty cannot be opened or read, or the wire lost data (it must not, on a lossless link).
pub fn run_through_pty(emulation: Emulation) -> io::Result<(Run, LoopbackReport)> {
    let link = PtyLink::open()?;
    let client_path = link.client_path().to_string();
    let mut client = serialport::new(&client_path, XV11_BAUD)
        .timeout(Duration::from_millis(50))
        .open_native()
        .map_err(io::Error::from)?;
    let writer_done = Arc::new(AtomicBool::new(false));
    let reader = {
        let writer_done = Arc::clone(&writer_done);
        thread::spawn(move || -> io::Result<(Vec<LidarSample>, DecoderStats)> {
            let mut decoder = Decoder::new();
            let mut assembler = RevolutionAssembler::new();
            let mut timeline = WireTimeline::new();
            let mut samples = Vec::new();
            let mut buf = [0u8; 8192];
            loop {
                match client.read(&mut buf) {
                    Ok(0) => {}
                    Ok(n) => {
                        for packet in decoder.feed(&buf[..n]) {
                            if let Some(rev) = assembler.push(packet) {
                                timeline.push(&rev, &mut samples);
                            }
                        }
                        continue;
                    }
                    Err(e) if e.kind() == ErrorKind::TimedOut => {}
                    Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                    Err(e) => return Err(e),
                }
                // Nothing arrived for a read timeout: once the writer has finished, the wire is
                // drained.
                if writer_done.load(Ordering::Acquire) {
                    break;
                }
            }
            if let Some(rev) = assembler.finish() {
                timeline.push(&rev, &mut samples);
            }
            Ok((samples, decoder.finish()))
        })
    };

    let mut streamer = Streamer::new(link, Pacing::Lossless);
    let mut collector = RevolutionCollector::default();
    let mut write_error = None;
    let mut run = emulation.run_with(|reading, rpm| {
        if write_error.is_none() {
            if let Some(frame) = collector.push(reading, rpm) {
                write_error = streamer.send(&frame).err();
            }
        }
    });
    writer_done.store(true, Ordering::Release);
    let received = reader
        .join()
        .map_err(|_| io::Error::other("the pty reader thread panicked"))?;
    if let Some(err) = write_error {
        return Err(err);
    }
    let (samples, decoder) = received?;
    let stream = streamer.stats().clone();
    let expected = stream.revolutions_sent as usize * 360;
    if stream.revolutions_dropped > 0 || samples.len() != expected || decoder.bad_checksum > 0 {
        return Err(io::Error::other(format!(
            "the serial path lost data: {} of {expected} readings arrived, {} bad checksums",
            samples.len(),
            decoder.bad_checksum
        )));
    }
    if let Some(emulated) = &run.recording.lidar {
        // The wire carries no truth; the harness has it. Attach each decoded reading's true
        // range (matched by revolution, angle and time) so that a run is scored against the
        // same truth on both paths; everything else is what the decoder produced.
        let mut samples = samples;
        for (decoded, truth) in samples.iter_mut().zip(emulated) {
            if (decoded.rev, decoded.angle_deg, decoded.t_s)
                != (truth.rev, truth.angle_deg, truth.t_s)
            {
                return Err(io::Error::other(format!(
                    "the serial path reordered readings: revolution {} angle {} arrived where \
                     revolution {} angle {} was sent",
                    decoded.rev, decoded.angle_deg, truth.rev, truth.angle_deg
                )));
            }
            decoded.true_range_m = truth.true_range_m;
        }
        run.recording.lidar = Some(samples);
    }
    Ok((
        run,
        LoopbackReport {
            stream,
            decoder,
            client_path,
        },
    ))
}
