//! The robot command port: a line protocol modelled on the Neato robots' USB command interface
//! (the XV "Programmer's Manual"), as a pure state machine. Bytes from the firmware go in
//! ([`CommandPort::feed`]); replies come out into a buffer; what a reply says about the robot
//! comes from a [`Robot`], so nothing here reads a clock or a port.
//!
//! The subset (`docs/hil.md` is the user's copy):
//! - a request is one line ending in `\n`, `\r\n` or `\r`; empty lines are ignored; commands
//!   and parameter names are case-insensitive; a line longer than [`MAX_LINE`] bytes is
//!   refused;
//! - every reply starts with the request line echoed (the real robot echoes what it is sent),
//!   ends each line with `\r\n` and ends with [`REPLY_END`] (Ctrl-Z, 0x1A), as the real robot
//!   does;
//! - `TestMode On|Off`; `SetMotor LWheelDist <mm> RWheelDist <mm> Speed <mm/s>` (or the three
//!   values alone, in that order) only in test mode; `GetMotors [Brush] [Vacuum] [LeftWheel]
//!   [RightWheel] [Laser] [Charger]`; `GetLDSScan`; `GetSonar` (hilsim's extension);
//! - an unknown command gets `Unknown Cmd: <name>`, anything else wrong `Error: <what>`.
//!
//! ```
//! use hilsim_hil::command_port::{CommandPort, Robot, Unavailable};
//! use hilsim_hil::motion::MotorRequest;
//! use hilsim_lidar_emulator::wire::RevolutionFrame;
//!
//! struct Parked;
//! impl Robot for Parked {
//!     fn set_motor(&mut self, _: MotorRequest) {}
//!     fn stop_motors(&mut self) {}
//!     fn wheel_positions_mm(&self) -> Option<[i64; 2]> { Some([12, -3]) }
//!     fn lds_rpm(&self) -> Option<f64> { None }
//!     fn lds_scan(&self) -> Result<&RevolutionFrame, Unavailable> { Err(Unavailable::NoSensor) }
//!     fn sonar_mm(&self) -> Result<Option<u32>, Unavailable> { Ok(Some(731)) }
//! }
//!
//! let mut port = CommandPort::new();
//! let mut reply = Vec::new();
//! port.feed(b"getsonar\r\n", &mut Parked, &mut reply);
//! assert_eq!(reply, b"getsonar\r\nSonar_DistInMM,731\r\n\x1a");
//! ```

use hilsim_lidar_emulator::neato_packet::READINGS_PER_REVOLUTION;
use hilsim_lidar_emulator::wire::RevolutionFrame;

use crate::motion::MotorRequest;

/// The byte that ends every reply (Ctrl-Z), as on the real robot.
pub const REPLY_END: u8 = 0x1A;
/// The longest request line accepted, bytes (the longest valid request is under 80).
pub const MAX_LINE: usize = 256;
/// The largest wheel distance `SetMotor` takes, mm (the robot's documented ±10,000 mm).
pub const MAX_WHEEL_DIST_MM: i32 = 10_000;
/// The highest wheel speed `SetMotor` takes, mm/s (the robot's documented 300 mm/s).
pub const MAX_SPEED_MM_S: i32 = 300;
/// How many distinct error replies the statistics keep, for the run's report.
const KEPT_ERRORS: usize = 5;

/// Why a sensor value cannot be given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unavailable {
    /// The scenario's robot lacks the sensor.
    NoSensor,
    /// The sensor has not produced a value yet (e.g. no complete lidar revolution).
    NotYet,
}

