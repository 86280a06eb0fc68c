//! The URG-04LX's side: the host's commands into replies, the head's readings into scan replies.

use super::commands::{self, Command, ScanRequest, Status, OK, UNDEFINED};
use super::encoding::{
    checksum, clock_ms, distance_field, encode, index_step, FIRST_STEP, LAST_STEP, MAX_STEP,
    NON_MEASURABLE_CODE, NO_OBJECT_CODE, STEPS_PER_REV,
};
use crate::{Output, Unit, UnitReading};

/// The longest command line kept: the longest command (`MD`, 15 characters, a `;` and 16 string
/// characters) with room to spare; a longer line is no command and is dropped whole.
const MAX_LINE: usize = 64;
/// Characters in one data line before its check character (specification section 8.1).
const BLOCK_LEN: usize = 64;
/// The bit rate the unit starts at and returns to on `RS` (the model's serial speed).
const DEFAULT_BIT_RATE: u32 = 115_200;
/// The bit rates `SS` accepts (specification section 8.7).
const BIT_RATES: [u32; 7] = [19_200, 38_400, 57_600, 115_200, 250_000, 500_000, 750_000];
/// The revolution rate assumed when a reading carries none: 600 rpm (`PP` `SCAN`).
const DEFAULT_REV_HZ: f64 = 10.0;
/// Marks a step no reading reached in the scan being assembled.
const MISSING: u32 = u32::MAX;

/// `VV`'s lines (the layout of the specification's section 8.11 and of the urgnetwork wiki's
/// URG-04LX example; the serial number is the emulator's own).
const VERSION_LINES: [&str; 5] = [
    "VEND:Hokuyo Automatic Co.,Ltd.",
    "PROD:SOKUIKI Sensor URG-04LX",
    "FIRM:3.1.04",
    "PROT:SCIP 2.0",
    "SERI:H0000000",
];
/// `PP`'s lines (the specification's section 8.12 example).
const PARAMETER_LINES: [&str; 8] = [
    "MODL:URG-04LX(Hokuyo Automatic Co.,Ltd.)",
    "DMIN:20",
    "DMAX:5600",
    "ARES:1024",
    "AMIN:44",
    "AMAX:725",
    "AFRT:384",
    "SCAN:600",
];

/// A scan request being served.
#[derive(Debug, Clone)]
struct Active {
    request: ScanRequest,
    /// The command line as the host sent it (the echo).
    echo: Vec<u8>,
    /// Whether a scan has started since the command (only scans taken after it are sent).
    armed: bool,
    /// Whether the scan being assembled is one to send.
    wanted: bool,
    /// Whether the scan being assembled has been sent.
    sent: bool,
    /// Scans still to skip before the next one sent.
    skip_left: u8,
    /// Scans still to send (`M` with a count).
    left: u8,
}

/// The scan being assembled.
#[derive(Debug, Clone)]
struct Scan {
    /// Distances by step, [`MISSING`] where no reading came.
    values: Vec<u32>,
    /// The unit's clock at the scan's step 0, ms.
    stamp_ms: u32,
    /// The last step read and when.
    last: Option<(u16, f64)>,
}

/// The Hokuyo URG-04LX speaking SCIP 2.0, as described in `docs/formats/scip-urg-04lx.md`.
///
/// It starts in SCIP 2.0 with its laser off; `BM` lights it, `MD`/`MS` stream scans (lighting
/// it themselves), `GD`/`GS` answer with the next whole scan, `QT` stops all.
#[derive(Debug, Clone)]
pub struct ScipUnit {
    line: Vec<u8>,
    line_overflow: bool,
    laser_on: bool,
    time_adjust: bool,
    motor_level: u8,
    bit_rate: u32,
    /// The simulation time of the unit's clock zero (`RS` resets it).
    epoch_s: f64,
    continuous: Option<Active>,
    single: Option<Active>,
    scan: Scan,
}

impl Default for ScipUnit {
    fn default() -> Self {
        Self {
            line: Vec::with_capacity(MAX_LINE),
            line_overflow: false,
            laser_on: false,
            time_adjust: false,
            motor_level: 0,
            bit_rate: DEFAULT_BIT_RATE,
            epoch_s: 0.0,
            continuous: None,
            single: None,
            scan: Scan {
                values: vec![MISSING; usize::from(MAX_STEP) + 1],
                stamp_ms: 0,
                last: None,
            },
        }
    }
}

