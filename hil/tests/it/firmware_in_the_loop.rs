//! Firmware in the loop: a client on the two ptys (this test, standing in for a
//! firmware) drives the simulated robot with `SetMotor` and reads its encoders, sonar and
//! lidar through the command port, in real time, while the lidar streams on the other port.

use std::io::{ErrorKind, Read};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::thread;
use std::time::{Duration, Instant};

use hilsim_hil::hil_run::{run, Ending, HilConfig, HilPorts, HilReport, HilWorld};
use hilsim_lidar_emulator::neato_packet::{Decoder, DecoderStats};
use hilsim_sim::Scenario;

const SCENARIO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../scenarios/hil-approach.toml"
);

/// Sends one request and returns the reply up to (without) its Ctrl-Z.
fn request(port: &mut dyn serialport::SerialPort, line: &str) -> String {
    port.write_all(format!("{line}\r\n").as_bytes()).unwrap();
    let mut reply = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(2);
    let mut buf = [0u8; 4096];
    while reply.last() != Some(&0x1A) {
        assert!(
            Instant::now() < deadline,
            "no complete reply to {line}: {reply:?}"
        );
        match port.read(&mut buf) {
            Ok(n) => reply.extend_from_slice(&buf[..n]),
            Err(e) if e.kind() == ErrorKind::TimedOut => {}
            Err(e) => panic!("{e}"),
        }
    }
    reply.pop();
    let text = String::from_utf8(reply).unwrap();
    let echo = format!("{line}\r\n");
    assert!(
        text.starts_with(&echo),
        "the reply echoes the request: {text:?}"
    );
    text[echo.len()..].to_string()
}

/// The value of `name` in a `Name,Value` reply.
fn value(reply: &str, name: &str) -> i64 {
    reply
        .lines()
        .find_map(|l| l.strip_prefix(name)?.strip_prefix(',')?.trim().parse().ok())
        .unwrap_or_else(|| panic!("no {name} in {reply:?}"))
}

#[test]
fn a_client_on_the_ports_drives_the_robot_and_reads_its_sensors_in_real_time() {
    let scenario = Scenario::load_with_duration(SCENARIO.as_ref(), Some(3.0)).unwrap();
    let world = HilWorld::new(&scenario, 5).unwrap();
    let ports = HilPorts::open().unwrap();
    let (lidar_path, robot_path) = (
        ports.lidar_path().to_string(),
        ports.robot_path().to_string(),
    );
    let stop = Arc::new(AtomicBool::new(false));
    let harness = {
        let stop = Arc::clone(&stop);
        thread::spawn(move || {
            run(
                world,
                ports,
                None,
                &HilConfig::new(Duration::from_secs(3)),
                &stop,
            )
        })
    };
    let lidar = thread::spawn(move || read_lidar_port(&lidar_path));
    let mut robot = serialport::new(&robot_path, 115_200)
        .timeout(Duration::from_millis(100))
        .open()
        .unwrap();
    let robot = robot.as_mut();

    converse(robot);

    let report = harness.join().unwrap().unwrap();
    let decoded = lidar.join().unwrap();
    check_report(&report, &decoded);
}

/// The lidar port, read as a driver would, until the harness closes it.
fn read_lidar_port(path: &str) -> DecoderStats {
    let mut port = serialport::new(path, 115_200)
        .timeout(Duration::from_millis(200))
        .open()
        .unwrap();
    let mut decoder = Decoder::new();
    let mut buf = [0u8; 4096];
    loop {
        match port.read(&mut buf) {
            Ok(n) => decoder.feed(&buf[..n]).for_each(drop),
            Err(e) if e.kind() == ErrorKind::TimedOut => {}
            Err(_) => return decoder.finish(),
        }
    }
}