/// What the command port asks of the robot. The harness implements it over the running
/// emulation; tests implement it with fixed values.
pub trait Robot {
    /// An accepted `SetMotor`: start this motion, replacing the current one.
    fn set_motor(&mut self, request: MotorRequest);
    /// `TestMode Off`: stop the wheels.
    fn stop_motors(&mut self);
    /// Cumulative travel of the left and right wheels as the encoders report it now, mm;
    /// `None` when the robot has no encoders.
    fn wheel_positions_mm(&self) -> Option<[i64; 2]>;
    /// The lidar motor's speed, rpm; `None` without a lidar.
    fn lds_rpm(&self) -> Option<f64>;
    /// The latest complete lidar revolution.
    ///
    /// # Errors
    /// No lidar, or no revolution completed yet.
    fn lds_scan(&self) -> Result<&RevolutionFrame, Unavailable>;
    /// The latest sonar ping: `Some(mm)` for an echo, `None` when the ping timed out.
    ///
    /// # Errors
    /// No sonar, or no ping yet.
    fn sonar_mm(&self) -> Result<Option<u32>, Unavailable>;
}

/// What the port has seen.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CommandStats {
    /// Bytes received.
    pub bytes: u64,
    /// Requests answered (non-empty lines).
    pub requests: u64,
    /// `TestMode` requests answered without error.
    pub test_mode: u64,
    /// `SetMotor` requests accepted.
    pub set_motor: u64,
    /// `GetMotors` requests answered without error.
    pub get_motors: u64,
    /// `GetLDSScan` requests answered without error.
    pub get_lds_scan: u64,
    /// `GetSonar` requests answered without error.
    pub get_sonar: u64,
    /// Requests answered with `Unknown Cmd` or `Error`.
    pub errors: u64,
    /// The first few distinct error replies, as `request -> reply`.
    pub first_errors: Vec<String>,
}

/// The protocol state: the partial line, test mode and the statistics.
#[derive(Debug, Clone, Default)]
pub struct CommandPort {
    line: Vec<u8>,
    overlong: bool,
    test_mode: bool,
    stats: CommandStats,
}

/// A parsed request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Request {
    TestMode(bool),
    SetMotor(MotorRequest),
    GetMotors(MotorGroups),
    GetLdsScan,
    GetSonar,
}

/// Why a request is refused: the reply line.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Refusal {
    Unknown(String),
    Error(String),
}

impl CommandPort {
    /// A port in the robot's power-on state: test mode off, nothing buffered.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether test mode is on.
    #[must_use]
    pub fn test_mode(&self) -> bool {
        self.test_mode
    }

    /// What the port has seen so far.
    #[must_use]
    pub fn stats(&self) -> &CommandStats {
        &self.stats
    }

    /// Takes bytes the firmware wrote, answers every line they complete into `out` (appended),
    /// and returns how many requests were answered. A partial line waits for its end.
    pub fn feed(&mut self, bytes: &[u8], robot: &mut dyn Robot, out: &mut Vec<u8>) -> usize {
        self.stats.bytes += bytes.len() as u64;
        let mut answered = 0;
        for &byte in bytes {
            if byte == b'\n' || byte == b'\r' {
                let line = std::mem::take(&mut self.line);
                let overlong = std::mem::replace(&mut self.overlong, false);
                if self.answer(&line, overlong, robot, out) {
                    answered += 1;
                }
                self.line = line;
                self.line.clear();
            } else if self.line.len() < MAX_LINE {
                self.line.push(byte);
            } else {
                self.overlong = true;
            }
        }
        answered
    }

    /// Answers one complete line; `false` for an empty one (no reply).
    fn answer(
        &mut self,
        line: &[u8],
        overlong: bool,
        robot: &mut dyn Robot,
        out: &mut Vec<u8>,
    ) -> bool {
        // Control characters would garble the echo (a 0x1A would end the reply early).
        let text: String = String::from_utf8_lossy(line)
            .chars()
            .map(|c| {
                if c.is_control() && !c.is_whitespace() {
                    '?'
                } else {
                    c
                }
            })
            .collect();
        let request = text.trim();
        if request.is_empty() && !overlong {
            return false;
        }
        self.stats.requests += 1;
        push_line(out, request);
        let parsed = if overlong {
            Err(Refusal::Error(format!("line longer than {MAX_LINE} bytes")))
        } else {
            parse(request)
        };
        match parsed.and_then(|r| self.execute(r, robot, out)) {
            Ok(()) => {}
            Err(refusal) => {
                let reply = match refusal {
                    Refusal::Unknown(name) => format!("Unknown Cmd: {name}"),
                    Refusal::Error(what) => format!("Error: {what}"),
                };
                push_line(out, &reply);
                self.stats.errors += 1;
                let entry = format!("{request} -> {reply}");
                if self.stats.first_errors.len() < KEPT_ERRORS
                    && !self.stats.first_errors.contains(&entry)
                {
                    self.stats.first_errors.push(entry);
                }
            }
        }
        out.push(REPLY_END);
        true
    }

