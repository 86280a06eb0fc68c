use super::*;
use hilsim_lidar_emulator::neato_packet::Reading;

#[derive(Default)]
struct FakeRobot {
    motions: Vec<MotorRequest>,
    stops: usize,
    wheels: Option<[i64; 2]>,
    rpm: Option<f64>,
    scan: Option<RevolutionFrame>,
    lidar: bool,
    sonar: Option<Result<Option<u32>, Unavailable>>,
}

impl Robot for FakeRobot {
    fn set_motor(&mut self, request: MotorRequest) {
        self.motions.push(request);
    }
    fn stop_motors(&mut self) {
        self.stops += 1;
    }
    fn wheel_positions_mm(&self) -> Option<[i64; 2]> {
        self.wheels
    }
    fn lds_rpm(&self) -> Option<f64> {
        self.rpm
    }
    fn lds_scan(&self) -> Result<&RevolutionFrame, Unavailable> {
        match (&self.scan, self.lidar) {
            (Some(frame), _) => Ok(frame),
            (None, true) => Err(Unavailable::NotYet),
            (None, false) => Err(Unavailable::NoSensor),
        }
    }
    fn sonar_mm(&self) -> Result<Option<u32>, Unavailable> {
        self.sonar.unwrap_or(Err(Unavailable::NoSensor))
    }
}

/// Feeds `input` and returns the replies as text.
fn talk(port: &mut CommandPort, robot: &mut FakeRobot, input: &[u8]) -> String {
    let mut out = Vec::new();
    port.feed(input, robot, &mut out);
    String::from_utf8(out).unwrap()
}

/// Splits replies on the terminator, dropping the empty tail.
fn replies(text: &str) -> Vec<&str> {
    let mut parts: Vec<&str> = text.split('\u{1a}').collect();
    assert_eq!(
        parts.pop(),
        Some(""),
        "every reply ends with Ctrl-Z: {text:?}"
    );
    parts
}

#[test]
fn test_mode_on_off_case_insensitive_and_echoed() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    let text = talk(
        &mut port,
        &mut robot,
        b"TestMode On\ntestmode OFF\r\nTESTMODE on\n",
    );
    assert_eq!(
        replies(&text),
        ["TestMode On\r\n", "testmode OFF\r\n", "TESTMODE on\r\n"]
    );
    assert!(port.test_mode());
    // Leaving test mode stopped the wheels once.
    assert_eq!(robot.stops, 1);
    let text = talk(&mut port, &mut robot, b"TestMode\nTestMode maybe\n");
    assert_eq!(
        replies(&text),
        [
            "TestMode\r\nError: TestMode takes On or Off\r\n",
            "TestMode maybe\r\nError: TestMode takes On or Off\r\n"
        ]
    );
    assert!(port.test_mode(), "a malformed TestMode changes nothing");
    assert_eq!(port.stats().test_mode, 3);
    assert_eq!(port.stats().errors, 2);
}

#[test]
fn set_motor_is_refused_outside_test_mode_like_the_real_robot() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    let text = talk(&mut port, &mut robot, b"SetMotor 100 100 100\n");
    assert_eq!(
        text,
        "SetMotor 100 100 100\r\nError: SetMotor needs TestMode On\r\n\u{1a}"
    );
    assert!(robot.motions.is_empty());
}

#[test]
fn set_motor_takes_named_parameters_in_any_order_or_three_values() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    talk(&mut port, &mut robot, b"testmode on\n");
    let text = talk(
        &mut port,
        &mut robot,
        b"SetMotor LWheelDist 100 RWheelDist -50 Speed 200\n\
          setmotor speed 10 rwheeldist 5 lwheeldist -7\n\
          SetMotor 300 300 300\n\
          SetMotor 0 0 0\n",
    );
    assert_eq!(replies(&text).len(), 4);
    assert!(!text.contains("Error"), "{text}");
    let m = |l, r, s| MotorRequest {
        left_mm: l,
        right_mm: r,
        speed_mm_s: s,
    };
    assert_eq!(
        robot.motions,
        [m(100, -50, 200), m(-7, 5, 10), m(300, 300, 300), m(0, 0, 0)]
    );
    assert_eq!(port.stats().set_motor, 4);
}

