//! The CoreSLAM data set's `.dat` logs (Steux and El Hamzaoui, ICARCV 2010; `exp1.dat` as
//! shipped with BreezySLAM's examples): a wheeled rover with a Hokuyo URG-04LX.
//!
//! The log's conventions, and where each comes from:
//! - a line is one scan: timestamp (µs), a field, the left and right encoder counts, 20 more
//!   fields, then the ranges (mm) of the 682 beams (BreezySLAM's `examples/mines.py` reads the
//!   same fields; any field after them is ignored, as it does);
//! - the counts are cumulative, positive forward on both wheels, 2000 a wheel turn (the
//!   authors' nominal value: BreezySLAM converts ticks to degrees by 180/2000 and then uses
//!   `r·(φl + φr)` and `(r / half axle)·(φr − φl)`, each twice the usual form, which together
//!   amount to 2000 ticks a turn); they do not wrap in this log, and a jump larger than a wheel
//!   could turn is an error;
//! - the beams run counter-clockwise seen from above, the first one on the right (SCIP 2.0,
//!   Hokuyo C-42-03320B, section 5: the URG-04LX turns anti-clockwise; its steps 44 to 725 of
//!   1024 a revolution are the 682 beams, step 384 straight ahead);
//! - readings under 20 mm are the sensor's error codes and 0 is no return (same section): both
//!   invalid;
//! - the beams are taken one step (100 ms / 1024, the URG-04LX's 600 rpm) apart in time, the
//!   first at the line's timestamp. The log does not say when its timestamp was taken relative
//!   to the encoder counts on the line (the odometry calibration can estimate that latency).
//!
//! The format has no room for a bad line that could be skipped safely (the counts are
//! cumulative, the scans one a line): a line that cannot be read is an error naming it.

use std::f64::consts::TAU;

use hilsim_recording::{LidarSample, Meta, Mount, OdometrySample, Recording, RobotMeta};

use crate::LogError;

/// Fields before the ranges: timestamp, one field, two encoder counts, 20 more.
const HEADER_FIELDS: usize = 24;
/// Beams of a scan (the URG-04LX's steps 44 to 725; SCIP 2.0, C-42-03320B, table 2).
pub const BEAMS: usize = 682;
/// The first beam's step and the step straight ahead (same table).
const FIRST_STEP: f64 = 44.0;
const FRONT_STEP: f64 = 384.0;
/// Steps in a revolution (same table: slit division 1024).
const STEPS_PER_TURN: f64 = 1024.0;
/// A revolution takes 100 ms (same table's PP example: 600 rpm).
const REVOLUTION_S: f64 = 0.1;
/// Readings under 20 mm are error codes (section 5, table 3; the PP example's DMIN 20).
const MIN_RANGE_MM: i64 = 20;
/// Fastest a wheel may turn between two scans before a jump of its count is taken for a wrap
/// or a corrupt field: 10 turns a second, 4.8 m/s on the data set's wheels, four times the
/// fastest stretch of `exp1.dat`.
const MAX_TURNS_PER_S: f64 = 10.0;
/// The most lines a log may hold: 10⁶ scans of 682 beams is about 40 GB of samples in memory,
/// already more than a reader should hold; the data set's logs have under 2,000.
pub const MAX_LINES: usize = 1_000_000;

/// The robot's nominal geometry, and how to read the beams.
#[derive(Debug, Clone, PartialEq)]
pub struct CoreSlamOptions {
    /// Wheel radius, metres (the data set's: 77 mm, as BreezySLAM's `mines.py` gives it).
    pub wheel_radius_m: f64,
    /// Distance between the wheels, metres (the data set's half axle 165 mm, doubled).
    pub wheel_base_m: f64,
    /// Encoder ticks a wheel turn (the data set's 2000).
    pub ticks_per_turn: f64,
    /// The lidar's forward offset from the axle, metres (the data set's 145 mm).
    pub lidar_x_m: f64,
    /// Read the beams clockwise, the first at +120° (wrong for the URG-04LX: a check of the
    /// convention, which a scan matcher then contradicts).
    pub first_beam_left: bool,
}

impl Default for CoreSlamOptions {
    fn default() -> Self {
        Self {
            wheel_radius_m: 0.077,
            wheel_base_m: 0.33,
            ticks_per_turn: 2000.0,
            lidar_x_m: 0.145,
            first_beam_left: false,
        }
    }
}

impl CoreSlamOptions {
    fn validate(&self) -> Result<(), LogError> {
        let positive = |name, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(LogError::Option {
                    name,
                    message: format!("{v} is not a positive number"),
                })
            }
        };
        positive("wheel_radius_m", self.wheel_radius_m)?;
        positive("wheel_base_m", self.wheel_base_m)?;
        positive("ticks_per_turn", self.ticks_per_turn)?;
        if !self.lidar_x_m.is_finite() {
            return Err(LogError::Option {
                name: "lidar_x_m",
                message: format!("{} is not a number", self.lidar_x_m),
            });
        }
        Ok(())
    }
}

/// One line of the log.
struct Scan {
    t_us: u64,
    ticks: [i64; 2],
}

