//! Feeds arbitrary bytes to the XV-11 decoder and checks what must hold for any input.
#![no_main]

use hilsim_lidar_protocols::xv11::{
    checksum, Decoder, Packet, PacketSummary, INDEX_BASE, PACKETS_PER_REVOLUTION, PACKET_LEN,
    START_BYTE,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // The first byte picks a chunk size, so split feeds are fuzzed too.
    let (chunk_len, stream) = match data.split_first() {
        Some((&first, rest)) => (usize::from(first).max(1), rest),
        None => (1, data),
    };

    // Byte by byte, where every packet's place in the stream is known.
    let mut decoder = Decoder::new();
    let mut packets: Vec<Packet> = Vec::new();
    for (at, &byte) in stream.iter().enumerate() {
        if let Some(packet) = decoder.push(byte) {
            let bytes = packet.encode();
            // Every emitted packet is exactly the 22 bytes just read, well formed, with a valid
            // checksum whose high byte is at most 0x7F.
            assert_eq!(&stream[at + 1 - PACKET_LEN..=at], &bytes[..]);
            assert_eq!(bytes[0], START_BYTE);
            assert!(usize::from(packet.index) < PACKETS_PER_REVOLUTION);
            assert_eq!(bytes[1], INDEX_BASE + packet.index);
            assert_eq!(checksum(&bytes).to_le_bytes(), [bytes[20], bytes[21]]);
            assert!(bytes[21] <= 0x7F);
            assert_eq!(Packet::decode(&bytes), Ok(packet));
            assert_eq!(decoder.pending_len(), 0);
            packets.push(packet);
        }
        let stats = decoder.stats();
        assert_eq!(stats.bytes, at as u64 + 1);
        assert_eq!(
            stats.packets * PACKET_LEN as u64 + stats.skipped_bytes + decoder.pending_len() as u64,
            stats.bytes
        );
        assert!(decoder.pending_len() < PACKET_LEN);
    }
    let stats = decoder.finish();
    assert_eq!(stats.bytes, stream.len() as u64);
    assert_eq!(stats.packets, packets.len() as u64);
    assert_eq!(
        stats.packets * PACKET_LEN as u64 + stats.skipped_bytes,
        stats.bytes
    );
    assert!(stats.index_gaps <= stats.packets.saturating_sub(1));
    assert!(stats.missing_packets >= stats.index_gaps);
    // A failed candidate's start byte is always skipped, so failures never outnumber skips.
    assert!(stats.bad_checksum <= stats.skipped_bytes);

    // In chunks: the same packets and counts.
    let mut chunked = Decoder::new();
    let mut chunked_packets = Vec::new();
    for chunk in stream.chunks(chunk_len) {
        chunked_packets.extend(chunked.feed(chunk));
    }
    assert_eq!(chunked_packets, packets);
    assert_eq!(chunked.finish(), stats);

    let mut summary = PacketSummary::new();
    packets.iter().for_each(|packet| summary.add(packet));
    assert_eq!(summary.readings(), 4 * stats.packets);
    assert!(summary.invalid() <= summary.readings());
    assert!(summary.strength_warning() <= summary.readings());
    for rpm in [summary.rpm_min(), summary.rpm_median(), summary.rpm_max()] {
        assert!(rpm.is_finite() && rpm >= 0.0);
    }
    assert!(summary.rpm_min() <= summary.rpm_median());
    assert!(summary.rpm_median() <= summary.rpm_max());
});