#[test]
fn malformed_set_motor_gets_an_error_line_and_moves_nothing() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    talk(&mut port, &mut robot, b"TestMode On\n");
    for (input, error) in [
        ("SetMotor", "needs LWheelDist"),
        ("SetMotor 100 100", "unsupported parameter `100`"),
        ("SetMotor LWheelDist 100 RWheelDist 100", "needs LWheelDist"),
        ("SetMotor LWheelDist", "LWheelDist needs a value"),
        (
            "SetMotor LWheelDist ten RWheelDist 1 Speed 1",
            "needs a whole number",
        ),
        (
            "SetMotor LWheelDist 1.5 RWheelDist 1 Speed 1",
            "needs a whole number",
        ),
        ("SetMotor 1 1 1 1", "unsupported parameter `1`"),
        ("SetMotor LWheelDist 1 LWheelDist 2 Speed 3", "given twice"),
        ("SetMotor Brush", "unsupported parameter `Brush`"),
        ("SetMotor 10001 0 100", "beyond ±10000 mm"),
        ("SetMotor 0 -10001 100", "beyond ±10000 mm"),
        ("SetMotor 100 100 301", "outside 1..=300"),
        ("SetMotor 100 100 -5", "outside 1..=300"),
        ("SetMotor 100 100 0", "outside 1..=300"),
        ("SetMotor 99999999999 1 1", "needs a whole number"),
    ] {
        let text = talk(&mut port, &mut robot, format!("{input}\n").as_bytes());
        let expected_start = format!("{input}\r\nError: ");
        assert!(text.starts_with(&expected_start), "{input}: {text:?}");
        assert!(text.contains(error), "{input}: {text:?}");
        assert!(text.ends_with("\r\n\u{1a}"), "{input}: {text:?}");
    }
    assert!(robot.motions.is_empty());
    assert_eq!(port.stats().errors, 15);
    assert_eq!(port.stats().first_errors.len(), KEPT_ERRORS);
}

#[test]
fn get_motors_reports_the_encoders_in_the_xv_table() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    robot.wheels = Some([1234, -56]);
    robot.rpm = Some(300.4);
    let text = talk(&mut port, &mut robot, b"GetMotors\n");
    let lines: Vec<&str> = text.split("\r\n").collect();
    assert_eq!(lines[0], "GetMotors");
    assert_eq!(lines[1], "Parameter,Value");
    assert_eq!(lines.len(), 2 + MOTOR_ROWS.len() + 1);
    assert_eq!(*lines.last().unwrap(), "\u{1a}");
    assert!(lines.contains(&"LeftWheel_PositionInMM,1234"));
    assert!(lines.contains(&"RightWheel_PositionInMM,-56"));
    assert!(lines.contains(&"Laser_RPM,300"));
    assert!(lines.contains(&"Brush_RPM,0"));
    // Flags select groups; no test mode is needed to read.
    let text = talk(&mut port, &mut robot, b"getmotors leftwheel RIGHTWHEEL\n");
    assert_eq!(
        text,
        "getmotors leftwheel RIGHTWHEEL\r\nParameter,Value\r\nLeftWheel_MaxPWM,0\r\n\
         LeftWheel_PWM,0\r\nLeftWheel_mVolts,0\r\nLeftWheel_Encoder,0\r\n\
         LeftWheel_PositionInMM,1234\r\nLeftWheel_RPM,0\r\nRightWheel_MaxPWM,0\r\n\
         RightWheel_PWM,0\r\nRightWheel_mVolts,0\r\nRightWheel_Encoder,0\r\n\
         RightWheel_PositionInMM,-56\r\nRightWheel_RPM,0\r\n\u{1a}"
    );
    let text = talk(&mut port, &mut robot, b"GetMotors Wheels\n");
    assert!(
        text.contains("Error: GetMotors: unknown flag `Wheels`"),
        "{text}"
    );
    robot.wheels = None;
    let text = talk(&mut port, &mut robot, b"GetMotors\n");
    assert_eq!(
        text,
        "GetMotors\r\nError: GetMotors: the robot has no wheel encoders\r\n\u{1a}"
    );
    assert_eq!(port.stats().get_motors, 2);
}

#[test]
fn get_lds_scan_lists_the_latest_revolution() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    let text = talk(&mut port, &mut robot, b"GetLDSScan\n");
    assert!(
        text.contains("Error: GetLDSScan: the robot has no lidar"),
        "{text}"
    );
    robot.lidar = true;
    let text = talk(&mut port, &mut robot, b"GetLDSScan\n");
    assert!(
        text.contains("Error: GetLDSScan: no complete revolution yet"),
        "{text}"
    );
    let mut readings = [Reading::distance(1500, 120); 360];
    readings[1] = Reading::error(0x35);
    readings[359] = Reading::distance(498, 700);
    robot.scan = Some(RevolutionFrame {
        rev: 3,
        rpm: 301.5,
        start_s: 0.6,
        readings,
    });
    let text = talk(&mut port, &mut robot, b"getldsscan\r\n");
    let lines: Vec<&str> = text.split("\r\n").collect();
    assert_eq!(lines.len(), 1 + 1 + 360 + 1 + 1);
    assert_eq!(lines[0], "getldsscan");
    assert_eq!(lines[1], "AngleInDegrees,DistInMM,Intensity,ErrorCodeHEX");
    assert_eq!(lines[2], "0,1500,120,0");
    assert_eq!(lines[3], "1,0,0,35");
    assert_eq!(lines[361], "359,498,700,0");
    assert_eq!(lines[362], "ROTATION_SPEED,5.03");
    assert_eq!(lines[363], "\u{1a}");
    let text = talk(&mut port, &mut robot, b"GetLDSScan now\n");
    assert!(
        text.contains("Error: GetLDSScan takes no parameters"),
        "{text}"
    );
    assert_eq!(port.stats().get_lds_scan, 1);
}

