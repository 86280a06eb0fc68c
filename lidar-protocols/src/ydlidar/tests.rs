//! Round trips unit → decoder, the command exchanges and damaged streams.

use super::*;
use crate::{DecodeStats, HostDecoder, Output, Point, Unit, UnitReading};
use proptest::prelude::*;

/// A revolution's readings as the X4's head takes them: `n` evenly spaced, 5,000 a second.
fn revolution(rev: u64, n: u32, distance: impl Fn(u32) -> u32) -> Vec<UnitReading> {
    (0..n)
        .map(|i| UnitReading {
            t_s: f64::from(rev as u32 * n + i) / 5000.0,
            rev,
            index: i,
            angle_deg: 0.2 + f64::from(i) * 360.0 / f64::from(n),
            distance_mm: distance(i),
            intensity: 0,
            rev_hz: 7.0,
            starts_revolution: i == 0,
        })
        .collect()
}

fn decode(bytes: &[u8]) -> (Vec<Point>, DecodeStats) {
    let mut decoder = YdlidarDecoder::new();
    let mut points = Vec::new();
    decoder.feed(bytes, &mut points);
    (points, decoder.stats())
}

fn angle_error(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

fn scan(readings: &[UnitReading]) -> Output {
    let mut unit = YdlidarUnit::new();
    let mut out = Output::new();
    unit.host_wrote(&[0xA5, cmd::FORCE_STOP, 0xA5, cmd::SCAN], 0.0, &mut out);
    for r in readings {
        unit.push(r, &mut out);
    }
    unit.host_wrote(&[0xA5, cmd::STOP], 9.0, &mut out);
    out
}

#[test]
fn info_and_health_replies_are_the_x4s() {
    let mut unit = YdlidarUnit::new();
    let mut out = Output::new();
    unit.host_wrote(&[0x11, 0xA5], 1.0, &mut out);
    unit.host_wrote(&[cmd::GET_INFO, 0xA5, cmd::GET_HEALTH], 2.0, &mut out);
    assert_eq!(out.packets.len(), 2);
    let (info, span) = out.iter().next().unwrap();
    assert_eq!(&info[..8], [0xA5, 0x5A, 0x14, 0x00, 0x00, 0x00, 0x04, 6]);
    assert_eq!(info.len(), 27);
    assert_eq!(span.due_s, 2.0);
    let (health, _) = out.iter().nth(1).unwrap();
    assert_eq!(health, [0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, 0, 0, 0]);
    let (points, stats) = decode(&out.bytes);
    assert!(points.is_empty());
    assert_eq!((stats.packets, stats.skipped_bytes), (2, 0));
    assert!(!unit.scanning());
}

#[test]
fn packet_layout_and_checksum_follow_the_manual() {
    let packet = Packet {
        ct: 0,
        fsa_q6: 0x6FE5 >> 1,
        lsa_q6: 0x79BD >> 1,
        samples: vec![0x1234, 0x0F00],
    };
    let mut bytes = Vec::new();
    packet.write(&mut bytes);
    assert_eq!(
        &bytes[..8],
        [0xAA, 0x55, 0x00, 0x02, 0xE5, 0x6F, 0xBD, 0x79]
    );
    let cs = 0x55AA ^ 0x0200 ^ 0x6FE5 ^ 0x79BD ^ 0x1234 ^ 0x0F00;
    assert_eq!(&bytes[8..10], (cs as u16).to_le_bytes());
    assert_eq!(&bytes[10..], [0x34, 0x12, 0x00, 0x0F]);
}

#[test]
fn revolutions_open_with_a_zero_packet_and_round_trip() {
    // 714 readings a revolution (5,000 a second at 7 Hz); near and far jumps, no returns.
    let mut readings = revolution(0, 714, |i| match i % 100 {
        0..=9 => 0,
        10..=49 => 130 + 5 * i,
        _ => 3000 + 10 * (i % 7),
    });
    readings.extend(revolution(1, 714, |i| 9000 + i));
    let out = scan(&readings);
    assert_eq!(&out.bytes[..7], [0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81]);
    let packets: Vec<_> = out.iter().skip(1).collect();
    let zeros: Vec<_> = packets.iter().filter(|(b, _)| b[2] & 1 == 1).collect();
    assert_eq!(zeros.len(), 2);
    for (bytes, span) in &zeros {
        assert_eq!(bytes[3], 1, "a zero packet holds one sample");
        assert_eq!(bytes[2] >> 1, 70, "7 Hz in tenths");
        assert!(span.starts_revolution);
    }
    assert!(packets.iter().all(|(b, _)| b[3] as usize <= MAX_SAMPLES));
    let samples: usize = packets.iter().map(|(b, _)| usize::from(b[3])).sum();
    assert_eq!(samples, readings.len());
    // Far, even stretches fill whole packets.
    assert!(
        packets.len() < readings.len() / 10,
        "{} packets",
        packets.len()
    );

    let (points, stats) = decode(&out.bytes);
    assert_eq!(stats.packets as usize, out.packets.len());
    assert_eq!((stats.skipped_bytes, stats.bad_checksum), (0, 0));
    assert_eq!(points.len(), readings.len());
    for (p, r) in points.iter().zip(&readings) {
        assert!(
            angle_error(p.angle_deg, r.angle_deg) <= 0.1 + 1e-9,
            "{p:?} {r:?}"
        );
        assert_eq!(p.distance_mm, r.distance_mm);
        assert_eq!(p.starts_revolution, r.starts_revolution);
        assert_eq!(p.rev_hz.is_some(), r.starts_revolution);
    }
    // Each packet is due at its last reading.
    assert_eq!(out.packets[1].due_s, readings[0].t_s);
}

#[test]
fn decoder_resynchronises_after_lost_and_flipped_bytes() {
    let readings = revolution(0, 400, |i| 2000 + i);
    let out = scan(&readings);
    let mut wire = out.bytes.clone();
    let third = out.packets[3].range.clone();
    wire[third.start + 12] ^= 0x40;
    wire.remove(out.packets[5].range.start + 3);
    let (points, stats) = decode(&wire);
    assert!(stats.bad_checksum >= 2, "{stats:?}");
    let lost = (out.packets[3].range.len() - 10) / 2 + (out.packets[5].range.len() - 10) / 2;
    assert_eq!(points.len(), readings.len() - lost);
    assert_eq!(points.last().unwrap().distance_mm, 2399);
}

proptest! {
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5EED_0A03),
        cases: 64,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_readings_survive_the_round_trip(
        start in 0.0f64..360.0,
        steps in prop::collection::vec((0.2f64..1.2, 0u32..12_000, prop::bool::weighted(0.01)), 1..400)
    ) {
        let mut angle = start;
        let readings: Vec<UnitReading> = steps.iter().enumerate().map(|(i, &(step, distance_mm, starts))| {
            angle = (angle + step) % 360.0;
            UnitReading {
                t_s: i as f64 * 2e-4, rev: 0, index: i as u32, angle_deg: angle, distance_mm,
                intensity: 0, rev_hz: 7.0, starts_revolution: starts,
            }
        }).collect();
        let (points, stats) = decode(&scan(&readings).bytes);
        prop_assert_eq!(points.len(), readings.len());
        prop_assert_eq!(stats.skipped_bytes, 0);
        for (p, r) in points.iter().zip(&readings) {
            prop_assert!(angle_error(p.angle_deg, r.angle_deg) <= 0.1 + 1e-9, "{:?} {:?}", p, r);
            prop_assert_eq!(p.distance_mm, r.distance_mm);
            prop_assert_eq!(p.starts_revolution, r.starts_revolution);
        }
    }

    #[test]
    fn random_bytes_never_panic_and_chunks_change_nothing(
        bytes in prop::collection::vec(any::<u8>(), 0..2000), chunk in 1usize..100
    ) {
        let (points, stats) = decode(&bytes);
        let mut decoder = YdlidarDecoder::new();
        let mut chunked = Vec::new();
        for piece in bytes.chunks(chunk) {
            decoder.feed(piece, &mut chunked);
        }
        prop_assert_eq!(&chunked, &points);
        prop_assert_eq!(decoder.stats(), stats);
        prop_assert_eq!(stats.bytes, bytes.len() as u64);
        prop_assert!(stats.bad_checksum <= stats.skipped_bytes);
        prop_assert!(decoder.pending_len() <= HEADER_LEN + 2 * 128);
        prop_assert!(points.iter().all(|p| (0.0..360.0).contains(&p.angle_deg)));
    }

    #[test]
    fn random_command_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        let mut unit = YdlidarUnit::new();
        let mut out = Output::new();
        unit.host_wrote(&bytes, 0.0, &mut out);
        for (packet, _) in out.iter() {
            prop_assert_eq!(&packet[..2], &[0xA5, 0x5A]);
        }
    }
}
