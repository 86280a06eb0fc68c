//! The XV-11 decoder must read what a real unit sends, gaps and damage included; it is
//! checked on a real capture against a deliberately naive scan written independently here.

use std::collections::BTreeMap;

use hilsim_lidar_emulator::neato_packet::{
    Decoder, DecoderStats, Packet, PacketSummary, RevolutionAssembler,
};

const CAPTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../tests/data/captures/xv11-hand-in-box.bin"
);

fn capture() -> Vec<u8> {
    std::fs::read(CAPTURE).unwrap_or_else(|err| panic!("{CAPTURE}: cannot read: {err}"))
}

/// The checksum exactly as the protocol note writes it, independent of the library's.
fn naive_checksum(bytes: &[u8]) -> u16 {
    let mut acc: u64 = 0;
    for i in 0..10 {
        acc = (acc << 1) + u64::from(bytes[2 * i]) + (u64::from(bytes[2 * i + 1]) << 8);
    }
    (((acc & 0x7FFF) + (acc >> 15)) & 0x7FFF) as u16
}

/// What the naive scan finds.
#[derive(Debug, Default)]
struct NaiveScan {
    packets: Vec<[u8; 22]>,
    bad_checksum: u64,
    skipped_bytes: u64,
}

/// Every offset, in order: a start byte, an index in A0..F9 and a good checksum is a packet
/// (jump past it); a start byte and index with a bad checksum is counted; anything else moves
/// on by one byte.
fn naive_scan(data: &[u8]) -> NaiveScan {
    let mut scan = NaiveScan::default();
    let mut at = 0;
    while at < data.len() {
        if at + 22 <= data.len() && data[at] == 0xFA && (0xA0..=0xF9).contains(&data[at + 1]) {
            let candidate = &data[at..at + 22];
            let stored = u16::from(candidate[20]) | u16::from(candidate[21]) << 8;
            if naive_checksum(candidate) == stored {
                let mut packet = [0; 22];
                packet.copy_from_slice(candidate);
                scan.packets.push(packet);
                at += 22;
                continue;
            }
            scan.bad_checksum += 1;
        }
        scan.skipped_bytes += 1;
        at += 1;
    }
    scan
}

fn decode(data: &[u8], chunk: usize) -> (Vec<Packet>, DecoderStats) {
    let mut decoder = Decoder::new();
    let mut packets = Vec::new();
    for piece in data.chunks(chunk) {
        packets.extend(decoder.feed(piece));
    }
    (packets, decoder.finish())
}

#[test]
fn decoder_agrees_with_a_naive_scan_of_the_real_capture() {
    let data = capture();
    let (packets, stats) = decode(&data, 4096);
    let naive = naive_scan(&data);

    let encoded: Vec<[u8; 22]> = packets.iter().map(Packet::encode).collect();
    assert_eq!(encoded, naive.packets, "same packets, byte for byte");
    assert_eq!(stats.bytes, data.len() as u64);
    assert_eq!(stats.packets, naive.packets.len() as u64);
    assert_eq!(stats.bad_checksum, naive.bad_checksum);
    assert_eq!(stats.skipped_bytes, naive.skipped_bytes);
    let naive_gaps = naive
        .packets
        .windows(2)
        .filter(|pair| pair[1][1] != 0xA0 + (pair[0][1] - 0xA0 + 1) % 90)
        .count();
    assert_eq!(stats.index_gaps, naive_gaps as u64);

    // Pinned from the naive scan (and a separate script) when this test was written, so a
    // change of behaviour shows up even if both scans changed together.
    assert_eq!(data.len(), 252_146);
    assert_eq!(
        (
            stats.packets,
            stats.bad_checksum,
            stats.skipped_bytes,
            stats.index_gaps
        ),
        (11_451, 1, 224, 512)
    );
}

#[test]
fn chunk_size_does_not_change_the_result() {
    let data = capture();
    let whole = decode(&data, data.len().max(1));
    for chunk in [1, 21, 22, 23, 1000] {
        assert_eq!(decode(&data, chunk), whole, "chunk size {chunk}");
    }
}

#[test]
fn real_capture_has_what_the_readme_promises() {
    let (packets, stats) = decode(&capture(), 4096);
    let mut summary = PacketSummary::new();
    let mut error_codes = BTreeMap::<u8, u64>::new();
    for packet in &packets {
        summary.add(packet);
        for code in packet.readings.iter().filter_map(|r| r.error_code()) {
            *error_codes.entry(code).or_default() += 1;
        }
    }
    assert_eq!(summary.readings(), 4 * stats.packets);

    // Invalid readings with several error codes, among them the ones the note names.
    assert!(summary.invalid() > 1000, "invalid: {}", summary.invalid());
    assert!(error_codes.len() >= 3, "error codes: {error_codes:x?}");
    for code in [0x21, 0x35, 0x52] {
        assert!(error_codes.contains_key(&code), "no error code {code:#x}");
    }
    assert!(summary.strength_warning() > 0);

    // The motor spun up: speeds below the drivers' 180..349 rpm window, yet the median sits
    // near the 300 rpm set point.
    assert!(summary.rpm_min() < 180.0, "rpm_min {}", summary.rpm_min());
    assert!(summary.rpm_max() <= 1024.0);
    assert!(
        (280.0..=320.0).contains(&summary.rpm_median()),
        "rpm_median {}",
        summary.rpm_median()
    );
    let outside = packets
        .iter()
        .filter(|p| !(180.0..349.0).contains(&p.rpm()))
        .count();
    assert!(outside > 0);

    // Gaps in the stream.
    assert!(stats.index_gaps > 0 && stats.missing_packets > 0);
    assert!(stats.bad_checksum > 0 || stats.skipped_bytes > 0);

    // Whole revolutions are there as well as broken ones.
    let mut assembler = RevolutionAssembler::new();
    let mut revolutions: Vec<_> = packets.iter().filter_map(|&p| assembler.push(p)).collect();
    revolutions.extend(assembler.finish());
    let complete = revolutions.iter().filter(|r| r.is_complete()).count();
    assert!(complete > 0, "no complete revolution");
    assert!(complete < revolutions.len(), "no revolution with gaps");
    let assembled: usize = revolutions.iter().map(|r| r.packet_count()).sum();
    assert_eq!(
        assembled,
        packets.len(),
        "every packet lands in exactly one revolution"
    );
}
