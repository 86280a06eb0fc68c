//! `hilsim serve` as clients see it: a strict driver that syncs on `FA A0` and reads whole
//! revolutions at fixed offsets, a client that disconnects and comes back, and `decode` of the
//! real XV-11 capture.

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use hilsim_recording::Recording;

use super::common::*;

/// A short straight run (3 s of lidar) so that realtime tests stay short.
const SHORT: &str = r#"
name = "short"
seed = 4
duration_s = 3.0
[world]
walls = [{ from = [2.0, -2.0], to = [2.0, 2.0] }, { from = [-2.0, -2.0], to = [-2.0, 2.0] }]
cylinders = [{ center = [0.8, 0.7], radius = 0.1 }]
[robot]
start = { x = 0.0, y = 0.0 }
wheel_base_m = 0.23
[[drive]]
speed_mps = 0.2
distance_m = 0.5
[sensors.lidar]
bias = [0.0525, 0.8838, 0.0584]
noise = [0.0, 0.0, 0.004]
"#;

struct Server {
    child: Child,
    port: String,
    /// Kept open: a closed pipe would fail the server's final summary.
    stdout: BufReader<std::process::ChildStdout>,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn serve(dir: &std::path::Path, args: &[&str]) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hilsim"))
        .arg("serve")
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    stdout.read_line(&mut first).unwrap();
    let port = first
        .strip_prefix("serial: ")
        .unwrap_or_else(|| panic!("first line: {first:?}"))
        .trim()
        .to_string();
    Server {
        child,
        port,
        stdout,
    }
}

fn open(port: &str) -> Box<dyn serialport::SerialPort> {
    serialport::new(port, 115_200)
        .timeout(Duration::from_millis(500))
        .open()
        .unwrap()
}

fn checksum_ok(p: &[u8]) -> bool {
    let mut acc: u32 = 0;
    for w in p[..20].chunks(2) {
        acc = (acc << 1) + u32::from(u16::from_le_bytes([w[0], w[1]]));
    }
    let chk = ((acc & 0x7FFF) + (acc >> 15)) & 0x7FFF;
    chk == u32::from(u16::from_le_bytes([p[20], p[21]]))
}

/// The ROS driver's way: find `FA A0`, then take 1,980 bytes at a time and read every field at
/// its fixed offset, without resyncing. Returns each revolution's 360 distances (0 if flagged).
fn strict_revolutions(port: &mut dyn serialport::SerialPort, count: usize) -> Vec<Vec<u16>> {
    let mut byte = [0u8; 1];
    let mut prev = 0u8;
    loop {
        port.read_exact(&mut byte).unwrap();
        if prev == 0xFA && byte[0] == 0xA0 {
            break;
        }
        prev = byte[0];
    }
    let mut block = vec![0u8; 1980];
    block[0] = 0xFA;
    block[1] = 0xA0;
    port.read_exact(&mut block[2..]).unwrap();
    let mut revs = Vec::new();
    loop {
        let mut distances = Vec::with_capacity(360);
        for (k, packet) in block.chunks_exact(22).enumerate() {
            assert_eq!(packet[0], 0xFA, "packet {k} misaligned");
            assert_eq!(usize::from(packet[1]), 0xA0 + k, "packet {k} index");
            assert!(checksum_ok(packet), "packet {k} checksum");
            let rpm = f64::from(u16::from_le_bytes([packet[2], packet[3]])) / 64.0;
            assert!((180.0..=349.0).contains(&rpm), "rpm {rpm}");
            for r in packet[4..20].chunks_exact(4) {
                let flagged = r[1] & 0xC0 != 0;
                distances.push(if flagged {
                    0
                } else {
                    u16::from(r[0]) | (u16::from(r[1] & 0x3F) << 8)
                });
            }
        }
        revs.push(distances);
        if revs.len() == count {
            return revs;
        }
        port.read_exact(&mut block).unwrap();
    }
}

