//! The host's side: SCIP 2.0 replies into readings, as a driver reads them.

use super::commands::number;
use super::encoding::{checksum, decode, step_angle_deg, MAX_STEP, MIN_DISTANCE_MM};
use crate::{DecodeStats, HostDecoder, Point};

/// The longest line kept: a data line is 66 bytes with its check character and LF, an
/// information line well under 100; a longer one is damage and is skipped.
const MAX_LINE: usize = 128;
/// The most bytes one reply may hold: a whole `MD` scan of steps 0–768 is about 2,400.
const MAX_REPLY: usize = 4096;

/// Reads a URG-04LX's SCIP 2.0 replies: every `MD`/`MS`/`GD`/`GS` scan reply into its points,
/// every other well-formed reply counted and passed over.
///
/// A reply is its lines up to the empty line that ends it; one whose status or data check
/// characters disagree is dropped whole (counted in `bad_checksum`), one that is no reply at
/// all is skipped. The points of a scan are emitted when its reply ends, so feeding byte by
/// byte or in chunks gives the same result.
#[derive(Debug, Clone, Default)]
pub struct ScipDecoder {
    /// The reply being read, its lines each ending in LF.
    reply: Vec<u8>,
    /// Where the line being read starts in `reply`.
    line_start: usize,
    /// The reply ran past its bounds: skip up to its end.
    discarding: bool,
    /// While discarding: whether the last byte was an LF.
    prev_lf: bool,
    stats: DecodeStats,
}

impl ScipDecoder {
    /// A decoder that has seen nothing.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Bytes held, waiting for the end of their reply.
    #[must_use]
    pub fn pending_len(&self) -> usize {
        self.reply.len()
    }

    fn push(&mut self, byte: u8, out: &mut Vec<Point>) {
        self.stats.bytes += 1;
        if self.discarding {
            // Skipping a damaged reply up to the empty line that ends it.
            self.stats.skipped_bytes += 1;
            if byte == b'\n' && self.prev_lf {
                self.discarding = false;
            }
            self.prev_lf = byte == b'\n';
            return;
        }
        self.reply.push(byte);
        if byte != b'\n' {
            let too_long = self.reply.len() - self.line_start > MAX_LINE;
            if too_long || self.reply.len() > MAX_REPLY {
                self.stats.skipped_bytes += self.reply.len() as u64;
                self.reply.clear();
                self.line_start = 0;
                self.discarding = true;
                self.prev_lf = false;
            }
            return;
        }
        if self.reply.len() - self.line_start > 1 {
            self.line_start = self.reply.len();
            return;
        }
        // An empty line: the reply is complete.
        let reply = std::mem::take(&mut self.reply);
        // Lines of damage or garbage run into the reply that follows them: a reply may start
        // at any of its lines, the ones before it skipped.
        let mut start = 0;
        loop {
            match parse_reply(&reply[start..], out) {
                Verdict::Accepted => {
                    self.stats.packets += 1;
                    self.stats.skipped_bytes += start as u64;
                }
                Verdict::BadChecksum => {
                    self.stats.bad_checksum += 1;
                    self.stats.skipped_bytes += reply.len() as u64;
                }
                Verdict::NoReply => match reply[start..].iter().position(|&b| b == b'\n') {
                    Some(at) if start + at + 2 < reply.len() => {
                        start += at + 1;
                        continue;
                    }
                    _ => self.stats.skipped_bytes += reply.len() as u64,
                },
            }
            break;
        }
        self.reply = reply;
        self.reply.clear();
        self.line_start = 0;
    }
}

impl HostDecoder for ScipDecoder {
    fn feed(&mut self, bytes: &[u8], out: &mut Vec<Point>) {
        for &byte in bytes {
            self.push(byte, out);
        }
    }

    fn stats(&self) -> DecodeStats {
        self.stats
    }
}

enum Verdict {
    Accepted,
    BadChecksum,
    NoReply,
}

/// The parameters a scan reply's echo carries.
struct Echo {
    two_char: bool,
    continuous: bool,
    start: u16,
    end: u16,
    cluster: u16,
}

fn parse_echo(echo: &[u8]) -> Option<Echo> {
    let params = echo.split(|&b| b == b';').next()?;
    let (continuous, len) = match params.first()? {
        b'M' => (true, 15),
        b'G' => (false, 12),
        _ => return None,
    };
    let two_char = match params.get(1)? {
        b'S' => true,
        b'D' => false,
        _ => return None,
    };
    if params.len() != len {
        return None;
    }
    let start = number(&params[2..6])?;
    let end = number(&params[6..10])?;
    let cluster = number(&params[10..12])?.max(1);
    if continuous {
        number(&params[12..15])?;
    }
    (start <= end && end <= u32::from(MAX_STEP)).then_some(Echo {
        two_char,
        continuous,
        start: start as u16,
        end: end as u16,
        cluster: cluster as u16,
    })
}

/// Checks one reply (its lines, the last empty) and appends a scan reply's points.
fn parse_reply(reply: &[u8], out: &mut Vec<Point>) -> Verdict {
    // The last two bytes are the LFs ending the last line and the empty line.
    let mut lines = reply[..reply.len().saturating_sub(2)].split(|&b| b == b'\n');
    let (Some(echo), Some(status)) = (lines.next(), lines.next()) else {
        return Verdict::NoReply;
    };
    if echo.is_empty() || status.len() != 3 {
        return Verdict::NoReply;
    }
    if checksum(&status[..2]) != status[2] {
        return Verdict::BadChecksum;
    }
    let Some(scan) = parse_echo(echo) else {
        // Another command's reply: its information lines carry their own check characters.
        let info_ok = lines.all(|line| match line {
            [body @ .., b';', sum] => checksum(body) == *sum,
            [body @ .., sum] => checksum(body) == *sum,
            [] => false,
        });
        return if info_ok {
            Verdict::Accepted
        } else {
            Verdict::BadChecksum
        };
    };
    let data_status: &[u8] = if scan.continuous { b"99" } else { b"00" };
    if &status[..2] != data_status {
        // An acknowledgement or an error: no scan in it.
        return if lines.next().is_none() {
            Verdict::Accepted
        } else {
            Verdict::NoReply
        };
    }
    let Some(stamp) = lines.next() else {
        return Verdict::NoReply;
    };
    if stamp.len() != 5 {
        return Verdict::NoReply;
    }
    let Some((&sum, body)) = stamp.split_last() else {
        return Verdict::NoReply;
    };
    if checksum(body) != sum {
        return Verdict::BadChecksum;
    }
    let mut data = Vec::new();
    for line in lines {
        let Some((&sum, body)) = line.split_last() else {
            return Verdict::NoReply;
        };
        if checksum(body) != sum {
            return Verdict::BadChecksum;
        }
        data.extend_from_slice(body);
    }
    let chars = if scan.two_char { 2 } else { 3 };
    let values = usize::from((scan.end - scan.start) / scan.cluster + 1);
    if data.len() != values * chars {
        return Verdict::NoReply;
    }
    let mut points = Vec::with_capacity(values);
    for (i, field) in data.chunks(chars).enumerate() {
        let Some(value) = decode(field) else {
            return Verdict::NoReply;
        };
        // The cluster's first step names it, as hokuyolx's get_angles does.
        let step = scan.start + i as u16 * scan.cluster;
        points.push(Point {
            angle_deg: step_angle_deg(step),
            distance_mm: if value < MIN_DISTANCE_MM { 0 } else { value },
            intensity: 0,
            starts_revolution: i == 0,
            rev_hz: None,
        });
    }
    out.extend(points);
    Verdict::Accepted
}
