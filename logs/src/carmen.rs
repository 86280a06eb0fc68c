//! CARMEN logs (`.log`, `.clf`; gzipped or not, see [`crate::read_text`]): one message a line,
//! `NAME fields… ipc_time ipc_host logger_time` (the header CARMEN's logger writes, and its
//! `logger_playback` documentation). The messages read:
//!
//! - `FLASER n r1 … rn x y θ odom_x odom_y odom_θ ipc_time host logger_time`: a front laser
//!   scan, ranges in metres, the robot's pose (x y θ: the localised or corrected one where the
//!   log has one) and its odometry at the scan. The old format writes no angles: n beams over
//!   [`CarmenOptions::flaser_fov_deg`] (180° by default, the SICK LMS's), the first at −fov/2 (on
//!   the right), counter-clockwise, 1° apart for 180 or 181 beams (an odd count reaches +fov/2,
//!   an even one stops a step short);
//! - `ROBOTLASER1 laser_type start_angle fov angular_resolution max_range accuracy
//!   remission_mode n r1 … rn m e1 … em laser_x laser_y laser_θ robot_x robot_y robot_θ tv rv
//!   forward_safety side_safety [turn_axis] ipc_time host logger_time`: a scan with its angles
//!   (radians) and the robot's pose; the laser's pose relative to the robot's on the first such
//!   line is the lidar's mount;
//! - `ODOM x y θ tv rv accel ipc_time host logger_time`: the robot's odometry pose;
//! - `TRUEPOS true_x true_y true_θ odom_x odom_y odom_θ ipc_time host logger_time`: the true
//!   pose (a simulator's);
//! - `PARAM robot_frontlaser_offset d …`: the front laser's distance ahead of the robot's centre
//!   (the lidar's mount when no `ROBOTLASER1` gives it).
//!
//! Each scan is one revolution in `lidar.csv`, all its beams at its line's time. A reading of 0
//! or less, or at or beyond the maximum range, is no return (invalid).
//!
//! Real logs are messy: a line whose time goes back from the previous line of its stream (scans,
//! or poses) is skipped, a line that is not one of the kinds read is skipped, and a line of a
//! known kind that cannot be read is skipped; each is counted in a note, with the first line's
//! number. Only more than [`MAX_LINES`] lines, or a log with no scan and no pose, is refused.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use hilsim_recording::{
    wrap_angle, LidarSample, Meta, Mount, OdometrySample, Pose, Recording, RobotMeta, TruthSample,
};

use crate::LogError;

/// The most lines a log may hold: 10⁷, about 1.8·10⁹ readings of 180-beam scans at most, the
/// most a recording should hold in memory; a day's CARMEN log has a few hundred thousand.
pub const MAX_LINES: usize = 10_000_000;
/// The longest line read, bytes: a scan of [`MAX_BEAMS`] ranges and as many remissions at 20
/// characters each fits. A longer line is malformed (it is not split into fields).
pub const MAX_LINE_BYTES: usize = 400_000;
/// The most beams of a scan: 10 times the 1,081 of a 0.25° 270° scanner.
pub const MAX_BEAMS: usize = 10_000;
/// Distinct unknown message names listed in the notes; the rest are counted together.
const MAX_UNKNOWN_NAMES: usize = 16;

/// What the log's own pose fields are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Poses {
    /// The scan lines' poses are good ones (a corrected log's: localised or SLAM-corrected):
    /// `truth.csv` from `FLASER`'s x y θ and `ROBOTLASER1`'s robot pose; a log with `TRUEPOS`
    /// lines has its truth from them instead. `ODOM` lines, CARMEN's odometry message, give
    /// `odometry.csv` (as in [`Poses::Odometry`]).
    #[default]
    Truth,
    /// The log's poses are odometry: `odometry.csv` as the wheel travel that dead reckoning
    /// ([`Pose::drive`] over [`CarmenOptions::wheel_base_m`]) turns back into the poses of the
    /// `ODOM` lines, or, in a log without them, of the scan lines (`FLASER`'s odom_x odom_y
    /// odom_θ, `ROBOTLASER1`'s robot pose); `TRUEPOS` gives `truth.csv`. The two kinds are not
    /// mixed: a corrected log's `ODOM` and scan poses are in different frames.
    Odometry,
}

/// Which of a line's two times is its time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Clock {
    /// `ipc_time`: set by the module that sent the message, when it read its sensor; the
    /// closest to when the scan or pose was taken.
    #[default]
    Ipc,
    /// `logger_time`: when the logger received the message, after IPC's queueing.
    Logger,
}

