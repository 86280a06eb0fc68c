//! Round trips unit → decoder, the request exchanges and damaged streams.

use super::*;
use crate::{HostDecoder, Output, Point, Unit, UnitReading};
use proptest::prelude::*;

/// A revolution's readings as the A1's head takes them: `n` evenly spaced, 2,000 a second.
fn revolution(rev: u64, n: u32, distance: impl Fn(u32) -> u32) -> Vec<UnitReading> {
    (0..n)
        .map(|i| UnitReading {
            t_s: (f64::from(rev as u32 * n + i)) / 2000.0,
            rev,
            index: i,
            angle_deg: 0.3 + f64::from(i) * 360.0 / f64::from(n),
            distance_mm: distance(i),
            intensity: (i % 256) as u8,
            rev_hz: 5.5,
            starts_revolution: i == 0,
        })
        .collect()
}

fn run(unit: &mut RplidarUnit, readings: &[UnitReading]) -> Output {
    let mut out = Output::new();
    for r in readings {
        unit.push(r, &mut out);
    }
    out
}

fn decode(bytes: &[u8]) -> (Vec<Point>, crate::DecodeStats) {
    let mut decoder = RplidarDecoder::new();
    let mut points = Vec::new();
    decoder.feed(bytes, &mut points);
    (points, decoder.stats())
}

