//! Feeds arbitrary bytes to the LDS02RR decoder and checks what must hold for any input.
#![no_main]

use hilsim_lidar_protocols::lds02rr::Lds02rrDecoder;
use hilsim_lidar_protocols::xv11::PACKET_LEN;
use hilsim_lidar_protocols::HostDecoder;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (chunk_len, stream) = match data.split_first() {
        Some((&first, rest)) => (usize::from(first).max(1), rest),
        None => (1, data),
    };

    let mut decoder = Lds02rrDecoder::new();
    let mut points = Vec::new();
    decoder.feed(stream, &mut points);
    let stats = decoder.stats();
    assert_eq!(stats.bytes, stream.len() as u64);
    assert_eq!(
        stats.packets * PACKET_LEN as u64 + stats.skipped_bytes + decoder.pending_len() as u64,
        stats.bytes
    );
    assert_eq!(points.len() as u64, 4 * stats.packets);
    for point in &points {
        assert!((0.0..360.0).contains(&point.angle_deg));
        assert!(point.distance_mm <= 0x3FFF);
    }

    let mut chunked = Lds02rrDecoder::new();
    let mut chunked_points = Vec::new();
    for chunk in stream.chunks(chunk_len) {
        chunked.feed(chunk, &mut chunked_points);
    }
    assert_eq!(chunked_points, points);
    assert_eq!(chunked.stats(), stats);
});