fn recorded_revolutions(dir: &std::path::Path, seed: &str) -> Vec<Vec<u16>> {
    let o = hilsim(
        dir,
        &["record", "short.toml", "--out", "rec", "--seed", seed],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let rec = Recording::read_dir(&dir.join("rec")).unwrap();
    rec.lidar
        .unwrap()
        .chunks(360)
        .map(|rev| {
            rev.iter()
                .map(|r| {
                    if r.invalid || r.warning {
                        0
                    } else {
                        (r.range_m * 1000.0).round() as u16
                    }
                })
                .collect()
        })
        .collect()
}

#[test]
fn a_strict_fixed_offset_client_reads_whole_revolutions_equal_to_the_recording() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("short.toml"), SHORT).unwrap();
    let expected = recorded_revolutions(tmp.path(), "9");
    let server = serve(tmp.path(), &["short.toml", "--realtime", "--seed", "9"]);
    let mut port = open(&server.port);
    let received = strict_revolutions(port.as_mut(), 6);
    let first = expected
        .iter()
        .position(|r| *r == received[0])
        .expect("the first revolution is one the recording has");
    // A connected realtime client loses nothing: the next five follow in order.
    assert_eq!(received, expected[first..first + 6].to_vec());
}

#[test]
fn a_client_that_disconnects_and_comes_back_gets_valid_fresh_packets() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("short.toml"), SHORT).unwrap();
    let expected = recorded_revolutions(tmp.path(), "2");
    let mut server = serve(tmp.path(), &["short.toml", "--realtime", "--seed", "2"]);
    let first = {
        let mut port = open(&server.port);
        strict_revolutions(port.as_mut(), 1)
    };
    // Away for 1.5 s: 7.5 revolutions pass while nobody reads.
    std::thread::sleep(Duration::from_millis(1500));
    let mut port = open(&server.port);
    let again = strict_revolutions(port.as_mut(), 2);
    let at = |rev: &Vec<u16>| {
        expected
            .iter()
            .position(|r| r == rev)
            .expect("a recorded revolution")
    };
    let (a, b, c) = (at(&first[0]), at(&again[0]), at(&again[1]));
    assert!(b > a && c == b + 1, "revolutions {a}, then {b}, {c}");
    // The backlog is kept under one revolution at each revolution's start, so a returning
    // client reads at most two revolutions of older data (the backlog plus the one being
    // written): live is ≥ a + 7 when it returns, so b ≥ a + 5; a + 4 leaves one revolution of
    // margin for a loaded machine.
    assert!(b >= a + 4, "stale data: {a} then {b}");
    // The server neither crashed nor blocked: it finishes the 3 s scenario by itself.
    let deadline = Instant::now() + Duration::from_secs(10);
    while server.child.try_wait().unwrap().is_none() {
        assert!(Instant::now() < deadline, "serve did not finish");
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(server.child.try_wait().unwrap().unwrap().success());
}

#[test]
fn serve_without_a_client_finishes_and_counts_what_nobody_read() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("short.toml"), SHORT).unwrap();
    let out = hilsim(tmp.path(), &["serve", "short.toml", "--fast"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.starts_with("serial: /dev/pts/"), "{text}");
    // 3 s = 15 revolutions, each either sent or counted as dropped (never blocked on).
    assert!(text.contains("revolutions sent"), "{text}");
}

#[test]
fn serve_to_an_existing_device_writes_the_stream_there() {
    // Another program's pty stands in for a USB adapter.
    let (mut master, slave) = serialport::TTYPort::pair().unwrap();
    let path = serialport::SerialPort::name(&slave).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("short.toml"), SHORT).unwrap();
    let server = serve(tmp.path(), &["short.toml", "--fast", "--port", &path]);
    assert_eq!(server.port, path);
    serialport::SerialPort::set_timeout(&mut master, Duration::from_secs(2)).unwrap();
    let mut bytes = vec![0u8; 4000];
    master.read_exact(&mut bytes).unwrap();
    let mut decoder = hilsim_lidar_emulator::neato_packet::Decoder::new();
    assert!(decoder.feed(&bytes).count() >= 150);
    drop(slave);
}

