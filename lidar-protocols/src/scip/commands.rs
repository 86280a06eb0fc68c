//! The host's command lines, parsed as the URG-04LX parses them (SCIP 2.0 specification
//! sections 7–9): a two-character symbol, fixed-length parameters, an optional `;` and up to 16
//! string characters echoed back.

use super::encoding::MAX_STEP;

/// A reply's two status characters.
pub type Status = [u8; 2];

/// Normal.
pub const OK: Status = *b"00";
/// Command with insufficient parameters (specification section 9: parameters too short).
pub const SHORT_PARAMETERS: Status = *b"0C";
/// Parameters longer than the command takes (the specification's "undefined command 1").
pub const LONG_PARAMETERS: Status = *b"0D";
/// Undefined command (the specification's "undefined command 2"), also the answer to every
/// command but `TM` while the unit is in time-adjust mode.
pub const UNDEFINED: Status = *b"0E";
/// String characters longer than 16.
pub const STRING_TOO_LONG: Status = *b"0G";
/// String characters outside letters, digits, space and `._+@`.
pub const STRING_INVALID: Status = *b"0H";

/// The longest string the host may append after `;`.
pub const MAX_STRING_LEN: usize = 16;

/// One scan request: `MD`/`MS` (continuous) or `GD`/`GS` (one scan).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ScanRequest {
    /// `M` (continuous) rather than `G` (one scan).
    pub continuous: bool,
    /// `S`: two characters a value (12 bits) rather than `D`'s three (18 bits).
    pub two_char: bool,
    /// The first step.
    pub start: u16,
    /// The last step.
    pub end: u16,
    /// Steps merged into one value (0 and 1: none).
    pub cluster: u8,
    /// Scans skipped after each one sent (`M` only).
    pub interval: u8,
    /// Scans to send, 0 for until `QT` (`M` only).
    pub scans: u8,
}

impl ScanRequest {
    /// Steps merged into one value, at least 1.
    #[must_use]
    pub fn cluster_len(&self) -> u16 {
        u16::from(self.cluster.max(1))
    }

    /// Values in one scan reply.
    #[must_use]
    pub fn values(&self) -> usize {
        usize::from((self.end - self.start) / self.cluster_len() + 1)
    }

    /// Characters a value takes.
    #[must_use]
    pub fn chars(&self) -> usize {
        if self.two_char {
            2
        } else {
            3
        }
    }

    /// The largest value a field carries.
    #[must_use]
    pub fn field_max(&self) -> u32 {
        (1 << (6 * self.chars())) - 1
    }
}

/// A command the unit understood.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// `SCIP2.0`: switch from SCIP 1.1.
    Scip20,
    /// `VV`: version.
    Version,
    /// `PP`: parameters.
    Parameters,
    /// `II`: status.
    Status,
    /// `BM`: laser on.
    LaserOn,
    /// `QT`: laser off, measurement stopped.
    Quit,
    /// `RS`: reset.
    Reset,
    /// `TM` with its control code character.
    Time(u8),
    /// `SS` with its six bit-rate characters.
    BitRate([u8; 6]),
    /// `CR` with its two speed characters.
    MotorSpeed([u8; 2]),
    /// `MD`, `MS`, `GD`, `GS`.
    Scan(ScanRequest),
}

/// Parses one command line (its terminator removed): the command, or the status the unit
/// answers a malformed or unknown one with.
pub fn parse(line: &[u8]) -> Result<Command, Status> {
    if line == b"SCIP2.0" {
        return Ok(Command::Scip20);
    }
    if line.len() < 2 {
        return Err(UNDEFINED);
    }
    let (symbol, rest) = line.split_at(2);
    let param_len = match symbol {
        b"VV" | b"PP" | b"II" | b"BM" | b"QT" | b"RS" => 0,
        b"TM" => 1,
        b"SS" => 6,
        b"CR" => 2,
        b"MD" | b"MS" => 13,
        b"GD" | b"GS" => 10,
        _ => return Err(UNDEFINED),
    };
    let (params, string) = match rest.iter().position(|&b| b == b';') {
        Some(at) => (&rest[..at], Some(&rest[at + 1..])),
        None => (rest, None),
    };
    if params.len() < param_len {
        return Err(SHORT_PARAMETERS);
    }
    if params.len() > param_len {
        return Err(LONG_PARAMETERS);
    }
    if let Some(string) = string {
        if string.len() > MAX_STRING_LEN {
            return Err(STRING_TOO_LONG);
        }
        let allowed = |b: &u8| b.is_ascii_alphanumeric() || b" ._+@".contains(b);
        if !string.iter().all(allowed) {
            return Err(STRING_INVALID);
        }
    }
    Ok(match symbol {
        b"VV" => Command::Version,
        b"PP" => Command::Parameters,
        b"II" => Command::Status,
        b"BM" => Command::LaserOn,
        b"QT" => Command::Quit,
        b"RS" => Command::Reset,
        b"TM" => Command::Time(params[0]),
        b"SS" => Command::BitRate(params.try_into().map_err(|_| SHORT_PARAMETERS)?),
        b"CR" => Command::MotorSpeed(params.try_into().map_err(|_| SHORT_PARAMETERS)?),
        _ => Command::Scan(parse_scan(symbol, params)?),
    })
}

