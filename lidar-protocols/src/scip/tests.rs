//! Round trips unit → decoder, the command exchanges and damaged streams.

use super::*;
use crate::{HostDecoder, Output, Point, Unit, UnitReading};
use proptest::prelude::*;

const STEP_S: f64 = 0.1 / 1024.0;

fn reading(rev: u64, step: u16, distance_mm: u32) -> UnitReading {
    UnitReading {
        t_s: rev as f64 * 0.1 + f64::from(step) * STEP_S,
        rev,
        index: u32::from(step - FIRST_STEP),
        angle_deg: step_angle_deg(step),
        distance_mm,
        intensity: 0,
        rev_hz: 10.0,
        starts_revolution: step == FIRST_STEP,
    }
}

/// Pushes whole revolutions `revs` with distances `dist(step)`.
fn run(
    unit: &mut ScipUnit,
    revs: std::ops::Range<u64>,
    dist: impl Fn(u16) -> u32,
    out: &mut Output,
) {
    for rev in revs {
        for step in FIRST_STEP..=LAST_STEP {
            unit.push(&reading(rev, step, dist(step)), out);
        }
    }
}

fn decode_all(bytes: &[u8]) -> (Vec<Point>, ScipDecoder) {
    let mut decoder = ScipDecoder::new();
    let mut points = Vec::new();
    decoder.feed(bytes, &mut points);
    (points, decoder)
}

fn ask(unit: &mut ScipUnit, command: &[u8], now_s: f64) -> Vec<u8> {
    let mut out = Output::new();
    unit.host_wrote(command, now_s, &mut out);
    out.bytes
}

#[test]
fn info_replies_carry_the_urg_04lx_parameters() {
    let mut unit = ScipUnit::new();
    let pp = ask(&mut unit, b"PP\n", 0.0);
    assert_eq!(
        pp,
        b"PP\n00P\nMODL:URG-04LX(Hokuyo Automatic Co.,Ltd.);N\nDMIN:20;4\nDMAX:5600;_\n\
ARES:1024;\\\nAMIN:44;7\nAMAX:725;o\nAFRT:384;6\nSCAN:600;e\n\n"
    );
    let vv = ask(&mut unit, b"VV;x\n", 0.0);
    assert!(vv.starts_with(b"VV;x\n00P\nVEND:Hokuyo Automatic Co.,Ltd.;[\n"));
    assert!(
        vv.ends_with(b"PROT:SCIP 2.0;N\nSERI:H0000000;5\n\n"),
        "{vv:?}"
    );
    let ii = ask(&mut unit, b"II\n", 1.5);
    let ii = String::from_utf8(ii).unwrap();
    assert!(ii.contains("\nLASR:OFF;7\n"), "{ii}");
    assert!(ii.contains("\nTIME:0005DC;"), "{ii}"); // 1,500 ms
}

#[test]
fn laser_commands_answer_with_their_statuses() {
    let mut unit = ScipUnit::new();
    assert_eq!(ask(&mut unit, b"BM\n", 0.0), b"BM\n00P\n\n");
    assert_eq!(ask(&mut unit, b"BM\n", 0.0), b"BM\n02R\n\n");
    assert!(unit.laser_on());
    assert_eq!(ask(&mut unit, b"QT\r\n", 0.0), b"QT\n00P\n\n");
    assert!(!unit.laser_on());
    assert_eq!(ask(&mut unit, b"SCIP2.0\n", 0.0), b"SCIP2.0\n0Ee\n\n");
    assert_eq!(ask(&mut unit, b"%ST\n", 0.0), b"%ST\n0Ee\n\n");
    assert_eq!(ask(&mut unit, b"SS115200\n", 0.0), b"SS115200\n03S\n\n");
    assert_eq!(ask(&mut unit, b"SS019200\n", 0.0), b"SS019200\n00P\n\n");
    assert_eq!(ask(&mut unit, b"SS012345\n", 0.0), b"SS012345\n02R\n\n");
    assert_eq!(ask(&mut unit, b"CR05\n", 0.0), b"CR05\n00P\n\n");
    assert_eq!(ask(&mut unit, b"CR05\n", 0.0), b"CR05\n03S\n\n");
    assert_eq!(ask(&mut unit, b"CR11\n", 0.0), b"CR11\n02R\n\n");
    assert_eq!(ask(&mut unit, b"CR99\n", 0.0), b"CR99\n00P\n\n");
}