fn angle_error(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

#[test]
fn info_health_and_samplerate_replies_are_the_a1s() {
    let mut unit = RplidarUnit::new();
    let mut out = Output::new();
    unit.host_wrote(&[0xA5, cmd::GET_INFO, 0xA5], 1.0, &mut out);
    unit.host_wrote(&[cmd::GET_HEALTH, 0xA5, cmd::GET_SAMPLERATE], 2.0, &mut out);
    assert_eq!(out.packets.len(), 3);
    let (info, span) = out.iter().next().unwrap();
    assert_eq!(&info[..7], [0xA5, 0x5A, 0x14, 0x00, 0x00, 0x00, 0x04]);
    assert_eq!(&info[7..11], [0x18, 29, 1, 7]);
    assert_eq!(info.len(), 27);
    assert_eq!(span.due_s, 1.0);
    let (health, span) = out.iter().nth(1).unwrap();
    assert_eq!(health, [0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, 0, 0, 0]);
    assert_eq!(span.due_s, 2.0);
    let (rate, _) = out.iter().nth(2).unwrap();
    assert_eq!(
        rate,
        [0xA5, 0x5A, 0x04, 0x00, 0x00, 0x00, 0x15, 0xF4, 0x01, 0xFA, 0x00]
    );
    assert!(!unit.scanning());
    // The replies decode as packets without readings.
    let (points, stats) = decode(&out.bytes);
    assert!(points.is_empty());
    assert_eq!((stats.packets, stats.skipped_bytes), (3, 0));
}

#[test]
fn scan_answers_its_descriptor_and_streams_until_stop() {
    let mut unit = RplidarUnit::new();
    let readings = revolution(0, 400, |i| 150 + 7 * i);
    assert!(
        run(&mut unit, &readings[..10]).is_empty(),
        "idle unit sent readings"
    );
    let mut out = Output::new();
    // FORCE_SCAN, split across writes, garbage before it.
    unit.host_wrote(&[0x00, 0x5A, 0xA5], 0.5, &mut out);
    unit.host_wrote(&[cmd::FORCE_SCAN], 0.5, &mut out);
    assert_eq!(out.bytes, [0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81]);
    assert!(unit.scanning());
    for r in &readings {
        unit.push(r, &mut out);
    }
    assert_eq!(out.packets.len(), 401);
    assert_eq!(out.packets[5].due_s, readings[4].t_s);
    assert!(out.packets[1].starts_revolution && !out.packets[2].starts_revolution);
    unit.host_wrote(&[0xA5, cmd::STOP], 1.0, &mut out);
    assert!(!unit.scanning());
    let before = out.bytes.len();
    unit.push(&readings[0], &mut out);
    assert_eq!(out.bytes.len(), before);

    let (points, stats) = decode(&out.bytes);
    assert_eq!(points.len(), 400);
    assert_eq!(
        (stats.packets, stats.skipped_bytes, stats.bad_checksum),
        (401, 0, 0)
    );
    for (p, r) in points.iter().zip(&readings) {
        assert!(
            angle_error(p.angle_deg, r.angle_deg) <= 1.0 / 128.0,
            "{p:?} {r:?}"
        );
        assert_eq!(p.distance_mm, r.distance_mm);
        assert_eq!(p.intensity, u16::from(r.intensity >> 2));
        assert_eq!(p.starts_revolution, r.starts_revolution);
    }
}

#[test]
fn set_motor_pwm_and_unknown_requests_get_no_reply_and_bad_checksums_are_dropped() {
    let mut unit = RplidarUnit::new();
    let mut out = Output::new();
    unit.host_wrote(
        &request(cmd::SET_MOTOR_PWM, &660u16.to_le_bytes()),
        0.0,
        &mut out,
    );
    unit.host_wrote(
        &[0xA5, 0x84, 0x04, 0x70, 0, 0, 0, 0xA5 ^ 0x84 ^ 0x04 ^ 0x70],
        0.0,
        &mut out,
    );
    let mut bad = request(cmd::EXPRESS_SCAN, &[0; 5]);
    bad[8] ^= 0x10;
    unit.host_wrote(&bad, 0.0, &mut out);
    assert!(out.is_empty());
    assert!(!unit.scanning());
    // RESET stops a scan and sends nothing.
    unit.host_wrote(&[0xA5, cmd::SCAN], 0.0, &mut out);
    unit.host_wrote(&[0xA5, cmd::RESET], 0.0, &mut out);
    assert!(!unit.scanning());
    assert_eq!(out.packets.len(), 1);
}

#[test]
fn express_capsules_round_trip_within_the_field_resolution() {
    let mut unit = RplidarUnit::new();
    let mut out = Output::new();
    unit.host_wrote(&request(cmd::EXPRESS_SCAN, &[0; 5]), 0.0, &mut out);
    assert_eq!(out.bytes, [0xA5, 0x5A, 0x54, 0x00, 0x00, 0x40, 0x82]);
    // Two revolutions of 727 readings (4,000 a second at 5.5 Hz), odd distances.
    let mut readings = revolution(0, 727, |i| if i % 50 == 7 { 0 } else { 120 + 13 * i });
    readings.extend(revolution(1, 727, |i| 16_000 + i));
    for r in &readings {
        unit.push(r, &mut out);
    }
    let capsules = readings.len() / 32;
    assert_eq!(out.packets.len(), 1 + capsules);
    assert!(out.packets[1..].iter().all(|s| s.range.len() == 84));
    assert_eq!(out.packets[1].due_s, readings[31].t_s);
    // The S flag is on the first capsule only.
    assert_eq!(out.bytes[7 + 3] >> 7, 1);
    assert_eq!(out.bytes[7 + 84 + 3] >> 7, 0);

    let (points, stats) = decode(&out.bytes);
    assert_eq!(stats.packets as usize, 1 + capsules);
    assert_eq!(stats.bad_checksum, 0);
    // The last capsule waits for its successor.
    assert_eq!(points.len(), 32 * (capsules - 1));
    for (p, r) in points.iter().zip(&readings) {
        assert!(angle_error(p.angle_deg, r.angle_deg) <= 0.1, "{p:?} {r:?}");
        assert_eq!(p.distance_mm, r.distance_mm.min(16_383));
    }
    let starts: Vec<usize> = points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.starts_revolution)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(starts, [727]);
}