impl ScipUnit {
    /// A unit just powered on: SCIP 2.0, laser off, clock at zero at simulation time 0.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether the laser is lit.
    #[must_use]
    pub fn laser_on(&self) -> bool {
        self.laser_on
    }

    fn clock(&self, t_s: f64) -> u32 {
        clock_ms(t_s - self.epoch_s)
    }

    fn stop(&mut self) {
        self.laser_on = false;
        self.continuous = None;
        self.single = None;
    }

    /// Answers one command line.
    fn command(&mut self, line: &[u8], now_s: f64, out: &mut Output) {
        let parsed = commands::parse(line);
        if self.time_adjust && !matches!(parsed, Ok(Command::Time(_))) {
            // In time-adjust mode the unit takes no other command (specification section 8.6).
            return reply(out, now_s, line, UNDEFINED, |_| {});
        }
        let command = match parsed {
            Ok(command) => command,
            Err(status) => return reply(out, now_s, line, status, |_| {}),
        };
        match command {
            Command::Scip20 => reply(out, now_s, line, UNDEFINED, |_| {}),
            Command::Version => reply(out, now_s, line, OK, |body| {
                VERSION_LINES.iter().for_each(|l| info_line(l, body));
            }),
            Command::Parameters => reply(out, now_s, line, OK, |body| {
                PARAMETER_LINES.iter().for_each(|l| info_line(l, body));
            }),
            Command::Status => {
                let lines = self.status_lines(now_s);
                reply(out, now_s, line, OK, |body| {
                    lines.iter().for_each(|l| info_line(l, body));
                });
            }
            Command::LaserOn => {
                let status = if self.laser_on { *b"02" } else { OK };
                self.laser_on = true;
                reply(out, now_s, line, status, |_| {});
            }
            Command::Quit => {
                self.stop();
                reply(out, now_s, line, OK, |_| {});
            }
            Command::Reset => {
                self.stop();
                self.motor_level = 0;
                self.bit_rate = DEFAULT_BIT_RATE;
                self.epoch_s = now_s;
                reply(out, now_s, line, OK, |_| {});
            }
            Command::Time(code) => self.time(code, line, now_s, out),
            Command::BitRate(digits) => {
                let status = match commands::number(&digits) {
                    None => *b"01",
                    Some(rate) if !BIT_RATES.contains(&rate) => *b"02",
                    Some(rate) if rate == self.bit_rate => *b"03",
                    Some(rate) => {
                        self.bit_rate = rate;
                        OK
                    }
                };
                reply(out, now_s, line, status, |_| {});
            }
            Command::MotorSpeed(digits) => {
                let status = match commands::number(&digits) {
                    None => *b"01",
                    Some(level) if level > 10 && level != 99 => *b"02",
                    // 00 and 99 both mean the initial speed.
                    Some(level) if (level % 99) as u8 == self.motor_level => *b"03",
                    Some(level) => {
                        self.motor_level = (level % 99) as u8;
                        OK
                    }
                };
                reply(out, now_s, line, status, |_| {});
            }
            Command::Scan(request) => self.scan_command(request, line, now_s, out),
        }
    }

    fn time(&mut self, code: u8, line: &[u8], now_s: f64, out: &mut Output) {
        match (code, self.time_adjust) {
            (b'0', true) => reply(out, now_s, line, *b"02", |_| {}),
            (b'0', false) => {
                // The laser goes off in time-adjust mode.
                self.stop();
                self.time_adjust = true;
                reply(out, now_s, line, OK, |_| {});
            }
            (b'1', false) => reply(out, now_s, line, *b"04", |_| {}),
            (b'1', true) => {
                let ms = self.clock(now_s);
                reply(out, now_s, line, OK, |body| data_line_value(ms, 4, body));
            }
            (b'2', false) => reply(out, now_s, line, *b"03", |_| {}),
            (b'2', true) => {
                self.time_adjust = false;
                reply(out, now_s, line, OK, |_| {});
            }
            _ => reply(out, now_s, line, *b"01", |_| {}),
        }
    }