/// How to read a CARMEN log.
#[derive(Debug, Clone, PartialEq)]
pub struct CarmenOptions {
    /// What the log's pose fields are.
    pub poses: Poses,
    /// Which time a line is at.
    pub clock: Clock,
    /// The wheel base written into `meta.toml` and used to turn poses into wheel travel
    /// ([`Poses::Odometry`]). The log does not give it; any positive value gives back the poses
    /// by dead reckoning, since the same value turns the travel back into poses.
    pub wheel_base_m: f64,
    /// The field of view of `FLASER` scans, degrees: 180, the SICK LMS 200's.
    pub flaser_fov_deg: f64,
    /// Readings at or beyond this are no return: 81.83 m, the SICK LMS's largest range value
    /// (8183 cm; the values above it are its error codes), which CARMEN writes for no echo.
    pub max_range_m: f64,
}

impl Default for CarmenOptions {
    fn default() -> Self {
        Self {
            poses: Poses::default(),
            clock: Clock::default(),
            wheel_base_m: Meta::default().robot.wheel_base_m,
            flaser_fov_deg: 180.0,
            max_range_m: 81.83,
        }
    }
}

impl CarmenOptions {
    fn validate(&self) -> Result<(), LogError> {
        for (name, v) in [
            ("wheel_base_m", self.wheel_base_m),
            ("flaser_fov_deg", self.flaser_fov_deg),
            ("max_range_m", self.max_range_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(LogError::Option {
                    name,
                    message: format!("{v} is not a positive number"),
                });
            }
        }
        if self.flaser_fov_deg > 360.0 {
            return Err(LogError::Option {
                name: "flaser_fov_deg",
                message: format!("{} is more than a turn", self.flaser_fov_deg),
            });
        }
        Ok(())
    }
}

/// Lines skipped for one reason: how many, and the first.
#[derive(Debug, Default)]
struct Skipped {
    count: usize,
    first_line: usize,
    first_reason: String,
}

impl Skipped {
    fn add(&mut self, line: usize, reason: impl FnOnce() -> String) {
        if self.count == 0 {
            self.first_line = line;
            self.first_reason = reason();
        }
        self.count += 1;
    }
}

/// A stream whose times must not go back: the scans, the ODOM poses, the TRUEPOS poses.
#[derive(Debug, Default)]
struct Stream {
    /// The times of the last two lines taken, and the last one's number.
    last_s: Option<f64>,
    before_last_s: Option<f64>,
    last_line: usize,
    back: Skipped,
    most_back_s: f64,
}

/// What becomes of a line in its stream.
#[derive(Debug, PartialEq, Eq)]
enum Take {
    /// It follows the last line taken.
    Yes,
    /// It comes before the last line taken but after the one before: the last one is dropped
    /// for it. Either of the two is out of order and a line is lost either way; dropping the
    /// last one keeps a single stamp far ahead (a corrupt one) from taking the rest of the log
    /// with it.
    InsteadOfLast,
    /// It comes before the last two lines taken.
    No,
}

impl Stream {
    /// Whether a line at `t` may follow; counts what is dropped.
    fn take(&mut self, t: f64, line: usize) -> Take {
        let Some(last) = self.last_s else {
            self.last_s = Some(t);
            self.last_line = line;
            return Take::Yes;
        };
        if t >= last {
            self.before_last_s = self.last_s;
            self.last_s = Some(t);
            self.last_line = line;
            return Take::Yes;
        }
        self.most_back_s = self.most_back_s.max(last - t);
        // With one line taken, that one goes: else a first stamp far ahead would take the
        // whole log with it.
        match self.before_last_s {
            Some(before) if t < before => {
                self.back.add(line, String::new);
                Take::No
            }
            _ => {
                let dropped = self.last_line;
                self.back.add(dropped, String::new);
                self.back.first_line = self.back.first_line.min(dropped);
                self.last_s = Some(t);
                self.last_line = line;
                Take::InsteadOfLast
            }
        }
    }
}

/// A pose read from a line, before it goes to a table.
#[derive(Debug, Clone, Copy)]
struct Stamped {
    t: f64,
    pose: Pose,
    /// An `ODOM` pose's dead reckoning restarted here since the pose before it (a corrected
    /// log's reset to the scan's pose): its travel is measured from this pose.
    from: Option<Pose>,
}