#[test]
fn time_adjust_mode_reports_the_clock_and_refuses_other_commands() {
    let mut unit = ScipUnit::new();
    assert_eq!(ask(&mut unit, b"TM1\n", 0.0), b"TM1\n04T\n\n");
    assert_eq!(ask(&mut unit, b"TM0\n", 0.0), b"TM0\n00P\n\n");
    assert_eq!(ask(&mut unit, b"TM0\n", 0.0), b"TM0\n02R\n\n");
    assert_eq!(ask(&mut unit, b"BM\n", 0.0), b"BM\n0Ee\n\n");
    let tm1 = ask(&mut unit, b"TM1\n", 16_000.0);
    assert_eq!(&tm1[..8], b"TM1\n00P\n");
    assert_eq!(decode(&tm1[8..12]), Some(16_000_000));
    assert_eq!(&tm1[12..], [checksum(&tm1[8..12]), b'\n', b'\n']);
    assert_eq!(ask(&mut unit, b"TM2\n", 0.0), b"TM2\n00P\n\n");
    assert_eq!(ask(&mut unit, b"TM2\n", 0.0), b"TM2\n03S\n\n");
    assert_eq!(ask(&mut unit, b"TM3\n", 0.0), b"TM3\n01Q\n\n");
    // RS sets the clock's zero.
    ask(&mut unit, b"RS\n", 10.0);
    ask(&mut unit, b"TM0\n", 10.0);
    let tm1 = ask(&mut unit, b"TM1\n", 10.25);
    assert_eq!(decode(&tm1[8..12]), Some(250));
}

#[test]
fn commands_survive_splits_and_garbage() {
    let mut unit = ScipUnit::new();
    let mut out = Output::new();
    for piece in [&b"\xff\x00B"[..], b"M", b"\n\xfe", b"Q", b"T\r", b"\n"] {
        unit.host_wrote(piece, 0.0, &mut out);
    }
    assert_eq!(out.bytes, b"BM\n00P\n\nQT\n00P\n\n");
    assert_eq!(out.packets.len(), 2);
    // An overlong line is dropped whole, and memory stays bounded.
    out.clear();
    unit.host_wrote(&[b'A'; 10_000], 0.0, &mut out);
    unit.host_wrote(b"\nBM\n", 0.0, &mut out);
    assert_eq!(out.bytes, b"BM\n00P\n\n");
}

#[test]
fn gd_answers_with_the_next_whole_scan() {
    let mut unit = ScipUnit::new();
    let mut out = Output::new();
    ask(&mut unit, b"BM\n", 0.0);
    run(&mut unit, 0..1, |s| 1000 + u32::from(s), &mut out);
    assert!(out.is_empty(), "no scan without a request");
    // Asked in the middle of revolution 1: revolution 2 answers.
    unit.push(&reading(1, 44, 1), &mut out);
    unit.host_wrote(b"GD0044072501;a\n", 0.11, &mut out);
    assert!(out.is_empty());
    run(
        &mut unit,
        2..4,
        |s| match s {
            100 => 0,
            200 => 10,
            s => 1000 + u32::from(s),
        },
        &mut out,
    );
    assert_eq!(out.packets.len(), 1);
    let span = &out.packets[0];
    assert_eq!(span.due_s, reading(2, LAST_STEP, 0).t_s);
    assert_eq!(span.sync_len, b"GD0044072501;a\n".len());
    let bytes = &out.bytes[span.range.clone()];
    assert!(bytes.starts_with(b"GD0044072501;a\n00P\n"));
    // The time stamp is the clock at step 0 of revolution 2: 200 ms.
    assert_eq!(decode(&bytes[19..23]), Some(200));
    let (points, decoder) = decode_all(&out.bytes);
    assert_eq!(points.len(), 682);
    assert_eq!(decoder.stats().packets, 1);
    for (point, step) in points.iter().zip(FIRST_STEP..) {
        let expected = if matches!(step, 100 | 200) {
            0
        } else {
            1000 + u32::from(step)
        };
        assert_eq!(point.distance_mm, expected, "step {step}");
        assert_eq!(point.angle_deg, step_angle_deg(step));
        assert_eq!(point.starts_revolution, step == FIRST_STEP);
    }
}