/// The recording of a CoreSLAM `.dat` log's `text` (`origin` names it in errors): the
/// encoders' travel over the nominal radius in `odometry.csv`, one revolution a line in
/// `lidar.csv`, its beams a step apart in time; time 0 is the first line's timestamp.
///
/// # Errors
/// A line that cannot be read (the error names it and what was expected), timestamps that do
/// not increase, an encoder count that jumps more than a wheel could turn, fewer than two
/// scans, more than [`MAX_LINES`] lines, or options out of range.
pub fn read_coreslam(
    text: &str,
    origin: &str,
    options: &CoreSlamOptions,
) -> Result<Recording, LogError> {
    options.validate()?;
    let metres_per_tick = TAU * options.wheel_radius_m / options.ticks_per_turn;
    let step_deg = 360.0 / STEPS_PER_TURN;
    let step_s = REVOLUTION_S / STEPS_PER_TURN;
    let mut first: Option<Scan> = None;
    let mut last: Option<Scan> = None;
    let mut odometry = Vec::new();
    let mut lidar = Vec::new();
    let mut fields: Vec<&str> = Vec::with_capacity(HEADER_FIELDS + BEAMS);
    for (n, line) in text.lines().enumerate() {
        if n >= MAX_LINES {
            return Err(LogError::TooManyLines {
                origin: origin.to_string(),
                limit: MAX_LINES,
            });
        }
        let bad = |message: String| LogError::Line {
            origin: origin.to_string(),
            line: n + 1,
            message,
        };
        fields.clear();
        // Only the fields read: a line with more is read as BreezySLAM reads it.
        fields.extend(line.split_whitespace().take(HEADER_FIELDS + BEAMS));
        if fields.is_empty() {
            continue;
        }
        if fields.len() < HEADER_FIELDS + BEAMS {
            return Err(bad(format!(
                "{} fields, expected at least {} (timestamp, a field, two encoder \
                 counts, 20 more fields, {BEAMS} ranges)",
                fields.len(),
                HEADER_FIELDS + BEAMS
            )));
        }
        let t_us: u64 = fields[0]
            .parse()
            .map_err(|_| bad(format!("the timestamp `{}` is not microseconds", fields[0])))?;
        let count = |i: usize, wheel: &str| -> Result<i64, LogError> {
            fields[i].parse().map_err(|_| {
                bad(format!(
                    "the {wheel} encoder count `{}` is not an integer",
                    fields[i]
                ))
            })
        };
        let ticks = [count(2, "left")?, count(3, "right")?];
        if let Some(last) = &last {
            if t_us <= last.t_us {
                return Err(bad(format!(
                    "the timestamp {t_us} µs does not follow the previous scan's {} µs",
                    last.t_us
                )));
            }
            let dt_s = (t_us - last.t_us) as f64 * 1e-6;
            // At least a revolution's time: two lines a few milliseconds apart may carry
            // counts read a revolution apart.
            let most = MAX_TURNS_PER_S * options.ticks_per_turn * dt_s.max(REVOLUTION_S);
            for (k, wheel) in ["left", "right"].iter().enumerate() {
                let step = ticks[k].saturating_sub(last.ticks[k]);
                if step.unsigned_abs() as f64 > most {
                    return Err(bad(format!(
                        "the {wheel} encoder count jumped by {step} ticks in {dt_s:.3} s, \
                         more than {MAX_TURNS_PER_S} wheel turns a second: a wrapped or corrupt \
                         count"
                    )));
                }
            }
        }
        let (t0, ticks0) = match &first {
            Some(f) => (f.t_us, f.ticks),
            None => (t_us, ticks),
        };
        let rev = odometry.len() as u64;
        let t_s = (t_us - t0) as f64 * 1e-6;
        // The stamps jitter by more than a scan's 67 ms span takes (one scan stamped 61 ms after
        // the one before): a scan's readings start no earlier than the previous scan's end, so
        // that time runs forward through the lidar's table.
        let readings_from_s = lidar
            .last()
            .map_or(t_s, |previous: &LidarSample| t_s.max(previous.t_s + step_s));
        let scan_start = lidar.len();
        for (i, f) in fields[HEADER_FIELDS..].iter().enumerate() {
            let mm: i64 = f
                .parse()
                .map_err(|_| bad(format!("beam {i}'s range `{f}` is not millimetres")))?;
            let from_front = (FIRST_STEP + i as f64 - FRONT_STEP) * step_deg;
            let angle = if options.first_beam_left {
                -from_front
            } else {
                from_front
            };
            let invalid = mm < MIN_RANGE_MM;
            lidar.push(LidarSample {
                // To the microsecond, as a recording's times are.
                t_s: ((readings_from_s + i as f64 * step_s) * 1e6).round() / 1e6,
                rev,
                angle_deg: angle.rem_euclid(360.0),
                range_m: if invalid { 0.0 } else { mm as f64 * 1e-3 },
                strength: 0,
                invalid,
                warning: false,
                true_range_m: None,
            });
        }
        debug_assert_eq!(lidar.len() - scan_start, BEAMS);
        odometry.push(OdometrySample {
            t_s,
            left_m: ticks[0].saturating_sub(ticks0[0]) as f64 * metres_per_tick,
            right_m: ticks[1].saturating_sub(ticks0[1]) as f64 * metres_per_tick,
        });
        if first.is_none() {
            first = Some(Scan { t_us, ticks });
        }
        last = Some(Scan { t_us, ticks });
    }
    if odometry.len() < 2 {
        return Err(LogError::Empty {
            origin: origin.to_string(),
            message: "fewer than two scans".to_string(),
        });
    }
    let mut rec = Recording::new(Meta {
        robot: RobotMeta {
            wheel_base_m: options.wheel_base_m,
            wheel_radius_m: Some(options.wheel_radius_m),
        },
        lidar: Some(Mount {
            x_m: options.lidar_x_m,
            y_m: 0.0,
            yaw_deg: 0.0,
        }),
        ..Meta::default()
    });
    rec.odometry = Some(odometry);
    rec.lidar = Some(lidar);
    Ok(rec)
}
