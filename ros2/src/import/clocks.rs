//! Time: the recording's t = 0 (an export's own start, else the earliest stamp among the
//! first messages), the stamps' clock against the log clock, and each table's rows kept in
//! time order to the microsecond. Apart from the conversions because every message's time goes
//! through the same rules, whatever its type.

use std::collections::HashMap;
use std::path::Path;

use hilsim_recording::round_half_away;

use super::wire::{decode_as, Encoding};
use super::Converter;
use crate::bag::{self, Item};
use crate::cdr::decode;
use crate::msgs::{Header, TfMessage, Time};
use crate::ros1;
use crate::topics::{Chosen, Kind, Role};
use crate::Error;

/// The metadata record an exported file starts with: its `start_ns` is the recording's t = 0,
/// so that importing an export gives back the recording's times even when no message is at 0.
pub(crate) const START_METADATA: &str = "hilsim";
/// The key of the recording's t = 0 (nanoseconds, as the messages' stamps).
pub(crate) const START_KEY: &str = "start_ns";
/// The keys of the wheel travel at the first odometry row (an `Odometry` pose starts from
/// nothing; a recording's encoders may not).
pub(crate) const ODOMETRY_START_KEYS: [&str; 2] = ["odometry_left_m", "odometry_right_m"];

/// Above this difference between a stamp and its log time the two come from different clocks
/// (simulated time against the recorder's wall clock): unstamped messages (`Twist`) are then
/// put on the stamps' clock. Below it, the difference is transport delay and is left alone.
const OTHER_CLOCK_NS: i64 = 60_000_000_000;

/// The stamp of a message of `kind`: its header's, or a TF message's first transform's.
fn first_stamp(kind: Kind, encoding: Encoding, data: &[u8]) -> Option<Time> {
    match (kind, encoding) {
        (Kind::Tf, _) => decode_as::<TfMessage>(encoding, data, 0)
            .ok()?
            .transforms
            .first()
            .map(|t| t.header.stamp),
        (_, Encoding::Cdr) => decode::<Header>(data).ok().map(|h| h.stamp),
        (_, Encoding::Ros1) => ros1::decode_prefix::<Header>(data).ok().map(|h| h.stamp),
    }
}

/// How far into a bag (log time) the earliest message is looked for: a scan's stamp is its first
/// reading's, logged a revolution or more later, after other topics' messages.
const EARLIEST_WITHIN_NS: i64 = 10_000_000_000;

/// The earliest stamped and unstamped times among the first messages of the chosen topics, and
/// the stamps' clock against the log clock (see [`earliest_time`]).
#[derive(Default)]
struct Earliest {
    stamped: Option<i64>,
    unstamped: Option<i64>,
    first_log: Option<i64>,
    offset: Option<i64>,
}

impl Earliest {
    /// Sees a message of `kind` logged at `log_ns`; `false` once past the window.
    fn see(&mut self, kind: Kind, encoding: Encoding, log_ns: i64, data: &[u8]) -> bool {
        let first = *self.first_log.get_or_insert(log_ns);
        if log_ns.saturating_sub(first) > EARLIEST_WITHIN_NS {
            return false;
        }
        if kind == Kind::Twist {
            self.unstamped = Some(self.unstamped.map_or(log_ns, |t| t.min(log_ns)));
        } else if let Some(stamp) = first_stamp(kind, encoding, data).filter(|s| !s.is_zero()) {
            let ns = stamp.ns();
            self.stamped = Some(self.stamped.map_or(ns, |t| t.min(ns)));
            self.offset.get_or_insert(clock_offset(ns, log_ns));
        }
        true
    }

    /// The recording's t = 0 and the clock offset.
    fn result(&self) -> (Option<i64>, Option<i64>) {
        let t0 = match (self.stamped, self.unstamped) {
            // Unstamped messages count when they are on the stamps' clock.
            (Some(s), Some(u)) if (s - u).abs() <= OTHER_CLOCK_NS => Some(s.min(u)),
            (Some(s), _) => Some(s),
            (None, u) => u,
        };
        (t0, self.offset)
    }
}

/// The recording's t = 0: an export's own start, else the earliest time among the first messages
/// of the chosen topics (each topic's first within the bag's first 10 s of log time): its header
/// stamp, or the log time of an unstamped one on the same clock. `None` when none is found
/// (the first message converted then sets it).
///
/// With it, the stamps' clock minus the log clock, as the first stamped message says (see
/// [`Converter::stamped`]): known before the first message is converted, a message stamped zero
/// at a simulator's start (time 0, or no stamp at all) is put on the stamps' clock too, not at
/// its wall-clock log time.
///
/// # Errors
/// As [`bag::stream`].
pub(super) fn earliest_time(
    file: &Path,
    chosen: &Chosen,
) -> Result<(Option<i64>, Option<i64>), Error> {
    let mut roles: HashMap<u16, Kind> = HashMap::new();
    let mut earliest = Earliest::default();
    let mut start = None;
    bag::stream_while(file, |item| {
        match item {
            Item::Channel(c) => {
                if let Some((_, kind)) = chosen.values().find(|(topic, _)| *topic == c.topic) {
                    roles.insert(c.id, *kind);
                }
            }
            Item::Metadata(m) if m.name == START_METADATA => {
                start = m
                    .metadata
                    .get(START_KEY)
                    .and_then(|v| v.parse::<i64>().ok());
                return Ok(start.is_none());
            }
            Item::Metadata(_) => {}
            Item::Message {
                channel_id,
                log_time,
                data,
            } => {
                let log_ns = i64::try_from(log_time).unwrap_or(i64::MAX);
                return Ok(match roles.get(&channel_id) {
                    Some(kind) => earliest.see(*kind, Encoding::Cdr, log_ns, data),
                    None => {
                        log_ns.saturating_sub(*earliest.first_log.get_or_insert(log_ns))
                            <= EARLIEST_WITHIN_NS
                    }
                });
            }
        }
        Ok(true)
    })?;
    if start.is_some() {
        return Ok((start, None));
    }
    Ok(earliest.result())
}