/// One line's fields, read in order.
struct Fields<'a> {
    it: std::str::SplitWhitespace<'a>,
}

impl<'a> Fields<'a> {
    fn word(&mut self, what: &str) -> Result<&'a str, String> {
        self.it
            .next()
            .ok_or_else(|| format!("ends before its {what}"))
    }
    fn number(&mut self, what: &str) -> Result<f64, String> {
        let w = self.word(what)?;
        w.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("its {what} `{}` is not a number", short(w)))
    }
    fn count(&mut self, what: &str) -> Result<usize, String> {
        let w = self.word(what)?;
        let n = w
            .parse::<usize>()
            .map_err(|_| format!("its {what} `{}` is not a count", short(w)))?;
        if n > MAX_BEAMS {
            return Err(format!("its {what} {n} is more than {MAX_BEAMS}"));
        }
        Ok(n)
    }
    fn pose(&mut self, what: &str) -> Result<Pose, String> {
        Ok(Pose::new(
            self.number(what)?,
            self.number(what)?,
            self.number(what)?,
        ))
    }
    /// `ipc_time host logger_time` and the end of the line; the chosen time.
    fn tail(&mut self, clock: Clock) -> Result<f64, String> {
        let ipc = self.word("ipc_time")?;
        self.word("host")?;
        let logger = self.word("logger_time")?;
        if let Some(extra) = self.it.next() {
            return Err(format!("has `{}` after its logger_time", short(extra)));
        }
        stamp(ipc, logger, clock)
    }
}

/// The time `clock` chooses of a line's `ipc_time` and `logger_time`.
fn stamp(ipc: &str, logger: &str, clock: Clock) -> Result<f64, String> {
    let (what, w) = match clock {
        Clock::Ipc => ("ipc_time", ipc),
        Clock::Logger => ("logger_time", logger),
    };
    w.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("its {what} `{}` is not a number", short(w)))
}

/// A field cut short for a note.
fn short(w: &str) -> String {
    hilsim_recording::printable_cut(w, 24).into_owned()
}

/// What a line gave.
enum Read {
    Scan {
        t: f64,
        pose: Pose,
        mount: Option<Mount>,
    },
    Odom(Stamped),
    True(Stamped),
    Nothing,
}