    /// Carries out a well-formed request, writing its reply body.
    fn execute(
        &mut self,
        request: Request,
        robot: &mut dyn Robot,
        out: &mut Vec<u8>,
    ) -> Result<(), Refusal> {
        match request {
            Request::TestMode(on) => {
                if self.test_mode && !on {
                    robot.stop_motors();
                }
                self.test_mode = on;
                self.stats.test_mode += 1;
            }
            Request::SetMotor(motor) => {
                if !self.test_mode {
                    return Err(Refusal::Error("SetMotor needs TestMode On".into()));
                }
                robot.set_motor(motor);
                self.stats.set_motor += 1;
            }
            Request::GetMotors(groups) => {
                let [left, right] = robot.wheel_positions_mm().ok_or_else(|| {
                    Refusal::Error("GetMotors: the robot has no wheel encoders".into())
                })?;
                let laser_rpm = robot.lds_rpm().map_or(0, |rpm| rpm.round() as i64);
                push_line(out, "Parameter,Value");
                for (group, name) in MOTOR_ROWS {
                    if !groups.contains(*group) {
                        continue;
                    }
                    let value = match *name {
                        "LeftWheel_PositionInMM" => left,
                        "RightWheel_PositionInMM" => right,
                        "Laser_RPM" => laser_rpm,
                        _ => 0,
                    };
                    push_line(out, &format!("{name},{value}"));
                }
                self.stats.get_motors += 1;
            }
            Request::GetLdsScan => {
                let frame = robot.lds_scan().map_err(|why| {
                    Refusal::Error(match why {
                        Unavailable::NoSensor => "GetLDSScan: the robot has no lidar".into(),
                        Unavailable::NotYet => "GetLDSScan: no complete revolution yet".into(),
                    })
                })?;
                push_lds_scan(out, frame);
                self.stats.get_lds_scan += 1;
            }
            Request::GetSonar => {
                let echo = robot.sonar_mm().map_err(|why| {
                    Refusal::Error(match why {
                        Unavailable::NoSensor => "GetSonar: the robot has no sonar".into(),
                        Unavailable::NotYet => "GetSonar: no ping yet".into(),
                    })
                })?;
                push_line(out, &format!("Sonar_DistInMM,{}", echo.unwrap_or(0)));
                self.stats.get_sonar += 1;
            }
        }
        Ok(())
    }
}

/// Appends `text` and the line end.
fn push_line(out: &mut Vec<u8>, text: &str) {
    out.extend_from_slice(text.as_bytes());
    out.extend_from_slice(b"\r\n");
}

/// The GetLDSScan body: the header, one line per degree, the motor speed in Hz.
fn push_lds_scan(out: &mut Vec<u8>, frame: &RevolutionFrame) {
    use std::io::Write as _;
    push_line(out, "AngleInDegrees,DistInMM,Intensity,ErrorCodeHEX");
    for (angle, reading) in frame
        .readings
        .iter()
        .enumerate()
        .take(READINGS_PER_REVOLUTION)
    {
        // Writing into a Vec cannot fail.
        let _ = match reading.error_code() {
            Some(code) => write!(out, "{angle},0,0,{code:X}\r\n"),
            None => write!(
                out,
                "{angle},{},{},0\r\n",
                reading.distance_mm, reading.strength
            ),
        };
    }
    let _ = write!(out, "ROTATION_SPEED,{:.2}\r\n", frame.rpm / 60.0);
}