#[test]
fn decode_counts_the_real_capture_and_writes_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let capture = root().join("tests/data/captures/xv11-hand-in-box.bin");
    let capture = capture.to_str().unwrap();
    let out = hilsim(
        tmp.path(),
        &["decode", capture, "--json", "--csv", "readings.csv"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    // Cross-checked against an independent naive scan in lidar-emulator's capture test.
    assert_eq!(json["bytes"], 252_146);
    assert_eq!(json["packets"], 11_451);
    assert_eq!(json["bad_checksum"], 1);
    assert_eq!(json["readings"], 45_804);
    assert_eq!(json["invalid"], 2_799);
    assert_eq!(json["strength_warning"], 130);
    let csv = std::fs::read_to_string(tmp.path().join("readings.csv")).unwrap();
    assert_eq!(csv.lines().count(), 45_804 + 1);
    let bad = hilsim(tmp.path(), &["decode", "nothing.bin", "--json"]);
    let err = assert_bad_input(&bad);
    assert!(err.contains("nothing.bin"), "{err}");
}

/// `--fast --wait-for-client` streams nothing until the client opens the port, and a
/// client that reads, however slowly (here 2 KB every 20 ms, far behind the simulation), loses
/// no revolution: it gets every one of the run's, equal to the recording's.
#[test]
fn a_late_slow_client_of_a_fast_stream_gets_every_revolution() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("short.toml"), SHORT).unwrap();
    let expected = recorded_revolutions(tmp.path(), "4");
    let mut server = serve(tmp.path(), &["short.toml", "--fast", "--wait-for-client"]);
    // Late: the run (3 s of lidar, a few milliseconds of work) would be over long before.
    std::thread::sleep(Duration::from_millis(300));
    let mut port = open(&server.port);
    let mut bytes = Vec::new();
    let mut chunk = [0u8; 2048];
    let deadline = Instant::now() + Duration::from_secs(20);
    while bytes.len() < expected.len() * 1980 && Instant::now() < deadline {
        match port.read(&mut chunk) {
            Ok(n) => bytes.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => {
                let mut rest = String::new();
                let _ = server.stdout.read_to_string(&mut rest);
                panic!("{e} after {} bytes; serve said: {rest}", bytes.len());
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let mut decoder = hilsim_lidar_emulator::neato_packet::Decoder::new();
    let packets: Vec<_> = decoder.feed(&bytes).collect();
    assert_eq!(packets.len(), expected.len() * 90, "{} bytes", bytes.len());
    let got: Vec<Vec<u16>> = packets
        .chunks(90)
        .map(|rev| {
            rev.iter()
                .flat_map(|p| {
                    p.readings.iter().map(|r| {
                        if r.invalid || r.strength_warning {
                            0
                        } else {
                            r.distance_mm
                        }
                    })
                })
                .collect()
        })
        .collect();
    assert_eq!(got, expected);
    let status = server.child.wait().unwrap();
    assert!(status.success());
}

/// A client of a fast stream that stops reading for a second loses whole
/// revolutions, and the summary counts them: every revolution is either sent or dropped.
#[test]
fn what_a_stalled_client_loses_is_counted() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("short.toml"), SHORT).unwrap();
    let mut server = serve(tmp.path(), &["short.toml", "--fast", "--wait-for-client"]);
    let mut port = open(&server.port);
    let mut chunk = [0u8; 1980];
    port.read_exact(&mut chunk).unwrap();
    // Stalled: the stream drops what it cannot deliver and ends without waiting.
    let status = server.child.wait().unwrap();
    assert!(status.success());
    drop(port);
    let mut text = String::new();
    server.stdout.read_to_string(&mut text).unwrap();
    let count = |key: &str| -> u64 {
        let (before, _) = text
            .split_once(key)
            .unwrap_or_else(|| panic!("{key}: {text}"));
        before.rsplit(' ').next().unwrap().parse().unwrap()
    };
    let (sent, dropped) = (count(" revolutions sent"), count(" dropped"));
    assert!(dropped > 0, "{text}");
    assert_eq!(sent + dropped, 15, "{text}");
}