#[test]
fn gd_with_the_laser_off_and_bad_parameters_get_error_statuses() {
    let mut unit = ScipUnit::new();
    assert_eq!(
        ask(&mut unit, b"GD0044072501\n", 0.0),
        b"GD0044072501\n10Q\n\n"
    );
    ask(&mut unit, b"BM\n", 0.0);
    assert_eq!(
        ask(&mut unit, b"GD0044080001\n", 0.0),
        b"GD0044080001\n04T\n\n"
    );
    assert_eq!(
        ask(&mut unit, b"GD0500040001\n", 0.0),
        b"GD0500040001\n05U\n\n"
    );
    assert_eq!(
        ask(&mut unit, b"GD00440725\n", 0.0),
        b"GD00440725\n0C\x63\n\n"
    );
}

#[test]
fn gs_clusters_take_the_smallest_valid_distance_and_mark_blind_steps() {
    let mut unit = ScipUnit::new();
    let mut out = Output::new();
    ask(&mut unit, b"BM\n", 0.0);
    unit.host_wrote(b"GS0040005003\n", 0.0, &mut out);
    run(
        &mut unit,
        0..1,
        |s| match s {
            44 => 0,
            45 => 900,
            46 => 800,
            _ => 700,
        },
        &mut out,
    );
    let bytes = &out.bytes[out.packets[0].range.clone()];
    // Steps 40–42 blind (19), 43–45 → 900 (44 is no return), 46–48 → 700, 49–50 → 700.
    let data = &bytes[b"GS0040005003\n00P\n".len() + 6..];
    let values: Vec<u32> = data[..8].chunks(2).map(|c| decode(c).unwrap()).collect();
    assert_eq!(values, [NON_MEASURABLE_CODE, 900, 700, 700]);
}

#[test]
fn md_streams_counted_scans_then_turns_the_laser_off() {
    let mut unit = ScipUnit::new();
    let mut out = Output::new();
    unit.host_wrote(b"MD0384039001103\n", 0.0, &mut out);
    assert_eq!(out.bytes, b"MD0384039001103\n00P\n\n");
    assert!(unit.scanning() && unit.laser_on());
    run(&mut unit, 0..8, |_| 1500, &mut out);
    // Interval 1: revolutions 0, 2 and 4 sent, the remaining count falling to 00.
    let echoes: Vec<&[u8]> = out.iter().skip(1).map(|(b, _)| &b[..16]).collect();
    assert_eq!(
        echoes,
        [
            &b"MD0384039001102\n"[..],
            b"MD0384039001101\n",
            b"MD0384039001100\n"
        ]
    );
    let dues: Vec<f64> = out.packets.iter().skip(1).map(|p| p.due_s).collect();
    assert_eq!(dues, [0.0, 0.2, 0.4].map(|r| r + 390.0 * STEP_S));
    assert!(!unit.scanning() && !unit.laser_on());
    let (points, decoder) = decode_all(&out.bytes);
    assert_eq!(decoder.stats().packets, 4);
    assert_eq!(points.len(), 3 * 7);
    assert!(points.iter().all(|p| p.distance_mm == 1500));
}

#[test]
fn ms_streams_until_qt_with_two_character_values() {
    let mut unit = ScipUnit::new();
    let mut out = Output::new();
    unit.host_wrote(b"MS0044072501000\n", 0.0, &mut out);
    run(&mut unit, 0..3, |s| u32::from(s) * 6, &mut out);
    unit.host_wrote(b"QT\n", 0.3, &mut out);
    run(&mut unit, 3..5, |_| 1000, &mut out);
    assert_eq!(out.packets.len(), 5); // ack, 3 scans, QT
    let (points, decoder) = decode_all(&out.bytes);
    assert_eq!(decoder.stats().packets, 5);
    assert_eq!(points.len(), 3 * 682);
    for (point, step) in points.iter().zip((FIRST_STEP..=LAST_STEP).cycle()) {
        // 2-character fields carry at most 4,095 mm; beyond, no object.
        let d = u32::from(step) * 6;
        assert_eq!(point.distance_mm, if d > 4095 { 0 } else { d });
    }
}