/// The client's conversation on the robot port: it drives 300 mm with `SetMotor` and reads
/// the encoders, the sonar and the lidar.
fn converse(robot: &mut dyn serialport::SerialPort) {
    // 2.5 m from the board: the sonar reads 0.021 + 1.028 d (± 8 mm noise, 15° cone).
    let sonar_before = value(&request(robot, "GetSonar"), "Sonar_DistInMM");
    assert!((2540..2640).contains(&sonar_before), "{sonar_before}");
    assert_eq!(
        request(robot, "SetMotor 300 300 300"),
        "Error: SetMotor needs TestMode On\r\n"
    );
    assert_eq!(request(robot, "TestMode On"), "");
    let sent = Instant::now();
    assert_eq!(
        request(robot, "setmotor lwheeldist 300 rwheeldist 300 speed 300"),
        ""
    );
    // 300 mm at 300 mm/s: one second, then the wheels stop by themselves.
    thread::sleep(Duration::from_millis(1300).saturating_sub(sent.elapsed()));
    let motors = request(robot, "GetMotors");
    let (left, right) = (
        value(&motors, "LeftWheel_PositionInMM"),
        value(&motors, "RightWheel_PositionInMM"),
    );
    // The encoders over-report by the scenario's 2.7 % slip, with 4 mm of noise (4 sd).
    for wheel in [left, right] {
        assert!((292..=324).contains(&wheel), "{motors}");
    }
    let sonar_after = value(&request(robot, "GetSonar"), "Sonar_DistInMM");
    let closer = sonar_before - sonar_after;
    assert!(
        (270..=350).contains(&closer),
        "{sonar_before} -> {sonar_after}"
    );
    let scan = request(robot, "GetLDSScan");
    let lines: Vec<&str> = scan.lines().collect();
    assert_eq!(lines.len(), 1 + 360 + 1, "{scan}");
    assert_eq!(lines[0], "AngleInDegrees,DistInMM,Intensity,ErrorCodeHEX");
    assert!(
        lines[361].starts_with("ROTATION_SPEED,5.0"),
        "{}",
        lines[361]
    );
    // Straight ahead the board is 2.2 m away; the range model reads 2.279 m there.
    let ahead: i64 = lines[1].split(',').nth(1).unwrap().parse().unwrap();
    assert!((2180..=2380).contains(&ahead), "{}", lines[1]);
    assert!(request(robot, "Dance").starts_with("Unknown Cmd: Dance"));
}

/// What the run did: the robot moved as commanded, every request was counted, and the lidar
/// client got the whole stream.
fn check_report(report: &HilReport, decoded: &DecoderStats) {
    assert_eq!(report.ending, Ending::TimeUp);
    assert!(report.firmware.is_none());
    let truth = report.run.recording.truth.as_ref().unwrap();
    let last = truth.last().unwrap();
    assert!((last.x_m - 2.2).abs() < 0.002, "{last:?}");
    // commands.csv: the motion controller's wheel commands as issued.
    let commands = &report.run.recording.commands;
    let moving: Vec<_> = commands.iter().filter(|c| c.left_mps != 0.0).collect();
    assert_eq!(moving.len(), 1, "{commands:?}");
    assert_eq!(moving[0].left_mps, 0.3);
    assert_eq!(commands.last().unwrap().left_mps, 0.0);
    let c = &report.commands;
    assert_eq!(
        (c.requests, c.set_motor, c.get_motors, c.get_sonar),
        (8, 1, 1, 2)
    );
    assert_eq!((c.get_lds_scan, c.test_mode, c.errors), (1, 1, 2));
    // The lidar client got every packet, whole and in order.
    assert_eq!(report.stream.revolutions_dropped, 0);
    assert!(report.stream.revolutions_sent >= 14, "{:?}", report.stream);
    assert_eq!((decoded.index_gaps, decoded.bad_checksum), (0, 0));
    // All but what was in flight when the port closed (a packet or two).
    let written = report.stream.bytes_written / 22;
    assert!(decoded.packets + 2 >= written, "{decoded:?} of {written}");
    assert!(report.lidar_bytes_read.unwrap() + 22 >= report.stream.bytes_written);
    // The recording holds the whole revolutions taken.
    let lidar_rows = report.run.recording.lidar.as_ref().unwrap();
    assert_eq!(lidar_rows.len() % 360, 0);
    assert!(lidar_rows.len() >= 14 * 360);
}
