//! Feeds arbitrary bytes to the LDS-01 decoder, and arbitrary host bytes to its unit, and checks
//! what must hold for any input.
#![no_main]

use hilsim_lidar_protocols::lds01::{
    checksum, Lds01Decoder, Lds01Unit, Packet, INDEX_BASE, PACKETS_PER_REVOLUTION, PACKET_LEN,
    START_BYTE,
};
use hilsim_lidar_protocols::{HostDecoder, Output, Unit};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (chunk_len, stream) = match data.split_first() {
        Some((&first, rest)) => (usize::from(first).max(1), rest),
        None => (1, data),
    };

    let mut decoder = Lds01Decoder::new();
    let mut packets = 0u64;
    for (at, &byte) in stream.iter().enumerate() {
        if let Some(packet) = decoder.push(byte) {
            let bytes = packet.encode();
            assert_eq!(&stream[at + 1 - PACKET_LEN..=at], &bytes[..]);
            assert_eq!(bytes[0], START_BYTE);
            assert!(usize::from(packet.index) < PACKETS_PER_REVOLUTION);
            assert_eq!(bytes[1], INDEX_BASE + packet.index);
            assert_eq!(checksum(&bytes).to_le_bytes(), [bytes[40], bytes[41]]);
            assert_eq!(Packet::decode(&bytes), Some(packet));
            packets += 1;
        }
        let stats = decoder.stats();
        assert_eq!(
            stats.packets * PACKET_LEN as u64 + stats.skipped_bytes + decoder.pending_len() as u64,
            stats.bytes
        );
    }
    let stats = decoder.stats();
    assert_eq!(stats.packets, packets);

    let mut whole = Vec::new();
    Lds01Decoder::new().feed(stream, &mut whole);
    let mut chunked = Lds01Decoder::new();
    let mut points = Vec::new();
    for chunk in stream.chunks(chunk_len) {
        chunked.feed(chunk, &mut points);
    }
    assert_eq!(points, whole);
    assert_eq!(chunked.stats(), stats);

    // The same bytes as host commands: no replies; the last `b` or `e` decides.
    let mut unit = Lds01Unit::new();
    let mut out = Output::new();
    for chunk in stream.chunks(chunk_len) {
        unit.host_wrote(chunk, 0.0, &mut out);
    }
    assert!(out.is_empty());
    let last = stream.iter().rev().find(|&&b| b == b'b' || b == b'e');
    assert_eq!(unit.scanning(), last.is_none_or(|&b| b == b'b'));
});