#[test]
fn the_decoder_drops_damaged_replies_and_resynchronises() {
    let mut unit = ScipUnit::new();
    let mut out = Output::new();
    unit.host_wrote(b"MD0044072501000\n", 0.0, &mut out);
    run(&mut unit, 0..4, |_| 2000, &mut out);
    let mut bytes = out.bytes.clone();
    let second = out.packets[2].range.clone();
    bytes[second.start + 40] ^= 0x01; // a flipped bit in scan 2's data
    let third = out.packets[3].range.clone();
    bytes.drain(third.start + 100..third.start + 101); // a lost byte in scan 3
    let mut garbage = b"\xff\x00garbage\n".to_vec();
    garbage.extend_from_slice(&bytes);
    let (points, decoder) = decode_all(&garbage);
    let stats = decoder.stats();
    assert_eq!(points.len(), 2 * 682);
    assert_eq!(stats.packets, 3); // the ack and scans 1 and 4
    assert_eq!(stats.bad_checksum, 2);
    assert_eq!(stats.bytes, garbage.len() as u64);
    assert_eq!(decoder.pending_len(), 0);
}

#[test]
fn the_decoder_skips_overlong_lines() {
    let mut stream = vec![b'x'; 5000];
    stream.extend_from_slice(b"\n\nBM\n00P\n\n");
    let (points, decoder) = decode_all(&stream);
    assert!(points.is_empty());
    assert_eq!(decoder.stats().packets, 1);
    assert_eq!(decoder.stats().skipped_bytes, 5002);
}

fn any_distance() -> impl Strategy<Value = u32> {
    prop_oneof![Just(0u32), 20u32..=5600]
}

proptest! {
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5C1D_0001),
        failure_persistence: None,
        cases: 64,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_scans_survive_the_round_trip(
        distances in proptest::collection::vec(any_distance(), 682),
        two_char in any::<bool>(),
        chunk in 1usize..300,
    ) {
        let mut unit = ScipUnit::new();
        let mut out = Output::new();
        let command: &[u8] = if two_char { b"MS0044072501000\n" } else { b"MD0044072501000\n" };
        unit.host_wrote(command, 0.0, &mut out);
        for step in FIRST_STEP..=LAST_STEP {
            unit.push(&reading(0, step, distances[usize::from(step - FIRST_STEP)]), &mut out);
        }
        let mut decoder = ScipDecoder::new();
        let mut points = Vec::new();
        for piece in out.bytes.chunks(chunk) {
            decoder.feed(piece, &mut points);
        }
        prop_assert_eq!(points.len(), 682);
        for ((point, &d), step) in points.iter().zip(&distances).zip(FIRST_STEP..) {
            let expected = if two_char && d > 4095 { 0 } else { d };
            prop_assert_eq!(point.distance_mm, expected);
            prop_assert!((point.angle_deg - reading(0, step, 0).angle_deg).abs() < 1e-9);
            prop_assert_eq!(point.starts_revolution, step == FIRST_STEP);
        }
        prop_assert_eq!(decoder.stats().bad_checksum, 0);
    }

    #[test]
    fn random_bytes_never_panic_and_chunking_changes_nothing(
        bytes in proptest::collection::vec(
            prop_oneof![any::<u8>(), Just(b'\n'), Just(b'0'), Just(b'M'), Just(b'D'), Just(b';')],
            0..3000),
        chunk in 1usize..64,
    ) {
        let (whole, decoder) = decode_all(&bytes);
        let stats = decoder.stats();
        prop_assert_eq!(stats.bytes, bytes.len() as u64);
        prop_assert!(stats.skipped_bytes + decoder.pending_len() as u64 <= stats.bytes);
        prop_assert!(decoder.pending_len() <= 4096 + 128);
        let mut chunked = ScipDecoder::new();
        let mut points = Vec::new();
        for piece in bytes.chunks(chunk) {
            chunked.feed(piece, &mut points);
        }
        prop_assert_eq!(points, whole);
        prop_assert_eq!(chunked.stats(), stats);
        // And the unit takes the same bytes as commands without panicking.
        let mut unit = ScipUnit::new();
        let mut out = Output::new();
        unit.host_wrote(&bytes, 0.0, &mut out);
        prop_assert!(out.packets.len() <= bytes.len());
        let mut replies = ScipDecoder::new();
        replies.feed(&out.bytes, &mut Vec::new());
        prop_assert_eq!(replies.stats().bad_checksum, 0);
        prop_assert_eq!(replies.stats().packets, out.packets.len() as u64);
    }
}