    fn scan_command(&mut self, request: ScanRequest, line: &[u8], now_s: f64, out: &mut Output) {
        if !request.continuous && !self.laser_on {
            return reply(out, now_s, line, *b"10", |_| {});
        }
        let active = Active {
            request,
            echo: line.to_vec(),
            armed: false,
            wanted: false,
            sent: false,
            skip_left: 0,
            left: request.scans,
        };
        if request.continuous {
            // MD and MS light the laser themselves and acknowledge at once.
            self.laser_on = true;
            self.continuous = Some(active);
            reply(out, now_s, line, OK, |_| {});
        } else {
            // GD and GS answer with the scan itself.
            self.single = Some(active);
        }
    }

    fn status_lines(&self, now_s: f64) -> [String; 7] {
        let speed = if self.motor_level == 0 {
            "SCSP:Initial(600[rpm])<-Default setting by user".to_string()
        } else {
            format!("SCSP:Changed(level {:02})", self.motor_level)
        };
        [
            PARAMETER_LINES[0].to_string(),
            format!("LASR:{}", if self.laser_on { "ON" } else { "OFF" }),
            speed,
            format!(
                "MESM:{}",
                if self.laser_on {
                    "Measuring by Normal Mode"
                } else {
                    "IDLE"
                }
            ),
            format!("SBPS:{}[bps]", self.bit_rate),
            format!("TIME:{:06X}", self.clock(now_s)),
            "STAT:Sensor works well.".to_string(),
        ]
    }

    /// Ends the scan being assembled: requests that wanted it and have not had it get it now,
    /// with what arrived (a reading lost on the way leaves its step at no object).
    fn finish_scan(&mut self, out: &mut Output) {
        let Some((_, last_t)) = self.scan.last else {
            return;
        };
        for slot in [&mut self.continuous, &mut self.single] {
            if slot.as_ref().is_some_and(|a| a.wanted && !a.sent) {
                send(slot, &self.scan, last_t, &mut self.laser_on, out);
            }
        }
    }

    fn begin_scan(&mut self, reading: &UnitReading, step: u16) {
        self.scan.values.fill(MISSING);
        let rev_hz = if reading.rev_hz.is_finite() && reading.rev_hz > 0.0 {
            reading.rev_hz
        } else {
            DEFAULT_REV_HZ
        };
        // The time stamp is the clock at the scan's step 0 (specification section 8.1,
        // figure 1), before the first step read.
        let step0_s = reading.t_s - f64::from(step) / (f64::from(STEPS_PER_REV) * rev_hz);
        self.scan.stamp_ms = self.clock(step0_s);
        for active in [&mut self.continuous, &mut self.single]
            .into_iter()
            .flatten()
        {
            active.sent = false;
            if !active.armed {
                active.armed = true;
                active.wanted = true;
            } else if active.skip_left > 0 {
                active.skip_left -= 1;
                active.wanted = false;
            } else {
                active.wanted = true;
            }
        }
    }
}

/// Sends the scan reply `slot`'s request wants, and retires the request when it is done.
fn send(slot: &mut Option<Active>, scan: &Scan, due_s: f64, laser_on: &mut bool, out: &mut Output) {
    let Some(active) = slot.as_mut() else {
        return;
    };
    let request = active.request;
    let mut echo = active.echo.clone();
    if request.continuous && request.scans > 0 {
        active.left = active.left.saturating_sub(1);
        // The echo carries the scans still to come in place of the count asked for.
        echo[13..15].copy_from_slice(&[b'0' + active.left / 10, b'0' + active.left % 10]);
    }
    active.sent = true;
    active.skip_left = request.interval;
    let status = if request.continuous { *b"99" } else { OK };
    out.packet(due_s, echo.len() + 1, true, |bytes| {
        bytes.extend_from_slice(&echo);
        bytes.push(b'\n');
        status_line(status, bytes);
        data_line_value(scan.stamp_ms, 4, bytes);
        let mut data = Vec::with_capacity(request.values() * request.chars());
        let mut step = request.start;
        while step <= request.end {
            let last = (step + request.cluster_len() - 1).min(request.end);
            let value = cluster_value(&scan.values[usize::from(step)..=usize::from(last)], step);
            let value = distance_field_or_code(value, request.field_max());
            encode(value, request.chars(), &mut data);
            step = last + 1;
        }
        for block in data.chunks(BLOCK_LEN) {
            bytes.extend_from_slice(block);
            bytes.push(checksum(block));
            bytes.push(b'\n');
        }
        bytes.push(b'\n');
    });
    let done = !request.continuous || (request.scans > 0 && active.left == 0);
    if done {
        *slot = None;
        if request.continuous {
            // The laser goes off after the last of the scans asked for (section 8.1).
            *laser_on = false;
        }
    }
}