/// GetMotors' row groups, selectable by flag.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct MotorGroups(u8);

impl MotorGroups {
    const ALL: Self = Self(0b11_1111);

    fn contains(self, group: Self) -> bool {
        self.0 & group.0 != 0
    }
}

const BRUSH: MotorGroups = MotorGroups(1);
const VACUUM: MotorGroups = MotorGroups(2);
const LEFT_WHEEL: MotorGroups = MotorGroups(4);
const RIGHT_WHEEL: MotorGroups = MotorGroups(8);
const LASER: MotorGroups = MotorGroups(16);
const CHARGER: MotorGroups = MotorGroups(32);

/// GetMotors' flags and the groups they select.
const MOTOR_FLAGS: &[(&str, MotorGroups)] = &[
    ("brush", BRUSH),
    ("vacuum", VACUUM),
    ("leftwheel", LEFT_WHEEL),
    ("rightwheel", RIGHT_WHEEL),
    ("laser", LASER),
    ("charger", CHARGER),
];

/// The XV series' GetMotors rows, in the robot's order (as the ROS `neato_driver` reads them).
/// Only the wheel positions and the laser speed carry values here; the rest report 0.
const MOTOR_ROWS: &[(MotorGroups, &str)] = &[
    (BRUSH, "Brush_MaxPWM"),
    (BRUSH, "Brush_PWM"),
    (BRUSH, "Brush_mVolts"),
    (BRUSH, "Brush_Encoder"),
    (BRUSH, "Brush_RPM"),
    (VACUUM, "Vacuum_MaxPWM"),
    (VACUUM, "Vacuum_PWM"),
    (VACUUM, "Vacuum_CurrentInMA"),
    (VACUUM, "Vacuum_Encoder"),
    (VACUUM, "Vacuum_RPM"),
    (LEFT_WHEEL, "LeftWheel_MaxPWM"),
    (LEFT_WHEEL, "LeftWheel_PWM"),
    (LEFT_WHEEL, "LeftWheel_mVolts"),
    (LEFT_WHEEL, "LeftWheel_Encoder"),
    (LEFT_WHEEL, "LeftWheel_PositionInMM"),
    (LEFT_WHEEL, "LeftWheel_RPM"),
    (RIGHT_WHEEL, "RightWheel_MaxPWM"),
    (RIGHT_WHEEL, "RightWheel_PWM"),
    (RIGHT_WHEEL, "RightWheel_mVolts"),
    (RIGHT_WHEEL, "RightWheel_Encoder"),
    (RIGHT_WHEEL, "RightWheel_PositionInMM"),
    (RIGHT_WHEEL, "RightWheel_RPM"),
    (LASER, "Laser_MaxPWM"),
    (LASER, "Laser_PWM"),
    (LASER, "Laser_mVolts"),
    (LASER, "Laser_Encoder"),
    (LASER, "Laser_RPM"),
    (CHARGER, "Charger_MaxPWM"),
    (CHARGER, "Charger_PWM"),
    (CHARGER, "Charger_mAH"),
];