/// A scenario's `[link]` faults reach a client of `serve`, seeded: the same run gives
/// the same bytes. The motor spins up from 50 rpm (the rpm field follows), packets fail their
/// checksum at the rate asked (5 %: 0.05 × ~1,100 packets ≈ 55, binomial sd 7) and the summary
/// counts them as the decoder does.
#[test]
fn link_faults_reach_the_client_and_are_counted() {
    let tmp = tempfile::tempdir().unwrap();
    let faulty = format!("{SHORT}\n[link]\nspin_up_s = 1.0\ncorrupt_packet_rate = 0.05\n");
    std::fs::write(tmp.path().join("faulty.toml"), faulty).unwrap();
    let capture = |name: &str| -> (Vec<u8>, String) {
        let mut server = serve(tmp.path(), &["faulty.toml", "--fast", "--wait-for-client"]);
        let mut port = open(&server.port);
        let mut bytes = Vec::new();
        let mut chunk = [0u8; 4096];
        loop {
            match port.read(&mut chunk) {
                Ok(n) => bytes.extend_from_slice(&chunk[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                // The server closed the port: everything has been read.
                Err(_) => break,
            }
        }
        assert!(server.child.wait().unwrap().success());
        let mut text = String::new();
        server.stdout.read_to_string(&mut text).unwrap();
        std::fs::write(tmp.path().join(name), &bytes).unwrap();
        (bytes, text)
    };
    let (_, text) = capture("a.bin");
    let faults_line = |text: &str| {
        text.lines()
            .find(|l| l.starts_with("link faults: "))
            .unwrap_or_else(|| panic!("{text}"))
            .to_string()
    };
    // The faults are drawn per packet from the run's seed: the same every run (what reaches a
    // client may differ only if it stalls, which a loaded machine can make it do).
    assert_eq!(faults_line(&capture("b.bin").1), faults_line(&text));
    let decoded = hilsim(tmp.path(), &["decode", "a.bin", "--json"]);
    let counts: serde_json::Value = serde_json::from_str(&stdout(&decoded)).unwrap();
    let bad = counts["bad_checksum"].as_u64().unwrap();
    let corrupted: u64 = faults_line(&text)
        .strip_prefix("link faults: ")
        .and_then(|l| l.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert!((25..=90).contains(&corrupted), "{text}");
    // Every bad checksum the client saw is a corruption the summary counted (a loaded machine
    // may keep a few packets from the client: never more bad ones than corrupted).
    assert!(bad > 0 && bad <= corrupted, "{counts} {text}");
    let rpm_min = counts["rpm_min"].as_f64().unwrap();
    assert!((50.0..60.0).contains(&rpm_min), "{counts}");
}

/// `--port` given something that is not a terminal says what it is instead.
#[test]
fn serve_to_something_that_is_not_a_terminal_says_what_it_is() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("short.toml"), SHORT).unwrap();
    std::fs::write(tmp.path().join("regular"), "").unwrap();
    std::fs::create_dir(tmp.path().join("dir")).unwrap();
    for (port, what) in [
        ("regular", "a regular file"),
        ("dir", "a directory"),
        ("/dev/null", "a character device that is not a terminal"),
    ] {
        let err = assert_bad_input(&hilsim(
            tmp.path(),
            &["serve", "short.toml", "--fast", "--port", port],
        ));
        assert_eq!(
            err.trim_end(),
            format!("hilsim: {port}: not a serial device or pseudo-terminal ({what})")
        );
    }
}

/// `[link] rpm_wobble` at or above the lidar's rpm is refused: it used to stop the stream's
/// clock and `serve --fast` never ended.
#[test]
fn serve_refuses_a_link_wobble_as_large_as_the_rpm() {
    let tmp = tempfile::tempdir().unwrap();
    let wobbly = format!("{SHORT}[link]\nrpm_wobble = 20000\n");
    std::fs::write(tmp.path().join("wobbly.toml"), &wobbly).unwrap();
    let line = wobbly.lines().count();
    let err = assert_bad_input(&hilsim(tmp.path(), &["serve", "wobbly.toml", "--fast"]));
    assert!(
        err.starts_with(&format!("hilsim: wobbly.toml:{line}: link.rpm_wobble: ")),
        "{err}"
    );
    assert!(err.contains("smaller than the rpm"), "{err}");
}

/// Ctrl-C ends a stream that would otherwise run on, and `serve` still says what it sent, marks
/// the run interrupted and exits 0.
#[test]
fn ctrl_c_ends_serve_with_its_summary() {
    let tmp = tempfile::tempdir().unwrap();
    let long = SHORT.replace("duration_s = 3.0", "duration_s = 600.0");
    std::fs::write(tmp.path().join("long.toml"), long).unwrap();
    let mut server = serve(tmp.path(), &["long.toml", "--realtime"]);
    std::thread::sleep(Duration::from_millis(700));
    let killed = Command::new("kill")
        .args(["-INT", &server.child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = server.child.wait().unwrap();
    let mut rest = String::new();
    server.stdout.read_to_string(&mut rest).unwrap();
    assert_eq!(status.code(), Some(0), "{rest}");
    assert!(
        rest.contains("revolutions sent") && rest.trim_end().ends_with("(interrupted)"),
        "{rest}"
    );
}