#[test]
fn get_sonar_reports_the_last_ping_and_zero_for_no_echo() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    let text = talk(&mut port, &mut robot, b"GetSonar\n");
    assert_eq!(
        text,
        "GetSonar\r\nError: GetSonar: the robot has no sonar\r\n\u{1a}"
    );
    robot.sonar = Some(Err(Unavailable::NotYet));
    assert!(talk(&mut port, &mut robot, b"GetSonar\n").contains("no ping yet"));
    robot.sonar = Some(Ok(Some(2468)));
    assert_eq!(
        talk(&mut port, &mut robot, b"GETSONAR\n"),
        "GETSONAR\r\nSonar_DistInMM,2468\r\n\u{1a}"
    );
    robot.sonar = Some(Ok(None));
    assert_eq!(
        talk(&mut port, &mut robot, b"getsonar\n"),
        "getsonar\r\nSonar_DistInMM,0\r\n\u{1a}"
    );
    assert_eq!(port.stats().get_sonar, 2);
}

#[test]
fn unknown_commands_get_an_error_line_and_the_port_keeps_answering() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    robot.sonar = Some(Ok(Some(100)));
    let text = talk(
        &mut port,
        &mut robot,
        b"GetVersion\nGetMotor\n\x1a\xff\xfe\nGetSonar\n",
    );
    let r = replies(&text);
    assert_eq!(r[0], "GetVersion\r\nUnknown Cmd: GetVersion\r\n");
    // No partial-word matching: the name must be whole.
    assert_eq!(r[1], "GetMotor\r\nUnknown Cmd: GetMotor\r\n");
    // Control characters are echoed as `?`, so a stray 0x1A cannot end a reply early.
    assert_eq!(
        r[2],
        "?\u{fffd}\u{fffd}\r\nUnknown Cmd: ?\u{fffd}\u{fffd}\r\n"
    );
    assert_eq!(r[3], "GetSonar\r\nSonar_DistInMM,100\r\n");
    assert_eq!(port.stats().errors, 3);
    assert_eq!(port.stats().requests, 4);
}

#[test]
fn partial_lines_wait_for_their_end_and_any_line_ending_works() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    robot.sonar = Some(Ok(Some(42)));
    let mut out = Vec::new();
    assert_eq!(port.feed(b"Get", &mut robot, &mut out), 0);
    assert_eq!(port.feed(b"So", &mut robot, &mut out), 0);
    assert!(out.is_empty(), "nothing is answered before the line ends");
    assert_eq!(port.feed(b"nar\r", &mut robot, &mut out), 1);
    // The `\n` of a `\r\n` split across reads ends an empty line: no reply.
    assert_eq!(port.feed(b"\n", &mut robot, &mut out), 0);
    assert_eq!(
        port.feed(b"GetSonar\n\n\r\n  \nGetSonar\r", &mut robot, &mut out),
        2
    );
    let text = String::from_utf8(out).unwrap();
    assert_eq!(replies(&text), ["GetSonar\r\nSonar_DistInMM,42\r\n"; 3]);
    assert_eq!(port.stats().bytes, 3 + 2 + 4 + 1 + 24);
}

#[test]
fn an_overlong_line_is_refused_once_and_the_next_line_is_answered() {
    let (mut port, mut robot) = (CommandPort::new(), FakeRobot::default());
    robot.sonar = Some(Ok(Some(7)));
    let mut input = vec![b'x'; 10_000];
    input.extend_from_slice(b"\nGetSonar\n");
    let text = talk(&mut port, &mut robot, &input);
    let r = replies(&text);
    assert_eq!(r.len(), 2);
    assert!(
        r[0].ends_with("\r\nError: line longer than 256 bytes\r\n"),
        "{}",
        r[0]
    );
    assert_eq!(
        r[0].len(),
        MAX_LINE + 2 + "Error: line longer than 256 bytes\r\n".len()
    );
    assert_eq!(r[1], "GetSonar\r\nSonar_DistInMM,7\r\n");
}
