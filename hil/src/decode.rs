//! Decoding a raw Neato XV-11 byte stream (a capture file, a serial device, a pty), as `hilsim
//! decode` does: in chunks, so a capture of any size or a live port is read in constant memory
//! (apart from the rpm histogram, bounded by 65,536 distinct speeds), until the stream ends.
//! A live port is read until its writer goes away: end of file, or `EIO`, which is what a
//! pseudo-terminal returns once the other side is closed.

use std::fmt::Write as _;
use std::io::{self, ErrorKind, Read};

use hilsim_lidar_emulator::neato_packet::{
    Decoder, DecoderStats, Packet, PacketSummary, Revolution, RevolutionAssembler,
};
use serde::Serialize;

/// Bytes read from the input at a time.
const CHUNK_LEN: usize = 64 * 1024;

/// `EIO` on Linux and the BSDs: what a pty master's reader gets once the slave side is closed.
#[cfg(unix)]
const EIO: i32 = 5;

/// What a stream held: `hilsim decode --json`'s object; field names are the interface
/// (`interfaces.md`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DecodeCounts {
    /// Bytes read.
    pub bytes: u64,
    /// Packets accepted (checksum good).
    pub packets: u64,
    /// Packets refused for their checksum.
    pub bad_checksum: u64,
    /// Bytes skipped while resynchronising.
    pub skipped_bytes: u64,
    /// Packet indices missing between accepted packets.
    pub index_gaps: u64,
    /// Readings in accepted packets.
    pub readings: u64,
    /// Of them, invalid.
    pub invalid: u64,
    /// Of them, with the strength warning.
    pub strength_warning: u64,
    /// Slowest motor speed of an accepted packet, rpm (0.0 when there are none).
    pub rpm_min: f64,
    /// Median motor speed, rpm (0.0 when there are none).
    pub rpm_median: f64,
    /// Fastest motor speed, rpm (0.0 when there are none).
    pub rpm_max: f64,
}

impl DecodeCounts {
    fn new(stats: &DecoderStats, summary: &PacketSummary) -> Self {
        Self {
            bytes: stats.bytes,
            packets: stats.packets,
            bad_checksum: stats.bad_checksum,
            skipped_bytes: stats.skipped_bytes,
            index_gaps: stats.index_gaps,
            readings: summary.readings(),
            invalid: summary.invalid(),
            strength_warning: summary.strength_warning(),
            rpm_min: summary.rpm_min(),
            rpm_median: summary.rpm_median(),
            rpm_max: summary.rpm_max(),
        }
    }
}

/// What is handed each decoded revolution.
pub type RevolutionSink<'a, E> = &'a mut dyn FnMut(&Revolution) -> Result<(), E>;

/// Why a stream could not be decoded to its end.
#[derive(Debug)]
pub enum DecodeError<E> {
    /// Reading the source failed.
    Read(io::Error),
    /// The revolution sink failed (e.g. writing the CSV).
    Sink(E),
}

/// Reads `source` to its end and decodes it; with `on_revolution`, hands it each revolution as
/// it completes (a partial first and last one included). An error from `on_revolution` stops
/// the decoding and is returned.
///
/// # Errors
/// A read error other than an interruption or a closed pty, or `on_revolution`'s.
pub fn decode_stream<E>(
    source: &mut dyn Read,
    mut on_revolution: Option<RevolutionSink<'_, E>>,
) -> Result<DecodeCounts, DecodeError<E>> {
    let mut decoder = Decoder::new();
    let mut summary = PacketSummary::new();
    let mut assembler = RevolutionAssembler::new();
    let mut chunk = vec![0; CHUNK_LEN];
    loop {
        let len = match source.read(&mut chunk) {
            Ok(0) => break,
            Ok(len) => len,
            Err(err) if err.kind() == ErrorKind::Interrupted => continue,
            Err(err) if is_closed_pty(&err) => break,
            Err(err) => return Err(DecodeError::Read(err)),
        };
        for packet in decoder.feed(&chunk[..len]) {
            summary.add(&packet);
            if let Some(sink) = on_revolution.as_mut() {
                if let Some(revolution) = assembler.push(packet) {
                    sink(&revolution).map_err(DecodeError::Sink)?;
                }
            }
        }
    }
    if let Some(sink) = on_revolution.as_mut() {
        if let Some(revolution) = assembler.finish() {
            sink(&revolution).map_err(DecodeError::Sink)?;
        }
    }
    Ok(DecodeCounts::new(&decoder.finish(), &summary))
}

#[cfg(unix)]
fn is_closed_pty(err: &io::Error) -> bool {
    err.raw_os_error() == Some(EIO)
}

#[cfg(not(unix))]
fn is_closed_pty(_err: &io::Error) -> bool {
    false
}

/// The header of the decoded readings' CSV (`hilsim decode --csv`).
pub const DECODED_CSV_HEADER: &str =
    "rev,packet_index,angle_deg,distance_mm,range_m,strength,invalid,warning,error_code,rpm";

/// Appends one CSV row per reading of `revolution`, in stream order, under
/// [`DECODED_CSV_HEADER`]: `rev` counts revolutions from 0, `angle_deg` is
/// `4 * packet_index + slot`, `distance_mm` and `range_m` are 0 for an invalid reading,
/// `invalid` and `warning` are 0/1, `error_code` is an invalid reading's code as `0x21`-style
/// hex (empty when valid) and `rpm` is that packet's motor speed.
pub fn decoded_csv_rows(revolution: &Revolution, out: &mut String) {
    for packet in revolution.packets.iter().flatten() {
        packet_rows(revolution.number, packet, out);
    }
}

fn packet_rows(rev: u64, packet: &Packet, out: &mut String) {
    for (angle_deg, reading) in (packet.first_angle_deg()..).zip(&packet.readings) {
        let distance_mm = if reading.invalid {
            0
        } else {
            reading.distance_mm
        };
        let error_code = reading
            .error_code()
            .map(|code| format!("{code:#04x}"))
            .unwrap_or_default();
        // Writing to a String cannot fail.
        let _ = writeln!(
            out,
            "{rev},{},{angle_deg},{distance_mm},{:.3},{},{},{},{error_code},{}",
            packet.index,
            f64::from(distance_mm) / 1000.0,
            reading.strength,
            u8::from(reading.invalid),
            u8::from(reading.strength_warning),
            packet.rpm(),
        );
    }
}
