//! Every lidar model on the wire: `hilsim serve` streams each checked-in `lidar-<model>`
//! scenario in its unit's protocol (started by the unit's own command where it has one), the
//! host's decoder reads back the recording's readings one for one, `decode --model` reads a
//! capture, and `run --via serial`, which reads only the XV-11's wire, refuses the others.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use hilsim_lidar_protocols::{Direction, LidarModel, Point};
use hilsim_recording::{LidarSample, Recording};

use super::common::*;

/// What a host sends to start each unit's readings (nothing for a unit that streams at
/// power-on): the RPLIDAR's SCAN request, the X4's scan command, SCIP's continuous distances
/// over every step (`MD`, 44..725, no grouping, no skipping, until told to stop).
fn start_command(model: LidarModel) -> &'static [u8] {
    match model {
        LidarModel::RplidarA1 => &[0xA5, 0x20],
        LidarModel::YdlidarX4 => &[0xA5, 0x60],
        LidarModel::Urg04lx => b"MD0044072500000\n",
        _ => b"",
    }
}

/// Serves `scenario` fast to one client, starts the unit, and returns the bytes it sent
/// until `wanted` readings were decoded (or 20 s passed).
fn capture(scenario: &str, model: LidarModel, wanted: usize) -> Vec<u8> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hilsim"))
        .args(["serve", scenario, "--fast", "--wait-for-client"])
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    stdout.read_line(&mut first).unwrap();
    let path = first.strip_prefix("serial: ").unwrap().trim().to_string();
    let mut port = serialport::new(&path, model.spec().baud)
        .timeout(Duration::from_millis(200))
        .open()
        .unwrap();
    port.write_all(start_command(model)).unwrap();
    let mut decoder = hilsim_lidar_protocols::decoder_for(model).unwrap();
    let (mut bytes, mut points, mut chunk) = (Vec::new(), Vec::new(), [0_u8; 4096]);
    let deadline = Instant::now() + Duration::from_secs(20);
    while points.len() < wanted && Instant::now() < deadline {
        match port.read(&mut chunk) {
            Ok(n) => {
                bytes.extend_from_slice(&chunk[..n]);
                decoder.feed(&chunk[..n], &mut points);
            }
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => panic!("{model}: {e} after {} bytes", bytes.len()),
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    bytes
}

fn recorded(scenario: &str) -> Vec<LidarSample> {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("rec");
    let o = hilsim(
        &root(),
        &["record", scenario, "--out", out.to_str().unwrap()],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    Recording::read_dir(&out).unwrap().lidar.unwrap()
}

/// A decoded point's angle in hilsim's frame (counter-clockwise).
fn ccw(model: LidarModel, point: &Point) -> f64 {
    match model.spec().direction {
        Direction::CounterClockwise => point.angle_deg,
        Direction::Clockwise => (360.0 - point.angle_deg).rem_euclid(360.0),
    }
}

fn same(model: LidarModel, point: &Point, row: &LidarSample) -> bool {
    let d = (ccw(model, point) - row.angle_deg).rem_euclid(360.0);
    let angle_ok = d.min(360.0 - d) <= 0.2;
    let distance_ok = if row.invalid {
        point.distance_mm == 0
    } else {
        (f64::from(point.distance_mm) - row.range_m * 1000.0).abs() <= 1.0
    };
    angle_ok && distance_ok
}

/// Every model's stream, read by its decoder from the moment the unit starts, is the
/// recording's readings in order, one for one: angles within 0.2°, distances to the millimetre
/// (the fields' resolution at worst), a no-return where the recording has an invalid reading.
#[test]
fn every_model_streams_the_recordings_readings_one_for_one() {
    for model in LidarModel::ALL.into_iter().skip(1) {
        let scenario = format!("scenarios/lidar-{model}.toml");
        let rows = recorded(&scenario);
        let bytes = capture(&scenario, model, 3_000);
        let mut decoder = hilsim_lidar_protocols::decoder_for(model).unwrap();
        let mut points = Vec::new();
        decoder.feed(&bytes, &mut points);
        assert!(points.len() >= 3_000, "{model}: {} points", points.len());
        assert_eq!(decoder.stats().bad_checksum, 0, "{model}");
        // The unit starts on a command: the stream joins the recording where the first few
        // points match.
        let offset = (0..rows.len().min(5_000))
            .find(|&k| (0..8).all(|i| same(model, &points[i], &rows[k + i])))
            .unwrap_or_else(|| panic!("{model}: the first points match no run of rows"));
        let mismatched = points
            .iter()
            .zip(&rows[offset..])
            .filter(|(p, r)| !same(model, p, r))
            .count();
        assert_eq!(mismatched, 0, "{model}: of {} points", points.len());
        let starts = points.iter().filter(|p| p.starts_revolution).count();
        assert!(starts >= 3, "{model}: {starts} revolutions marked");
    }
}

/// `decode --model` reads a unit's capture: its counts as JSON, its readings as CSV.
#[test]
fn decode_reads_a_captured_ld06_stream() {
    let tmp = tempfile::tempdir().unwrap();
    let bytes = capture("scenarios/lidar-ld06.toml", LidarModel::Ld06, 2_000);
    std::fs::write(tmp.path().join("ld06.bin"), &bytes).unwrap();
    let o = hilsim(
        tmp.path(),
        &[
            "decode",
            "ld06.bin",
            "--model",
            "ld06",
            "--json",
            "--csv",
            "points.csv",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert_eq!(json["model"], "ld06");
    assert_eq!(json["bytes"], bytes.len());
    assert_eq!(json["bad_checksum"], 0);
    let readings = json["readings"].as_u64().unwrap();
    // 12 readings a 47-byte packet; the capture may end inside one.
    assert_eq!(readings, 12 * (bytes.len() as u64 / 47));
    // The LD06 reports its speed: 10 Hz, quantised to its 1°/s field.
    assert!(
        (json["rev_hz_median"].as_f64().unwrap() - 10.0).abs() < 0.05,
        "{json}"
    );
    let csv = std::fs::read_to_string(tmp.path().join("points.csv")).unwrap();
    assert!(csv.starts_with("rev,angle_deg,distance_mm,range_m,intensity,rev_hz\n"));
    assert_eq!(csv.lines().count() as u64, readings + 1);
    let unknown = hilsim(tmp.path(), &["decode", "ld06.bin", "--model", "lds-03"]);
    assert_eq!(unknown.status.code(), Some(2), "{}", stderr(&unknown));
}

/// A scenario's model is checked as it is read: an unknown unit, a rate the unit cannot turn
/// at, a model beside a log's schedule; each a one-line error naming the file and line.
#[test]
fn a_model_the_unit_cannot_be_is_refused_naming_the_line() {
    let tmp = tempfile::tempdir().unwrap();
    let base = std::fs::read_to_string(repo_file("scenarios/lidar-ld06.toml")).unwrap();
    for (change, expected) in [
        (
            ("model = \"ld06\"", "model = \"lds-03\""),
            "unknown variant",
        ),
        (
            ("model = \"ld06\"", "model = \"ld06\"\nrpm = 900.0"),
            "turns at 300–780 rpm",
        ),
        (
            (
                "model = \"ld06\"",
                "model = \"ld06\"\nschedule = \"scans.csv\"",
            ),
            "set one",
        ),
    ] {
        std::fs::write(tmp.path().join("s.toml"), base.replace(change.0, change.1)).unwrap();
        std::fs::write(
            tmp.path().join("scans.csv"),
            "t_s,rev,beams,first_deg,step_deg,beam_period_s\n0,0,10,0,1,0.001\n",
        )
        .unwrap();
        let o = hilsim(tmp.path(), &["record", "s.toml", "--out", "rec"]);
        let err = assert_bad_input(&o);
        assert!(err.contains("s.toml:") && err.contains(expected), "{err}");
    }
}

/// `run --via serial` reads the XV-11's wire only: another unit is refused before anything
/// runs, saying what to use instead.
#[test]
fn run_via_serial_refuses_other_units() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/lidar-rplidar-a1.toml");
    let o = hilsim(
        tmp.path(),
        &["run", scenario.to_str().unwrap(), "--via", "serial"],
    );
    let err = assert_bad_input(&o);
    assert!(
        err.contains("rplidar-a1") && err.contains("hilsim serve"),
        "{err}"
    );
}