/// The recording of a CARMEN log's `text` (`origin` names it in notes and errors), and notes
/// on what was skipped and why. Time 0 is the earliest line taken.
///
/// # Errors
/// More than [`MAX_LINES`] lines, no scan and no pose, or options out of range.
pub fn read_carmen(
    text: &str,
    origin: &str,
    options: &CarmenOptions,
) -> Result<(Recording, Vec<String>), LogError> {
    options.validate()?;
    let mut lidar: Vec<LidarSample> = Vec::new();
    // The scan lines' poses, the ODOM lines', the TRUEPOS lines'.
    let mut poses: Vec<Stamped> = Vec::new();
    let mut odoms: Vec<Stamped> = Vec::new();
    let mut truths: Vec<Stamped> = Vec::new();
    let (mut scans, mut odom_stream, mut truth_stream) =
        (Stream::default(), Stream::default(), Stream::default());
    let mut malformed = Skipped::default();
    let mut unknown: BTreeMap<String, Skipped> = BTreeMap::new();
    let mut unknown_other = Skipped::default();
    let mut revs = 0u64;
    // Where the last scan taken starts in `lidar`.
    let mut last_scan_start = 0;
    let mut mount: Option<Mount> = None;
    let mut front_offset: Option<f64> = None;
    // The pose an ODOM line restarted the dead reckoning at, until the next ODOM line taken.
    let mut reset: Option<Pose> = None;
    let mut resets = 0usize;
    for (n, line) in text.lines().enumerate() {
        if n >= MAX_LINES {
            return Err(LogError::TooManyLines {
                origin: origin.to_string(),
                limit: MAX_LINES,
            });
        }
        let number = n + 1;
        if line.len() > MAX_LINE_BYTES {
            malformed.add(number, || format!("longer than {MAX_LINE_BYTES} bytes"));
            continue;
        }
        let mut fields = Fields {
            it: line.split_whitespace(),
        };
        let Some(name) = fields.it.next() else {
            continue;
        };
        if name.starts_with('#') {
            continue;
        }
        let scan_start = lidar.len();
        let read = match name {
            "FLASER" => read_flaser(&mut fields, options, revs, &mut lidar),
            "ROBOTLASER1" => read_robotlaser(&mut fields, options, revs, &mut lidar),
            "ODOM" => (|| {
                let pose = fields.pose("pose")?;
                for what in ["tv", "rv", "accel"] {
                    fields.number(what)?;
                }
                let t = fields.tail(options.clock)?;
                Ok(Read::Odom(Stamped {
                    t,
                    pose,
                    from: None,
                }))
            })(),
            "TRUEPOS" => (|| {
                let pose = fields.pose("true pose")?;
                fields.pose("odometry pose")?;
                let t = fields.tail(options.clock)?;
                Ok(Read::True(Stamped {
                    t,
                    pose,
                    from: None,
                }))
            })(),
            "PARAM" => {
                if fields.it.next() == Some("robot_frontlaser_offset") {
                    match fields.number("value") {
                        Ok(v) => front_offset = front_offset.or(Some(v)),
                        Err(e) => malformed.add(number, || format!("PARAM {e}")),
                    }
                }
                Ok(Read::Nothing)
            }
            "SYNC" => Ok(Read::Nothing),
            _ => {
                if unknown.len() < MAX_UNKNOWN_NAMES || unknown.contains_key(name) {
                    unknown
                        .entry(short(name))
                        .or_default()
                        .add(number, String::new);
                } else {
                    unknown_other.add(number, String::new);
                }
                Ok(Read::Nothing)
            }
        };
        let read = match read {
            Ok(r) => r,
            Err(e) => {
                lidar.truncate(scan_start);
                malformed.add(number, || format!("{name} {e}"));
                continue;
            }
        };
        let t = match &read {
            Read::Scan { t, .. } => *t,
            Read::Odom(s) | Read::True(s) => s.t,
            Read::Nothing => continue,
        };
        // The log's own time until the end, when time 0 becomes the earliest line taken.
        let t_s = t;
        match read {
            Read::Scan { pose, mount: m, .. } => {
                match scans.take(t_s, number) {
                    Take::No => {
                        lidar.truncate(scan_start);
                        continue;
                    }
                    Take::InsteadOfLast => {
                        // The last scan's readings go; this one's move down to its place.
                        lidar.drain(last_scan_start..scan_start);
                        poses.pop();
                        revs -= 1;
                    }
                    Take::Yes => last_scan_start = scan_start,
                }
                for s in &mut lidar[last_scan_start..] {
                    s.t_s = t_s;
                    s.rev = revs;
                }
                revs += 1;
                mount = mount.or(m);
                poses.push(Stamped {
                    t: t_s,
                    pose,
                    from: None,
                });
            }
            // A corrected log's odometry restarts at each scan's corrected pose (an ODOM line
            // with the scan's very pose, stamped 0 in the Radish logs): the jump to it is the
            // SLAM's correction, not the wheels' travel.
            Read::Odom(s) if poses.last().is_some_and(|p| p.pose == s.pose) => {
                reset = Some(s.pose);
                resets += 1;
            }
            Read::Odom(s) => {
                let stamped = Stamped { from: reset, ..s };
                if put(&mut odom_stream, &mut odoms, stamped, number) {
                    reset = None;
                }
            }
            Read::True(s) => {
                put(&mut truth_stream, &mut truths, s, number);
            }
            Read::Nothing => {}
        }
    }
    if revs == 0 && odoms.is_empty() && truths.is_empty() {
        return Err(LogError::Empty {
            origin: origin.to_string(),
            message: "no scan (FLASER, ROBOTLASER1) and no pose (ODOM, TRUEPOS)".to_string(),
        });
    }

    let t0 = [
        lidar.first().map(|s| s.t_s),
        odoms.first().map(|s| s.t),
        truths.first().map(|s| s.t),
    ]
    .into_iter()
    .flatten()
    .fold(f64::INFINITY, f64::min);
    for s in &mut lidar {
        s.t_s -= t0;
    }
    for s in poses.iter_mut().chain(&mut odoms).chain(&mut truths) {
        s.t -= t0;
    }

    let mut notes = Vec::new();
    for (stream, what) in [
        (&scans, "scan"),
        (&odom_stream, "ODOM"),
        (&truth_stream, "TRUEPOS"),
    ] {
        if stream.back.count > 0 {
            notes.push(format!(
                "{origin}: {} {what} line(s) out of time order, skipped (of two lines out of \
                 order the later-stamped one; stamps up to {:.3} s back; the first at line {})",
                stream.back.count, stream.most_back_s, stream.back.first_line
            ));
        }
    }
    if malformed.count > 0 {
        notes.push(format!(
            "{origin}: {} line(s) of a known kind could not be read: skipped (the first at line \
             {}: {})",
            malformed.count, malformed.first_line, malformed.first_reason
        ));
    }
    if !unknown.is_empty() {
        let mut list = String::new();
        for (name, s) in &unknown {
            let _ = write!(
                list,
                "{}{name} ×{} (first at line {})",
                if list.is_empty() { "" } else { ", " },
                s.count,
                s.first_line
            );
        }
        if unknown_other.count > 0 {
            let _ = write!(list, ", {} more of other kinds", unknown_other.count);
        }
        notes.push(format!(
            "{origin}: lines of kinds not read, skipped: {list}"
        ));
    }

    let mount = mount.or(front_offset.map(|x_m| Mount {
        x_m,
        ..Mount::default()
    }));
    if mount.is_none() && revs > 0 {
        notes.push(format!(
            "{origin}: the log does not give the laser's mount (no ROBOTLASER1, no PARAM \
             robot_frontlaser_offset): taken at the robot's centre"
        ));
    }
    let mut rec = Recording::new(Meta {
        robot: RobotMeta {
            wheel_base_m: options.wheel_base_m,
            wheel_radius_m: None,
        },
        lidar: (revs > 0).then(|| mount.unwrap_or_default()),
        ..Meta::default()
    });
    if revs > 0 {
        rec.lidar = Some(lidar);
    }
    let table = |v: &[Stamped]| -> Vec<TruthSample> {
        v.iter()
            .map(|s| TruthSample {
                t_s: s.t,
                x_m: s.pose.x,
                y_m: s.pose.y,
                yaw_rad: s.pose.yaw,
            })
            .collect()
    };
    if resets > 0 && !odoms.is_empty() {
        notes.push(format!(
            "{origin}: {resets} ODOM line(s) restart the odometry at a scan line's pose (a \
             corrected log's, reset to each corrected pose): the jumps to them are corrections, \
             left out of the wheel travel"
        ));
    }
    let mut odometry = |v: &[Stamped], what: &str| -> Vec<OdometrySample> {
        let (odometry, sideways_m) = wheel_travel(v, options.wheel_base_m);
        // A millimetre: below the poses' printed precision in CARMEN logs.
        if sideways_m > 1e-3 {
            notes.push(format!(
                "{origin}: the {what} poses move sideways, which wheels cannot: up to \
                 {sideways_m:.3} m between two poses, left out of the wheel travel"
            ));
        }
        odometry
    };
    let odometry = match options.poses {
        Poses::Truth => (!odoms.is_empty()).then(|| odometry(&odoms, "ODOM")),
        Poses::Odometry if !odoms.is_empty() => Some(odometry(&odoms, "ODOM")),
        Poses::Odometry => (!poses.is_empty()).then(|| odometry(&poses, "scan lines'")),
    };
    rec.odometry = odometry;
    if !truths.is_empty() {
        if options.poses == Poses::Truth && !poses.is_empty() {
            notes.push(format!(
                "{origin}: the truth is the TRUEPOS lines'; the {} poses of the scan lines are \
                 not used",
                poses.len()
            ));
        }
        rec.truth = Some(table(&truths));
    } else if options.poses == Poses::Truth && !poses.is_empty() {
        rec.truth = Some(table(&poses));
    }
    Ok((rec, notes))
}

