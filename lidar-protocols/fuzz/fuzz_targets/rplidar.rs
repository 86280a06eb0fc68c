//! Feeds arbitrary bytes to the RPLIDAR decoder (whole and in chunks) and to the unit's request
//! parser, and checks what must hold for any input.
#![no_main]

use hilsim_lidar_protocols::rplidar::{RplidarDecoder, RplidarUnit, CAPSULE_LEN};
use hilsim_lidar_protocols::{HostDecoder, Output, Unit};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (chunk_len, stream) = match data.split_first() {
        Some((&first, rest)) => (usize::from(first).max(1), rest),
        None => (1, data),
    };
    let mut whole = RplidarDecoder::new();
    let mut points = Vec::new();
    whole.feed(stream, &mut points);
    let stats = whole.stats();
    assert_eq!(stats.bytes, stream.len() as u64);
    assert!(stats.bad_checksum <= stats.skipped_bytes);
    assert!(whole.pending_len() < CAPSULE_LEN);
    assert!(points.iter().all(|p| (0.0..360.0).contains(&p.angle_deg)));

    let mut chunked = RplidarDecoder::new();
    let mut chunked_points = Vec::new();
    for chunk in stream.chunks(chunk_len) {
        chunked.feed(chunk, &mut chunked_points);
    }
    assert_eq!(chunked_points, points);
    assert_eq!(chunked.stats(), stats);

    // The unit answers only with descriptors.
    let mut unit = RplidarUnit::new();
    let mut out = Output::new();
    for chunk in stream.chunks(chunk_len) {
        unit.host_wrote(chunk, 0.0, &mut out);
    }
    for (packet, _) in out.iter() {
        assert_eq!(&packet[..2], &[0xA5, 0x5A]);
    }
});
