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
use hilsim_lidar_protocols::{HostDecoder, LidarModel, Point};
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
    while let Some(len) = read_chunk(source, &mut chunk)? {
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

/// The next chunk of `source` into `chunk`: its length, or `None` at the stream's end (end of
/// file, or a pty whose writer went away).
fn read_chunk<E>(source: &mut dyn Read, chunk: &mut [u8]) -> Result<Option<usize>, DecodeError<E>> {
    loop {
        match source.read(chunk) {
            Ok(0) => return Ok(None),
            Ok(len) => return Ok(Some(len)),
            Err(err) if err.kind() == ErrorKind::Interrupted => {}
            Err(err) if is_closed_pty(&err) => return Ok(None),
            Err(err) => return Err(DecodeError::Read(err)),
        }
    }
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

/// What a stream of a unit other than the XV-11 held: `hilsim decode --model M --json`'s
/// object.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UnitDecodeCounts {
    /// The unit (`rplidar-a1`, …).
    pub model: &'static str,
    /// Bytes read.
    pub bytes: u64,
    /// Packets (or replies) accepted.
    pub packets: u64,
    /// Packets refused for their checksum or check bits.
    pub bad_checksum: u64,
    /// Bytes skipped while resynchronising.
    pub skipped_bytes: u64,
    /// Readings decoded.
    pub readings: u64,
    /// Of them, without a return (distance 0).
    pub no_return: u64,
    /// Revolutions begun (readings the unit marked as a revolution's first).
    pub revolutions: u64,
    /// The median revolution rate the packets reported, Hz (0.0 when they report none).
    pub rev_hz_median: f64,
}

/// What is handed each decoded reading, with its revolution's number.
pub type PointSink<'a, E> = &'a mut dyn FnMut(u64, &Point) -> Result<(), E>;

/// Reads `source` to its end and decodes it with `decoder` (the unit `model`'s host side);
/// with `on_point`, hands it each reading with its revolution's number (counted from 0, a
/// partial first one included). Memory stays bounded: the rate's median comes from a
/// histogram of 0.01 Hz bins up to 100 Hz.
///
/// # Errors
/// A read error other than an interruption or a closed pty, or `on_point`'s.
pub fn decode_unit_stream<E>(
    source: &mut dyn Read,
    model: LidarModel,
    decoder: &mut dyn HostDecoder,
    mut on_point: Option<PointSink<'_, E>>,
) -> Result<UnitDecodeCounts, DecodeError<E>> {
    const RATE_BINS: usize = 10_000;
    let mut rates = vec![0_u64; RATE_BINS];
    let mut chunk = vec![0; CHUNK_LEN];
    let mut points = Vec::new();
    let mut counts = UnitDecodeCounts {
        model: model.name(),
        bytes: 0,
        packets: 0,
        bad_checksum: 0,
        skipped_bytes: 0,
        readings: 0,
        no_return: 0,
        revolutions: 0,
        rev_hz_median: 0.0,
    };
    let mut rev: Option<u64> = None;
    while let Some(len) = read_chunk(source, &mut chunk)? {
        points.clear();
        decoder.feed(&chunk[..len], &mut points);
        for point in &points {
            if point.starts_revolution || rev.is_none() {
                rev = Some(rev.map_or(0, |r| r + 1));
                if point.starts_revolution {
                    counts.revolutions += 1;
                }
            }
            counts.readings += 1;
            counts.no_return += u64::from(point.distance_mm == 0);
            if let Some(hz) = point.rev_hz.filter(|hz| hz.is_finite() && *hz >= 0.0) {
                rates[((hz * 100.0).round() as usize).min(RATE_BINS - 1)] += 1;
            }
            if let Some(sink) = on_point.as_mut() {
                sink(rev.unwrap_or(0), point).map_err(DecodeError::Sink)?;
            }
        }
    }
    let stats = decoder.stats();
    counts.bytes = stats.bytes;
    counts.packets = stats.packets;
    counts.bad_checksum = stats.bad_checksum;
    counts.skipped_bytes = stats.skipped_bytes;
    let total: u64 = rates.iter().sum();
    if total > 0 {
        let mut seen = 0;
        for (bin, n) in rates.iter().enumerate() {
            seen += n;
            if 2 * seen >= total {
                counts.rev_hz_median = bin as f64 / 100.0;
                break;
            }
        }
    }
    Ok(counts)
}

/// The header of a unit's decoded readings' CSV (`hilsim decode --model M --csv`).
pub const UNIT_CSV_HEADER: &str = "rev,angle_deg,distance_mm,range_m,intensity,rev_hz";

/// One CSV row under [`UNIT_CSV_HEADER`]: the angle in the unit's own convention, the
/// distance 0 without a return, the rate empty when the packet reports none.
pub fn unit_csv_row(rev: u64, point: &Point, out: &mut String) {
    let rate = point
        .rev_hz
        .map(|hz| format!("{hz:.3}"))
        .unwrap_or_default();
    // Writing to a String cannot fail.
    let _ = writeln!(
        out,
        "{rev},{:.3},{},{:.3},{},{rate}",
        point.angle_deg,
        point.distance_mm,
        f64::from(point.distance_mm) / 1000.0,
        point.intensity,
    );
}