/// Puts `pose` into `stream`'s table, or not: whether it was put. One put instead of the last
/// keeps the last one's restart.
fn put(stream: &mut Stream, table: &mut Vec<Stamped>, pose: Stamped, line: usize) -> bool {
    let mut pose = pose;
    match stream.take(pose.t, line) {
        Take::No => return false,
        Take::InsteadOfLast => {
            let dropped = table.pop();
            pose.from = pose.from.or(dropped.and_then(|d| d.from));
        }
        Take::Yes => {}
    }
    table.push(pose);
    true
}

/// The wheel travel that [`Pose::drive`] turns back into `poses` (the inverse of dead
/// reckoning: each step's turn and its motion along the heading halfway through it), and the
/// largest sideways step it cannot express.
fn wheel_travel(poses: &[Stamped], wheel_base_m: f64) -> (Vec<OdometrySample>, f64) {
    let mut out = Vec::with_capacity(poses.len());
    let (mut left, mut right, mut sideways) = (0.0, 0.0, 0.0f64);
    let mut previous: Option<Pose> = None;
    for s in poses {
        if let Some(p) = s.from.or(previous) {
            let turn = wrap_angle(s.pose.yaw - p.yaw);
            let (sin, cos) = (p.yaw + turn / 2.0).sin_cos();
            let (dx, dy) = (s.pose.x - p.x, s.pose.y - p.y);
            let forward = dx * cos + dy * sin;
            sideways = sideways.max((dy * cos - dx * sin).abs());
            left += forward - turn * wheel_base_m / 2.0;
            right += forward + turn * wheel_base_m / 2.0;
        }
        previous = Some(s.pose);
        out.push(OdometrySample {
            t_s: s.t,
            left_m: left,
            right_m: right,
        });
    }
    (out, sideways)
}

