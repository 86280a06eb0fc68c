//! Feeds arbitrary bytes to the SCIP 2.0 decoder, and as commands to the unit, and checks what
//! must hold for any input.
#![no_main]

use hilsim_lidar_protocols::scip::{ScipDecoder, ScipUnit};
use hilsim_lidar_protocols::{HostDecoder, Output, Unit};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The first byte picks a chunk size, so split feeds are fuzzed too.
    let (chunk_len, stream) = match data.split_first() {
        Some((&first, rest)) => (usize::from(first).max(1), rest),
        None => (1, data),
    };

    let mut decoder = ScipDecoder::new();
    let mut points = Vec::new();
    for &byte in stream {
        decoder.feed(&[byte], &mut points);
        let stats = decoder.stats();
        assert!(stats.skipped_bytes + decoder.pending_len() as u64 <= stats.bytes);
        assert!(decoder.pending_len() <= 4096 + 128);
    }
    let stats = decoder.stats();
    assert_eq!(stats.bytes, stream.len() as u64);
    for point in &points {
        assert!((0.0..360.0).contains(&point.angle_deg));
        assert!(point.distance_mm == 0 || point.distance_mm >= 20);
    }

    let mut chunked = ScipDecoder::new();
    let mut chunked_points = Vec::new();
    for chunk in stream.chunks(chunk_len) {
        chunked.feed(chunk, &mut chunked_points);
    }
    assert_eq!(chunked_points, points);
    assert_eq!(chunked.stats(), stats);

    // The same bytes as the host's commands: every reply is a whole packet, and the decoder
    // reads the unit's replies back without a bad checksum.
    let mut unit = ScipUnit::new();
    let mut out = Output::new();
    for chunk in stream.chunks(chunk_len) {
        unit.host_wrote(chunk, 0.0, &mut out);
    }
    let mut replies = ScipDecoder::new();
    replies.feed(&out.bytes, &mut Vec::new());
    assert_eq!(replies.stats().bad_checksum, 0);
    assert_eq!(replies.stats().packets, out.packets.len() as u64);
});