/// A cluster's value: the smallest valid distance among its steps, else the first step's error
/// code (specification section 8.1, "Cluster Count").
fn cluster_value(values: &[u32], first_step: u16) -> u32 {
    let code = |i: usize, v: u32| {
        let step = first_step + i as u16;
        if !(FIRST_STEP..=LAST_STEP).contains(&step) {
            NON_MEASURABLE_CODE
        } else if v == MISSING {
            NO_OBJECT_CODE
        } else {
            v
        }
    };
    let mut valid = values
        .iter()
        .enumerate()
        .map(|(i, &v)| code(i, v))
        .filter(|&v| v >= super::encoding::MIN_DISTANCE_MM);
    match valid.next() {
        Some(first) => valid.fold(first, u32::min),
        None => values.first().map_or(NO_OBJECT_CODE, |&v| code(0, v)),
    }
}

/// A value as its field carries it: distances in range stay, error codes stay, the rest is no
/// object.
fn distance_field_or_code(value: u32, field_max: u32) -> u32 {
    if value < super::encoding::MIN_DISTANCE_MM {
        value
    } else {
        distance_field(value, field_max)
    }
}

/// Appends a reply: the echo, the status with its check character, what `body` adds, the empty
/// line.
fn reply(
    out: &mut Output,
    now_s: f64,
    echo: &[u8],
    status: Status,
    body: impl FnOnce(&mut Vec<u8>),
) {
    out.packet(now_s, echo.len() + 1, false, |bytes| {
        bytes.extend_from_slice(echo);
        bytes.push(b'\n');
        status_line(status, bytes);
        body(bytes);
        bytes.push(b'\n');
    });
}

fn status_line(status: Status, bytes: &mut Vec<u8>) {
    bytes.extend_from_slice(&status);
    bytes.push(checksum(&status));
    bytes.push(b'\n');
}

/// An information line: `KEY:VALUE;` and the check character of `KEY:VALUE` (the `;` is left
/// out of the sum, as the specification's examples show).
fn info_line(line: &str, bytes: &mut Vec<u8>) {
    bytes.extend_from_slice(line.as_bytes());
    bytes.push(b';');
    bytes.push(checksum(line.as_bytes()));
    bytes.push(b'\n');
}

fn data_line_value(value: u32, chars: usize, bytes: &mut Vec<u8>) {
    let start = bytes.len();
    encode(value, chars, bytes);
    let sum = checksum(&bytes[start..]);
    bytes.push(sum);
    bytes.push(b'\n');
}

impl Unit for ScipUnit {
    fn host_wrote(&mut self, bytes: &[u8], now_s: f64, out: &mut Output) {
        for &byte in bytes {
            match byte {
                b'\n' | b'\r' => {
                    let line = std::mem::take(&mut self.line);
                    if !line.is_empty() && !self.line_overflow {
                        self.command(&line, now_s, out);
                    }
                    self.line = line;
                    self.line.clear();
                    self.line_overflow = false;
                }
                // A byte no command holds: what came before it on the line was garbage.
                0x00..=0x1F | 0x7F..=0xFF => {
                    self.line.clear();
                    self.line_overflow = false;
                }
                _ if self.line.len() >= MAX_LINE => self.line_overflow = true,
                _ => self.line.push(byte),
            }
        }
    }

    fn scanning(&self) -> bool {
        self.continuous.is_some()
    }

    fn push(&mut self, reading: &UnitReading, out: &mut Output) {
        let Some(step) = index_step(reading.index) else {
            return;
        };
        let wrapped = self.scan.last.is_none_or(|(last, _)| step <= last);
        if reading.starts_revolution || wrapped {
            self.finish_scan(out);
            self.begin_scan(reading, step);
        }
        self.scan.values[usize::from(step)] = reading.distance_mm.min(MISSING - 1);
        self.scan.last = Some((step, reading.t_s));
        for slot in [&mut self.continuous, &mut self.single] {
            let due = slot.as_ref().is_some_and(|a| {
                a.wanted && !a.sent && step >= a.request.end.clamp(FIRST_STEP, LAST_STEP)
            });
            if due {
                send(slot, &self.scan, reading.t_s, &mut self.laser_on, out);
            }
        }
    }
}