/// A reading as a sample at `angle_deg` (any angle; wrapped into [0, 360)).
fn reading(rev: u64, angle_deg: f64, range_m: f64, max_range_m: f64) -> LidarSample {
    let invalid = range_m <= 0.0 || range_m >= max_range_m;
    LidarSample {
        t_s: 0.0,
        rev,
        angle_deg: angle_deg.rem_euclid(360.0),
        range_m: if invalid { 0.0 } else { range_m },
        strength: 0,
        invalid,
        warning: false,
        true_range_m: None,
    }
}

fn read_flaser(
    f: &mut Fields,
    options: &CarmenOptions,
    rev: u64,
    lidar: &mut Vec<LidarSample>,
) -> Result<Read, String> {
    let n = f.count("number of ranges")?;
    if n == 0 {
        return Err("has no range".to_string());
    }
    let fov = options.flaser_fov_deg;
    // An odd count spans the whole field (181 beams 1° apart over 180°), an even one a step
    // short of it (180 beams, 1° apart, the last at +89°).
    let step = if n % 2 == 1 && n > 1 {
        fov / (n - 1) as f64
    } else {
        fov / n as f64
    };
    for i in 0..n {
        let r = f.number("range")?;
        lidar.push(reading(
            rev,
            -fov / 2.0 + step * i as f64,
            r,
            options.max_range_m,
        ));
    }
    let pose = f.pose("pose")?;
    let odom = f.pose("odometry pose")?;
    let t = f.tail(options.clock)?;
    Ok(Read::Scan {
        t,
        pose: match options.poses {
            Poses::Truth => pose,
            Poses::Odometry => odom,
        },
        mount: None,
    })
}

fn read_robotlaser(
    f: &mut Fields,
    options: &CarmenOptions,
    rev: u64,
    lidar: &mut Vec<LidarSample>,
) -> Result<Read, String> {
    f.word("laser_type")?;
    let start = f.number("start_angle")?;
    f.number("field of view")?;
    let resolution = f.number("angular_resolution")?;
    let max_range = f.number("maximum_range")?;
    f.number("accuracy")?;
    f.word("remission_mode")?;
    let n = f.count("number of ranges")?;
    if n == 0 {
        return Err("has no range".to_string());
    }
    // The laser's own maximum when it gives one, else the option's.
    let max_range_m = if max_range > 0.0 {
        max_range.min(options.max_range_m)
    } else {
        options.max_range_m
    };
    for i in 0..n {
        let r = f.number("range")?;
        let angle = (start + resolution * i as f64).to_degrees();
        lidar.push(reading(rev, angle, r, max_range_m));
    }
    let m = f.count("number of remissions")?;
    for _ in 0..m {
        f.number("remission")?;
    }
    let laser = f.pose("laser pose")?;
    let robot = f.pose("robot pose")?;
    for what in ["tv", "rv", "forward_safety_dist", "side_safety_dist"] {
        f.number(what)?;
    }
    // turn_axis came later in CARMEN's history: a line may or may not carry it, so the tail is
    // the last three fields.
    let mut rest = [""; 4];
    let mut k = 0;
    for w in f.it.by_ref() {
        if k == rest.len() {
            return Err("has more than 4 fields after its safety distances".to_string());
        }
        rest[k] = w;
        k += 1;
    }
    if k < 3 {
        return Err(format!(
            "has {k} fields after its safety distances, expected 3 or 4"
        ));
    }
    let t = stamp(rest[k - 3], rest[k - 1], options.clock)?;
    let relative = laser.relative_to(&robot);
    Ok(Read::Scan {
        t,
        pose: robot,
        mount: Some(Mount {
            x_m: relative.x,
            y_m: relative.y,
            yaw_deg: relative.yaw.to_degrees(),
        }),
    })
}