/// Parses one non-empty request line.
fn parse(line: &str) -> Result<Request, Refusal> {
    let mut words = line.split_whitespace();
    let name = words.next().unwrap_or_default();
    let args: Vec<&str> = words.collect();
    match name.to_ascii_lowercase().as_str() {
        "testmode" => match args.as_slice() {
            [on] if on.eq_ignore_ascii_case("on") => Ok(Request::TestMode(true)),
            [off] if off.eq_ignore_ascii_case("off") => Ok(Request::TestMode(false)),
            _ => Err(Refusal::Error("TestMode takes On or Off".into())),
        },
        "setmotor" => parse_set_motor(&args).map(Request::SetMotor),
        "getmotors" => {
            if args.is_empty() {
                return Ok(Request::GetMotors(MotorGroups::ALL));
            }
            let mut groups = MotorGroups(0);
            for arg in &args {
                let (_, group) = MOTOR_FLAGS
                    .iter()
                    .find(|(flag, _)| arg.eq_ignore_ascii_case(flag))
                    .ok_or_else(|| {
                        Refusal::Error(format!(
                            "GetMotors: unknown flag `{arg}` (Brush, Vacuum, LeftWheel, \
                             RightWheel, Laser, Charger)"
                        ))
                    })?;
                groups.0 |= group.0;
            }
            Ok(Request::GetMotors(groups))
        }
        "getldsscan" => no_args("GetLDSScan", &args).map(|()| Request::GetLdsScan),
        "getsonar" => no_args("GetSonar", &args).map(|()| Request::GetSonar),
        _ => Err(Refusal::Unknown(name.to_string())),
    }
}

fn no_args(name: &str, args: &[&str]) -> Result<(), Refusal> {
    match args.first() {
        None => Ok(()),
        Some(arg) => Err(Refusal::Error(format!(
            "{name} takes no parameters, got `{arg}`"
        ))),
    }
}

/// `SetMotor LWheelDist <mm> RWheelDist <mm> Speed <mm/s>` (names in any order, any case) or
/// `SetMotor <mm> <mm> <mm/s>`.
fn parse_set_motor(args: &[&str]) -> Result<MotorRequest, Refusal> {
    const NAMES: [&str; 3] = ["LWheelDist", "RWheelDist", "Speed"];
    let mut values: [Option<i32>; 3] = [None; 3];
    if args.len() == 3 && args.iter().all(|a| a.parse::<i64>().is_ok()) {
        for (slot, (arg, name)) in values.iter_mut().zip(args.iter().zip(NAMES)) {
            *slot = Some(integer(name, arg)?);
        }
    } else {
        let mut rest = args.iter();
        while let Some(param) = rest.next() {
            let index = NAMES
                .iter()
                .position(|n| param.eq_ignore_ascii_case(n))
                .ok_or_else(|| {
                    Refusal::Error(format!(
                        "SetMotor: unsupported parameter `{param}` (hilsim takes LWheelDist, \
                         RWheelDist and Speed)"
                    ))
                })?;
            let name = NAMES[index];
            let value = rest
                .next()
                .ok_or_else(|| Refusal::Error(format!("SetMotor: {name} needs a value")))?;
            if values[index].is_some() {
                return Err(Refusal::Error(format!("SetMotor: {name} given twice")));
            }
            values[index] = Some(integer(name, value)?);
        }
    }
    let [Some(left_mm), Some(right_mm), Some(speed_mm_s)] = values else {
        return Err(Refusal::Error(
            "SetMotor needs LWheelDist <mm> RWheelDist <mm> Speed <mm/s>".into(),
        ));
    };
    for (name, dist) in [("LWheelDist", left_mm), ("RWheelDist", right_mm)] {
        if dist.abs() > MAX_WHEEL_DIST_MM {
            return Err(Refusal::Error(format!(
                "SetMotor: {name} {dist} is beyond ±{MAX_WHEEL_DIST_MM} mm"
            )));
        }
    }
    let stop = left_mm == 0 && right_mm == 0;
    if !(0..=MAX_SPEED_MM_S).contains(&speed_mm_s) || (speed_mm_s == 0 && !stop) {
        return Err(Refusal::Error(format!(
            "SetMotor: Speed {speed_mm_s} is outside 1..={MAX_SPEED_MM_S} mm/s"
        )));
    }
    Ok(MotorRequest {
        left_mm,
        right_mm,
        speed_mm_s,
    })
}

fn integer(name: &str, text: &str) -> Result<i32, Refusal> {
    text.parse::<i32>().map_err(|_| {
        Refusal::Error(format!(
            "SetMotor: {name} needs a whole number, got `{text}`"
        ))
    })
}

#[cfg(test)]
mod tests;
