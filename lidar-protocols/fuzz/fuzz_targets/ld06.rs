//! Feeds arbitrary bytes to the LD06 decoder and checks what must hold for any input.
#![no_main]

use hilsim_lidar_protocols::ld06::{crc8, Ld06Decoder, Packet, HEADER, PACKET_LEN, VER_LEN};
use hilsim_lidar_protocols::HostDecoder;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The first byte picks a chunk size, so split feeds are fuzzed too.
    let (chunk_len, stream) = match data.split_first() {
        Some((&first, rest)) => (usize::from(first).max(1), rest),
        None => (1, data),
    };

    let mut decoder = Ld06Decoder::new();
    let mut packets = 0u64;
    for (at, &byte) in stream.iter().enumerate() {
        if let Some(packet) = decoder.push(byte) {
            // Every packet is exactly the 47 bytes just read, header and CRC good.
            let bytes = packet.encode();
            assert_eq!(&stream[at + 1 - PACKET_LEN..=at], &bytes[..]);
            assert_eq!((bytes[0], bytes[1]), (HEADER, VER_LEN));
            assert_eq!(crc8(&bytes[..PACKET_LEN - 1]), bytes[PACKET_LEN - 1]);
            assert_eq!(Packet::decode(&bytes), Some(packet));
            for i in 0..12 {
                let angle = packet.angle_deg(i);
                assert!((0.0..360.0).contains(&angle));
            }
            packets += 1;
        }
        let stats = decoder.stats();
        assert_eq!(stats.bytes, at as u64 + 1);
        assert_eq!(
            stats.packets * PACKET_LEN as u64 + stats.skipped_bytes + decoder.pending_len() as u64,
            stats.bytes
        );
        assert!(decoder.pending_len() < PACKET_LEN);
    }
    let stats = decoder.stats();
    assert_eq!(stats.packets, packets);

    // In chunks: the same points and counts.
    let mut whole = Vec::new();
    Ld06Decoder::new().feed(stream, &mut whole);
    assert_eq!(whole.len() as u64, 12 * packets);
    let mut chunked = Ld06Decoder::new();
    let mut points = Vec::new();
    for chunk in stream.chunks(chunk_len) {
        chunked.feed(chunk, &mut points);
    }
    assert_eq!(points, whole);
    assert_eq!(chunked.stats(), stats);
});