#[test]
fn decoder_resynchronises_after_lost_and_flipped_bytes() {
    let mut unit = RplidarUnit::new();
    let mut out = Output::new();
    unit.host_wrote(&[0xA5, cmd::SCAN], 0.0, &mut out);
    let readings = revolution(0, 200, |i| 1000 + i);
    for r in &readings {
        unit.push(r, &mut out);
    }
    let mut wire = out.bytes.clone();
    wire.remove(7 + 5 * 20 + 2); // a lost byte in node 20
    let (points, stats) = decode(&wire);
    assert!(
        stats.skipped_bytes >= 4 && stats.bad_checksum >= 1,
        "{stats:?}"
    );
    assert!(points.len() >= 190);
    // Whatever is decoded after the damage is a real reading again by the end.
    let last = points.last().unwrap();
    assert_eq!(last.distance_mm, 1199);

    // Capsules: a flipped bit fails the checksum, the next capsule is found.
    let mut unit = RplidarUnit::new();
    let mut out = Output::new();
    unit.host_wrote(&request(cmd::EXPRESS_SCAN, &[0; 5]), 0.0, &mut out);
    for r in &revolution(0, 320, |i| 500 + i) {
        unit.push(r, &mut out);
    }
    let mut wire = out.bytes.clone();
    wire[7 + 84 * 3 + 40] ^= 0x04;
    let (points, stats) = decode(&wire);
    assert_eq!(stats.packets, 1 + 9);
    assert!(stats.bad_checksum >= 1);
    assert_eq!(points.len(), 32 * 7);
}

proptest! {
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5EED_0A02),
        cases: 64,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_readings_survive_the_standard_scan(
        raw in prop::collection::vec((0.0f64..360.0, 0u32..20_000, any::<u8>(), any::<bool>()), 1..200)
    ) {
        let mut unit = RplidarUnit::new();
        let mut out = Output::new();
        unit.host_wrote(&[0xA5, cmd::SCAN], 0.0, &mut out);
        for (i, &(angle_deg, distance_mm, intensity, starts)) in raw.iter().enumerate() {
            unit.push(&UnitReading {
                t_s: i as f64 * 5e-4, rev: 0, index: i as u32, angle_deg, distance_mm,
                intensity, rev_hz: 5.5, starts_revolution: starts,
            }, &mut out);
        }
        let (points, stats) = decode(&out.bytes);
        prop_assert_eq!(points.len(), raw.len());
        prop_assert_eq!(stats.skipped_bytes, 0);
        for (p, &(angle, distance, intensity, starts)) in points.iter().zip(&raw) {
            prop_assert!(angle_error(p.angle_deg, angle) <= 1.0 / 128.0 + 1e-9);
            prop_assert_eq!(p.distance_mm, distance.min(16_383));
            prop_assert_eq!(p.intensity, u16::from(intensity >> 2));
            prop_assert_eq!(p.starts_revolution, starts);
        }
    }

    #[test]
    fn random_bytes_never_panic_and_chunks_change_nothing(
        bytes in prop::collection::vec(any::<u8>(), 0..2000), chunk in 1usize..100
    ) {
        let (points, stats) = decode(&bytes);
        let mut decoder = RplidarDecoder::new();
        let mut chunked = Vec::new();
        for piece in bytes.chunks(chunk) {
            decoder.feed(piece, &mut chunked);
        }
        prop_assert_eq!(&chunked, &points);
        prop_assert_eq!(decoder.stats(), stats);
        prop_assert_eq!(stats.bytes, bytes.len() as u64);
        prop_assert!(stats.bad_checksum <= stats.skipped_bytes);
        prop_assert!(stats.skipped_bytes + decoder.pending_len() as u64 <= stats.bytes);
        prop_assert!(decoder.pending_len() < CAPSULE_LEN);
        prop_assert!(points.iter().all(|p| (0.0..360.0).contains(&p.angle_deg)));
    }

    #[test]
    fn random_request_bytes_never_panic_and_replies_are_well_formed(
        bytes in prop::collection::vec(any::<u8>(), 0..600)
    ) {
        let mut unit = RplidarUnit::new();
        let mut out = Output::new();
        unit.host_wrote(&bytes, 0.0, &mut out);
        for (packet, _) in out.iter() {
            prop_assert_eq!(&packet[..2], &[0xA5, 0x5A]);
        }
    }
}