/// The decimal value of `digits`, if all are digits.
#[must_use]
pub fn number(digits: &[u8]) -> Option<u32> {
    digits.iter().try_fold(0u32, |n, &d| {
        d.is_ascii_digit()
            .then(|| n.saturating_mul(10).saturating_add(u32::from(d - b'0')))
    })
}

/// A scan request's parameters, checked in the specification's status order.
fn parse_scan(symbol: &[u8], params: &[u8]) -> Result<ScanRequest, Status> {
    let continuous = symbol[0] == b'M';
    let field =
        |range: std::ops::Range<usize>, status: &[u8; 2]| number(&params[range]).ok_or(*status);
    let start = field(0..4, b"01")?;
    let end = field(4..8, b"02")?;
    let cluster = field(8..10, b"03")?;
    let (interval, scans) = if continuous {
        (field(10..11, b"06")?, field(11..13, b"07")?)
    } else {
        (0, 0)
    };
    if end > u32::from(MAX_STEP) {
        return Err(*b"04");
    }
    if start > end {
        return Err(*b"05");
    }
    // Every value was checked against a bound that fits its type.
    Ok(ScanRequest {
        continuous,
        two_char: symbol[1] == b'S',
        start: start as u16,
        end: end as u16,
        cluster: cluster as u8,
        interval: interval as u8,
        scans: scans as u8,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_commands_parse_their_fields() {
        let Ok(Command::Scan(md)) = parse(b"MD0044072501000;abc") else {
            panic!("MD parses");
        };
        assert_eq!(
            md,
            ScanRequest {
                continuous: true,
                two_char: false,
                start: 44,
                end: 725,
                cluster: 1,
                interval: 0,
                scans: 0,
            }
        );
        assert_eq!(md.values(), 682);
        let Ok(Command::Scan(gs)) = parse(b"GS0000076803") else {
            panic!("GS parses");
        };
        assert!(!gs.continuous && gs.two_char);
        assert_eq!(gs.values(), 257);
        assert_eq!(gs.field_max(), 4095);
    }

    #[test]
    fn malformed_scan_commands_get_the_specification_statuses() {
        assert_eq!(parse(b"MD00440725010"), Err(SHORT_PARAMETERS));
        assert_eq!(parse(b"MD00440725010000"), Err(LONG_PARAMETERS));
        assert_eq!(parse(b"MDx044072501000"), Err(*b"01"));
        assert_eq!(parse(b"GD00440x2501"), Err(*b"02"));
        assert_eq!(parse(b"GD004407250a"), Err(*b"03"));
        assert_eq!(parse(b"MD0044072501x00"), Err(*b"06"));
        assert_eq!(parse(b"MD004407250100x"), Err(*b"07"));
        assert_eq!(parse(b"GD0044076901"), Err(*b"04"));
        assert_eq!(parse(b"GD0400030001"), Err(*b"05"));
    }

    #[test]
    fn strings_are_checked_and_unknown_commands_refused() {
        assert_eq!(parse(b"BM;hello world"), Ok(Command::LaserOn));
        assert_eq!(parse(b"BM;12345678901234567"), Err(STRING_TOO_LONG));
        assert_eq!(parse(b"BM;a#b"), Err(STRING_INVALID));
        assert_eq!(parse(b"%ST"), Err(UNDEFINED));
        assert_eq!(parse(b"RT"), Err(UNDEFINED));
        assert_eq!(parse(b"X"), Err(UNDEFINED));
        assert_eq!(parse(b"TM"), Err(SHORT_PARAMETERS));
        assert_eq!(parse(b"TM1"), Ok(Command::Time(b'1')));
        assert_eq!(parse(b"SCIP2.0"), Ok(Command::Scip20));
        assert_eq!(parse(b"SS115200"), Ok(Command::BitRate(*b"115200")));
    }
}