/// [`earliest_time`] of a ROS 1 bag (which has no export's start).
///
/// # Errors
/// Not a ROS 1 bag.
pub(super) fn ros1_earliest_time(
    file: &Path,
    connections: &[ros1::Connection],
    chosen: &Chosen,
) -> Result<(Option<i64>, Option<i64>), Error> {
    let kind_of = |topic: &str| {
        chosen
            .values()
            .find(|(t, _)| t == topic)
            .map(|(_, kind)| *kind)
    };
    let mut kinds: HashMap<u32, Kind> = connections
        .iter()
        .filter_map(|c| Some((c.id, kind_of(&c.topic)?)))
        .collect();
    let mut earliest = Earliest::default();
    ros1::stream_while(file, |item| {
        Ok(match item {
            ros1::Item::Connection(c) => {
                if let Some(kind) = kind_of(&c.topic) {
                    kinds.insert(c.id, kind);
                }
                true
            }
            ros1::Item::Message {
                conn,
                time_ns,
                data,
            } => match kinds.get(&conn) {
                Some(kind) => earliest.see(*kind, Encoding::Ros1, time_ns, data),
                None => {
                    time_ns.saturating_sub(*earliest.first_log.get_or_insert(time_ns))
                        <= EARLIEST_WITHIN_NS
                }
            },
        })
    })?;
    Ok(earliest.result())
}

/// The stamps' clock minus the log clock from a message's stamp and log time: the difference
/// when it says the two are different clocks, else 0 (transport delay is left alone).
fn clock_offset(stamp_ns: i64, log_ns: i64) -> i64 {
    let offset = stamp_ns - log_ns;
    if offset.abs() > OTHER_CLOCK_NS {
        offset
    } else {
        0
    }
}

/// A table's time order: the latest time written, and the rows that came earlier than it.
#[derive(Default)]
pub(super) struct TableClock {
    last_us: u64,
    pub(super) reordered: u64,
    pub(super) worst_us: u64,
}

impl TableClock {
    /// `t_us`, or the latest time written when `t_us` is earlier (counted; a time before
    /// t = 0 is put at 0).
    pub(super) fn order(&mut self, t_us: i64) -> u64 {
        match u64::try_from(t_us) {
            Ok(t) if t >= self.last_us => {
                self.last_us = t;
                t
            }
            _ => {
                self.reordered += 1;
                let early = i128::from(self.last_us) - i128::from(t_us);
                self.worst_us = self.worst_us.max(u64::try_from(early).unwrap_or(u64::MAX));
                self.last_us
            }
        }
    }
}

/// Microseconds of `ns` plus `extra_ns`, to the nearest (the difference from t = 0 taken in
/// integers first, as a stamp, ~1.7e18 ns, is finer than an f64 resolves).
pub(super) fn microseconds(ns_from_start: i64, extra_ns: f64) -> i64 {
    round_half_away((ns_from_start as f64 + extra_ns) / 1e3) as i64
}

/// Seconds of a whole number of microseconds: the `f64` closest to the decimal.
pub(super) fn seconds_of(us: u64) -> f64 {
    us as f64 / 1e6
}

impl Converter {
    /// The time of a stamped message on the stamps' clock (a zero stamp, which a driver that
    /// sets none leaves, is replaced by the log time).
    pub(super) fn stamped(&mut self, stamp: Time, log_ns: i64) -> i64 {
        if stamp.is_zero() {
            return log_ns + self.clock_offset_ns.unwrap_or(0);
        }
        let ns = stamp.ns();
        if self.clock_offset_ns.is_none() {
            let offset = clock_offset(ns, log_ns);
            self.clock_offset_ns = Some(offset);
            let first_pending = self.pending_commands.first().map(|(log, _)| log + offset);
            if self.t0_ns.is_none() {
                self.t0_ns = Some(first_pending.map_or(ns, |p| p.min(ns)));
            }
        }
        ns
    }

    /// Seconds from t = 0, to the microsecond (what a recording keeps: `0.15`, not
    /// `0.15000000000000002`; far below any sensor's timing), in the table's order.
    /// `ns` on the stamps' clock plus `extra_ns` (a reading's offset within its scan): the
    /// difference from t = 0 is taken in integers first, as a stamp (~1.7e18 ns) is finer than
    /// an f64 resolves.
    pub(super) fn seconds(&mut self, role: Role, ns: i64, extra_ns: f64) -> f64 {
        let t0 = *self.t0_ns.get_or_insert(ns);
        let t_us = microseconds(ns - t0, extra_ns);
        seconds_of(self.clocks.entry(role).or_default().order(t_us))
    }
}
