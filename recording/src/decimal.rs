//! Numbers as CSV text, exactly as `Display` writes them (the shortest decimal that reads back
//! as the same `f64`, in plain notation), faster: formatting was half the time of `hilsim
//! record` and most of `hilsim import`'s. The fixed decimals a recording
//! mostly holds (times to the microsecond, millimetres) are written from their integer digits;
//! other numbers' shortest digits come from Żmij (`zmij`, by the author of `ryu` and `itoa`),
//! with its notation and its rounding of exact ties changed to `Display`'s, so recordings keep
//! their bytes.
//!
//! The way back from a float32 (a ROS message's field) to the decimal it was written as,
//! [`decimal_of_f32`], lives here too: an imported range is then written as it was sent.

/// Where CSV text goes: a `String` (a whole table) or a byte buffer (a streamed table's).
pub(crate) trait Text {
    /// Appends `s`.
    fn push_str(&mut self, s: &str);
    /// Appends one ASCII byte.
    fn push_byte(&mut self, b: u8);
    /// Appends the ASCII text `write` puts at the start of a buffer of [`SHORT_MAX`] bytes
    /// (it returns its length).
    fn push_short(&mut self, write: impl FnOnce(&mut [u8]) -> usize);
    /// Appends a row that `write` puts into a [`Row`] of [`ROW_MAX`] bytes; nothing when it
    /// gives `None` (a number off the fast path: the caller writes the row the long way).
    fn push_row(&mut self, write: impl FnOnce(&mut Row<'_>) -> Option<()>) -> bool;
}

impl Text for String {
    fn push_str(&mut self, s: &str) {
        String::push_str(self, s);
    }
    fn push_byte(&mut self, b: u8) {
        self.push(char::from(b));
    }
    fn push_short(&mut self, write: impl FnOnce(&mut [u8]) -> usize) {
        let mut bytes = [0; SHORT_MAX];
        let len = write(&mut bytes);
        // ASCII: digits, '-' and '.'.
        String::push_str(self, std::str::from_utf8(&bytes[..len]).unwrap_or_default());
    }
    fn push_row(&mut self, write: impl FnOnce(&mut Row<'_>) -> Option<()>) -> bool {
        let mut bytes = [0; ROW_MAX];
        let mut row = Row {
            out: &mut bytes,
            len: 0,
        };
        if write(&mut row).is_none() {
            return false;
        }
        let len = row.len;
        // ASCII: digits, '-', '.', ',' and '\n'.
        String::push_str(self, std::str::from_utf8(&bytes[..len]).unwrap_or_default());
        true
    }
}

impl Text for Vec<u8> {
    fn push_str(&mut self, s: &str) {
        self.extend_from_slice(s.as_bytes());
    }
    fn push_byte(&mut self, b: u8) {
        self.push(b);
    }
    fn push_short(&mut self, write: impl FnOnce(&mut [u8]) -> usize) {
        // Written in place (a copy from a stack buffer would wait for the bytes just stored
        // there), then the unused tail cut off.
        let start = self.len();
        self.extend_from_slice(&[0; SHORT_MAX]);
        let len = write(&mut self[start..]);
        self.truncate(start + len);
    }
    fn push_row(&mut self, write: impl FnOnce(&mut Row<'_>) -> Option<()>) -> bool {
        // In place, as `push_short`: one length check and one cut a row, not one a field.
        let start = self.len();
        self.resize(start + ROW_MAX, 0);
        let mut row = Row {
            out: &mut self[start..],
            len: 0,
        };
        let written = write(&mut row).map(|()| row.len);
        self.truncate(start + written.unwrap_or(0));
        written.is_some()
    }
}

/// Room for a row written in one piece: a lidar row with its true range is at most 7 fields
/// of [`SHORT_MAX`] and 8 separators.
pub(crate) const ROW_MAX: usize = 8 * SHORT_MAX;

/// A row being written into a buffer of [`ROW_MAX`] bytes, field by field, for the common case
/// only: numbers on the grid (below), zeros and integers. A field it does not take makes the
/// row `None`, to be written the long way ([`push_f64`], [`push_int`]) with the same bytes.
pub(crate) struct Row<'a> {
    out: &'a mut [u8],
    len: usize,
}

impl Row<'_> {
    /// Room for one more field and its separator, or `None`.
    fn room(&mut self) -> Option<&mut [u8]> {
        self.out.get_mut(self.len..self.len + SHORT_MAX + 1)
    }

    /// `x` as `Display` writes it, if it is 0 or on the grid.
    pub(crate) fn f64(&mut self, x: f64) -> Option<()> {
        let room = self.room()?;
        let len = if x == 0.0 {
            // "0" or "-0".
            let sign = usize::from(x.is_sign_negative());
            room[0] = b'-';
            room[sign] = b'0';
            sign + 1
        } else {
            write_grid(room, x < 0.0, on_grid(x)?)
        };
        self.len += len;
        Some(())
    }

    /// n·10^−`scale` as `Display` writes the `f64` closest to it, if the decimal is on the grid
    /// (`scale` ≤ 9, n·10^(9−scale) < 10¹⁵): written from its digits, no `f64` involved.
    pub(crate) fn decimal(&mut self, n: u64, scale: u32) -> Option<()> {
        const TO_GRID: [u64; 10] = [
            1_000_000_000,
            100_000_000,
            10_000_000,
            1_000_000,
            100_000,
            10_000,
            1_000,
            100,
            10,
            1,
        ];
        let on_grid = n.checked_mul(*TO_GRID.get(usize::try_from(scale).ok()?)?)?;
        if on_grid >= GRID_LIMIT_N {
            return None;
        }
        if on_grid == 0 {
            return self.byte(b'0');
        }
        let room = self.room()?;
        self.len += write_grid(room, false, on_grid);
        Some(())
    }

    /// An unsigned integer as `Display` writes it.
    pub(crate) fn int(&mut self, n: impl Into<u64>) -> Option<()> {
        let room = self.room()?;
        self.len += write_unsigned(room, n.into());
        Some(())
    }

    /// One ASCII byte (a separator, a flag).
    pub(crate) fn byte(&mut self, b: u8) -> Option<()> {
        *self.out.get_mut(self.len)? = b;
        self.len += 1;
        Some(())
    }
}

/// The longest short text: "-999999.999999999", or a u64's 20 digits.
const SHORT_MAX: usize = 24;

/// "00" to "99": two digits at a time.
const PAIRS: &[u8; 200] = b"\
0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// The number of decimal digits of `n` (1 for 0).
fn digit_count(n: u64) -> usize {
    let mut count = 1;
    let mut power = 10u64;
    while count < 20 && n >= power {
        count += 1;
        power = power.wrapping_mul(10);
    }
    count
}

/// Writes `n`'s last `count` digits (zero-padded) into `out[..count]`.
fn write_digits(out: &mut [u8], mut n: u64, count: usize) {
    let mut end = count;
    while end >= 2 {
        let pair = usize::try_from(n % 100).unwrap_or(0) * 2;
        out[end - 2..end].copy_from_slice(&PAIRS[pair..pair + 2]);
        n /= 100;
        end -= 2;
    }
    if end == 1 {
        out[0] = b'0' + u8::try_from(n % 10).unwrap_or(0);
    }
}

/// Writes an unsigned integer as `Display` does; its length.
fn write_unsigned(out: &mut [u8], n: u64) -> usize {
    let count = digit_count(n);
    write_digits(out, n, count);
    count
}

/// The 8 decimal digits of `n` < 10⁸ (zero-padded), one a byte, first digit in the lowest byte
/// (so `to_le_bytes` reads them in order), as values 0–9: a zero digit is a zero byte. Divisions
/// by 10⁴, 10² and 10 done on all lanes at once by multiplying with a reciprocal (SWAR): exact
/// for the lanes' ranges (x/100 = x·10486 >> 20 for x < 10⁴; x/10 = x·103 >> 10 for x < 100,
/// both checked over every x in the tests).
fn eight_digits(n: u64) -> u64 {
    // Two 32-bit lanes of 4 digits.
    let lanes = (n / 10_000) | ((n % 10_000) << 32);
    // Four 16-bit lanes of 2 digits.
    let hundreds = ((lanes * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let lanes = hundreds | ((lanes - hundreds * 100) << 16);
    // Eight bytes of 1 digit.
    let tens = ((lanes * 103) >> 10) & 0x000F_000F_000F_000F;
    tens | ((lanes - tens * 10) << 8)
}

/// Digits from [`eight_digits`] as ASCII.
fn ascii(digits: u64) -> u64 {
    digits | 0x3030_3030_3030_3030
}

/// At and above this magnitude, and for "NaN" and "inf", `Display` itself writes the number:
/// a recording's values are far below (times to 86,400 s, distances to 1,000 m).
const FAST_BELOW: f64 = 2_147_483_648.0; // 2^31

/// Appends `x` as `format!("{x}")` would.
///
/// Żmij and `Display` both write the fewest digits that read back as `x`, the closest to `x`
/// when several would; they differ only when `x` lies exactly halfway between the two closest
/// (Żmij rounds half to even, `Display` half up). That is common in a recording: a float that
/// came from `f32` (rapier's positions) has a short exact decimal expansion. Such a tie is found
/// exactly from the bits and left to `Display`.
pub(crate) fn push_f64(out: &mut impl Text, x: f64) {
    if let Some(n) = on_grid(x) {
        out.push_short(|bytes| write_grid(bytes, x < 0.0, n));
        return;
    }
    if !x.is_finite() || x.abs() >= FAST_BELOW {
        out.push_str(&x.to_string());
        return;
    }
    let mut buffer = zmij::Buffer::new();
    let shortest = buffer.format_finite(x);
    // Plain notation ("-12.25", "3.0"): as Display's but for a whole number's ".0".
    if let Some((whole, fraction)) = shortest.split_once('.') {
        if fraction == "0" {
            // |x| < 2^31 is whole: exact, no tie to round.
            out.push_str(whole);
            return;
        }
        if !shortest.contains('e') {
            // q = n − point is the number of digits after the point.
            if is_halfway(x, fraction.len(), 0) {
                out.push_str(&x.to_string());
            } else {
                out.push_str(shortest);
            }
            return;
        }
    }
    // Scientific ("1.5e-7", "5e-324"): small numbers, rare in a recording.
    let Some(decimal) = Decimal::parse(shortest) else {
        out.push_str(&x.to_string());
        return;
    };
    if decimal.digits.is_empty() {
        out.push_str(if x.is_sign_negative() { "-0" } else { "0" });
    } else if is_halfway(x, decimal.digits.len(), decimal.point) {
        out.push_str(&x.to_string());
    } else {
        decimal.push_plain(out, x.is_sign_negative());
    }
}

/// The fixed decimals a recording mostly holds (times to the microsecond, angles to 1e-4°,
/// ranges to the millimetre, wheel travel to the nanometre): numbers that are the `f64`
/// closest to n·10⁻⁹ for a whole n, 0 < |n| < 10¹⁵.
const GRID: f64 = 1e9;
const GRID_LIMIT_N: u64 = 1_000_000_000_000_000;
const GRID_LIMIT: f64 = GRID_LIMIT_N as f64;

/// |n| when `x` is the `f64` closest to n·10⁻⁹ for a whole n, 0 < |n| < 10¹⁵; `None`
/// otherwise (and for a few within 10⁻⁶ of a tie between two `f64`, which lose nothing but
/// this shortcut).
fn on_grid(x: f64) -> Option<u64> {
    let magnitude = x.abs();
    if !(1e-9..GRID_LIMIT / GRID).contains(&magnitude) {
        return None;
    }
    // The whole number nearest |x|·10⁹ (a cast, not a call to `round`; a wrong guess fails the
    // check below). Signed: one instruction each way, where u64 takes several.
    let n = (magnitude * GRID + 0.5) as i64;
    // The f64 closest to n·10⁻⁹ is |x| when n lies within 10⁹ × half the step between |x| and
    // its neighbours of |x|·10⁹ (a division would say so, slower). |x|·10⁹ exactly is
    // high + low, |x| cut into its upper 32 bits and lower 21, each product exact (10⁹ =
    // 1953125·2⁹ has 21 bits); n − high is exact (the two are within a factor of 2 of each
    // other whenever it matters), so d is n − |x|·10⁹ to 2⁻⁵³ of itself.
    let bits = magnitude.to_bits();
    let high = f64::from_bits(bits & !((1 << 21) - 1));
    let low = magnitude - high;
    let d = (n as f64 - high * GRID) - low * GRID;
    // Half a step is 2^(e−53) for |x| in [2^e, 2^(e+1)); below a power of two the step halves.
    let exponent = bits >> 52;
    let mut half_step = f64::from_bits((exponent - 53) << 52) * GRID;
    if bits & ((1 << 52) - 1) == 0 && d < 0.0 {
        half_step *= 0.5;
    }
    // Strictly inside, by a margin far above d's own rounding: no tie, no doubt.
    if n == 0 || d.abs() >= half_step * (1.0 - 1e-6) {
        return None;
    }
    u64::try_from(n).ok()
}

/// Writes n·10⁻⁹ (0 < n < 10¹⁵) as `Display` writes the `f64` closest to it; its length.
///
/// Two different decimals of at most 15 significant digits are never closest to the same normal
/// `f64` (15 is `f64::DIGITS`), and n·10⁻⁹ has at most 15: so no other decimal as short reads
/// back as that `f64`, and n·10⁻⁹ without its trailing zeros is the shortest, as `Display`
/// writes it (no tie to round either).
fn write_grid(out: &mut [u8], negative: bool, n: u64) -> usize {
    let whole = n / 1_000_000_000;
    let fraction = n % 1_000_000_000;
    let sign = usize::from(negative);
    out[0] = b'-';
    let mut len = sign + write_unsigned(&mut out[sign..], whole);
    if fraction != 0 {
        // The first of the 9 digits, then 8 at once; the trailing zeros (zero bytes at the
        // top of the 8) are not kept: no loop, no division.
        let first = fraction / 100_000_000;
        let rest = eight_digits(fraction % 100_000_000);
        let kept = if rest == 0 {
            1
        } else {
            9 - (rest.leading_zeros() / 8) as usize
        };
        out[len] = b'.';
        out[len + 1] = b'0' + u8::try_from(first).unwrap_or(0);
        out[len + 2..len + 10].copy_from_slice(&ascii(rest).to_le_bytes());
        len += 1 + kept;
    }
    len
}

/// A decimal 0.d1d2…dn × 10^point, without leading or trailing zero digits.
struct Decimal {
    digits: Vec<u8>,
    point: i64,
}

impl Decimal {
    /// Reads Żmij's text ("-0.25", "1.5e-7", "1e+16"); `None` for anything else.
    fn parse(text: &str) -> Option<Self> {
        let text = text.strip_prefix('-').unwrap_or(text);
        let (mantissa, exponent) = match text.split_once('e') {
            Some((m, e)) => (m, e.parse::<i64>().ok()?),
            None => (text, 0),
        };
        let (whole, fraction) = mantissa.split_once('.').unwrap_or((mantissa, ""));
        let all = whole.bytes().chain(fraction.bytes());
        let leading = whole.bytes().take_while(|&b| b == b'0').count();
        let mut digits: Vec<u8> = all.skip_while(|&b| b == b'0').collect();
        if !digits.iter().all(u8::is_ascii_digit) {
            return None;
        }
        // A whole part of zeros: the digits start after the fraction's own leading zeros.
        let point = if leading == whole.len() {
            -i64::try_from(fraction.bytes().take_while(|&b| b == b'0').count()).ok()?
        } else {
            i64::try_from(whole.len() - leading).ok()?
        } + exponent;
        while digits.last() == Some(&b'0') {
            digits.pop();
        }
        Some(Self { digits, point })
    }

    /// Writes the number in plain notation, as `Display` does.
    fn push_plain(&self, out: &mut impl Text, negative: bool) {
        if negative {
            out.push_byte(b'-');
        }
        let digits = std::str::from_utf8(&self.digits).unwrap_or_default();
        let n = i64::try_from(digits.len()).unwrap_or(i64::MAX);
        let zeros = |out: &mut dyn FnMut(u8), count: i64| {
            for _ in 0..count {
                out(b'0');
            }
        };
        if self.point <= 0 {
            out.push_str("0.");
            zeros(&mut |b| out.push_byte(b), -self.point);
            out.push_str(digits);
        } else if self.point >= n {
            out.push_str(digits);
            zeros(&mut |b| out.push_byte(b), self.point - n);
        } else {
            let split = usize::try_from(self.point).unwrap_or(0);
            out.push_str(&digits[..split]);
            out.push_byte(b'.');
            out.push_str(&digits[split..]);
        }
    }
}

/// Whether `x` lies exactly halfway between two decimals of `n` significant digits whose first
/// digit is at `point` (0.d1…dn × 10^point): whether 2·|x|·10^q, q = n − point, is an odd
/// integer. With |x| = m·2^e (m = m'·2^z, m' odd) that is m'·5^q·2^(z+e+1+q), odd and whole
/// exactly when z + e + 1 + q = 0 (for q ≥ 0; a negative q, a whole number ending in zeros,
/// is answered "maybe").
fn is_halfway(x: f64, n: usize, point: i64) -> bool {
    let q = i64::try_from(n).unwrap_or(i64::MAX) - point;
    if q < 0 {
        return true;
    }
    let bits = x.abs().to_bits();
    let biased = i64::try_from(bits >> 52).unwrap_or(0);
    let fraction = bits & ((1 << 52) - 1);
    let (m, e) = if biased == 0 {
        (fraction, -1074)
    } else {
        (fraction | (1 << 52), biased - 1075)
    };
    m != 0 && i64::from(m.trailing_zeros()) + e + 1 + q == 0
}

/// Appends an unsigned integer as `Display` writes it.
pub(crate) fn push_int(out: &mut impl Text, n: impl Into<u64>) {
    let n = n.into();
    out.push_short(|bytes| write_unsigned(bytes, n));
}

/// A float32 field as the decimal it was written as: the shortest decimal that reads back as
/// that float32 (`1.234`, not `1.2339999675750732`), so that millimetre ranges stay millimetres
/// and a recording exported and imported keeps its numbers.
#[must_use]
pub fn decimal_of_f32(x: f32) -> f64 {
    if !x.is_finite() {
        return f64::from(x);
    }
    if let Some((digits, scale)) = short_decimal_of_f32(x) {
        let decimal = digits as f64 / POWERS_OF_TEN[scale as usize];
        return if x < 0.0 { -decimal } else { decimal };
    }
    let mut buffer = zmij::Buffer::new();
    buffer
        .format_finite(x)
        .parse()
        .unwrap_or_else(|_| f64::from(x))
}

/// `x`'s decimal, as its digits and the power of ten they are divided by, when it has at most
/// 6 significant digits (millimetre ranges, `0.5`, `12.25`), found without formatting; `None`
/// otherwise (and outside 1e-10..1e6).
///
/// Two different decimals of at most 6 significant digits (`f32::DIGITS`) are never read as
/// the same normal `f32`, so one that reads as `x` is the only one as short: the shortest, the
/// one [`decimal_of_f32`] gives. The 6-digit decimals are 10⁻ˢ apart, 10 to 100 times the
/// float32's step, so only the one closest to `x` can read as `x`: n·10⁻ˢ for n the whole
/// number closest to |x|·10ˢ, with s such that n has 6 digits.
pub fn short_decimal_of_f32(x: f32) -> Option<(u64, u32)> {
    let magnitude = f64::from(x).abs();
    if !(1e-10..1e6).contains(&magnitude) {
        return None;
    }
    let bits = x.abs().to_bits();
    let e = i32::try_from(bits >> 23).unwrap_or(0) - 127;
    // Within half a step of `x` towards either neighbour, a decimal reads as `x`; the margin
    // of one part in 10⁶ is far above the f64 rounding of the products (10⁻¹⁶), so that no
    // double rounding decides. The step is 2^(e−23), and half that below a power of two.
    let step = f64::from_bits(u64::try_from(e - 23 + 1023).unwrap_or(0) << 52);
    let half_step = if bits & 0x007F_FFFF == 0 {
        0.25 * step
    } else {
        0.5 * step
    } * (1.0 - 1e-6);
    // Millimetres first (most lidars' and sonars' ranges): n·10⁻³ with n < 10⁶ has at most
    // 6 significant digits, so if it reads as `x` it is the one such decimal.
    let millimetres = magnitude * 1e3;
    let n = round_half_away(millimetres);
    if n < 1e6 && (n - millimetres).abs() < half_step * 1e3 {
        return Some((n as u64, 3));
    }
    let s = POWERS_OF_TEN.iter().position(|p| magnitude * p >= 1e5)?;
    let power = POWERS_OF_TEN[s];
    let scaled = round_half_away(magnitude * power);
    // n ≥ 10⁵ by the choice of s: n ≤ 10⁶ has at most 6 significant digits. (A power one
    // off at a boundary makes 7 digits, or a decimal that misses `x`: `None` either way.)
    if scaled > 1e6 {
        return None;
    }
    // The f64 closest to n·10⁻ˢ (n and 10ˢ are exact: one rounding), what parsing the
    // decimal gives.
    let decimal = scaled / power;
    // n ≤ 10⁶ and s ≤ 15: both exact in their integer types.
    ((decimal - magnitude).abs() < half_step).then_some((scaled as u64, s as u32))
}

/// 10⁰ to 10¹⁵, each exact in an `f64`.
const POWERS_OF_TEN: [f64; 16] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
];

/// `f64::round` (half away from zero) without its call into the C library, which the
/// baseline x86-64 target has no instruction for: it was a tenth of an import's time.
#[must_use]
pub fn round_half_away(x: f64) -> f64 {
    // 2⁵²: from here on every f64 is whole (and NaN, ±inf pass through).
    if x.is_nan() || x.abs() >= 4_503_599_627_370_496.0 {
        return x;
    }
    // |x| < 2⁵²: the cast truncates exactly, and `x - whole` is exact.
    let whole = x as i64 as f64;
    let fraction = x - whole;
    if fraction >= 0.5 {
        whole + 1.0
    } else if fraction <= -0.5 {
        whole - 1.0
    } else {
        // Keeps the sign of a zero, as `round` does.
        whole.copysign(x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn float32_fields_keep_their_decimals() {
        assert_eq!(decimal_of_f32(1.234), 1.234);
        assert_eq!(decimal_of_f32(0.5), 0.5);
        assert_eq!(decimal_of_f32(6.0), 6.0);
    }

    /// The short path gives what formatting the float32's shortest decimal and reading it does,
    /// for every float32 between 1e-11 and 1e7 in steps of a prime number of bit patterns.
    #[test]
    fn short_decimals_are_the_shortest() {
        let slow = |x: f32| -> f64 { zmij::Buffer::new().format_finite(x).parse().unwrap() };
        let (low, high) = (1e-11f32.to_bits(), 1e7f32.to_bits());
        let mut short = 0;
        for bits in (low..high).step_by(997) {
            for x in [f32::from_bits(bits), -f32::from_bits(bits)] {
                assert_eq!(decimal_of_f32(x), slow(x), "{x:e}");
                short += usize::from(short_decimal_of_f32(x).is_some());
            }
        }
        for text in [
            "1.234", "0.001", "65.535", "12.3456", "0.000123", "1000", "0.5", "99999.9", "10",
            "123456", "1e-9",
        ] {
            let x: f32 = text.parse().unwrap();
            let expected: f64 = text.parse().unwrap();
            for x in [x, -x] {
                let (digits, scale) = short_decimal_of_f32(x).unwrap();
                assert_eq!(digits as f64 / 10f64.powi(scale as i32), expected, "{text}");
                assert_eq!(decimal_of_f32(x), expected.copysign(f64::from(x)), "{text}");
            }
        }
        assert_eq!(short_decimal_of_f32(1.234_567_8), None);
        assert!(short > 0);
        // Every millimetre range to 100 m (the fast path of an import) is short.
        for mm in 1..100_000u32 {
            let x = mm as f32 / 1000.0;
            let (digits, scale) = short_decimal_of_f32(x).unwrap();
            assert_eq!(
                digits as f64 / 10f64.powi(scale as i32),
                f64::from(mm) / 1e3
            );
        }
    }

    #[test]
    fn rounding_is_round() {
        let mut x = 1e-3f64;
        for _ in 0..2000 {
            for v in [
                x,
                -x,
                x + 0.5,
                -x - 0.5,
                x.floor() + 0.5,
                -(x.floor() + 0.5),
            ] {
                assert_eq!(round_half_away(v).to_bits(), v.round().to_bits(), "{v:e}");
            }
            x *= 1.037;
        }
        for v in [
            0.0,
            -0.0,
            0.499_999_999_999_999_94,
            -0.499_999_999_999_999_94,
            4.5e15 + 0.5,
        ] {
            assert_eq!(round_half_away(v).to_bits(), v.round().to_bits(), "{v:e}");
        }
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300] {
            assert_eq!(round_half_away(v).to_bits(), v.round().to_bits(), "{v:e}");
        }
    }

    use proptest::prelude::*;

    /// As a whole table's `String` and a streamed table's bytes write it (the two must agree).
    fn shown(x: f64) -> String {
        let mut s = String::new();
        push_f64(&mut s, x);
        let mut bytes = b"a,".to_vec();
        push_f64(&mut bytes, x);
        assert_eq!(bytes, format!("a,{s}").into_bytes());
        // A row's fast path, where it takes the number, writes the same.
        let mut row = b"a,".to_vec();
        if row.push_row(|row| row.f64(x)) {
            assert_eq!(row, bytes, "{x:?}");
        } else {
            assert_eq!(row, b"a,");
        }
        let mut row = String::new();
        if row.push_row(|row| row.f64(x)) {
            assert_eq!(row, s, "{x:?}");
        }
        s
    }

    #[test]
    fn the_reciprocals_divide_exactly() {
        for x in 0..10_000u64 {
            assert_eq!((x * 10_486) >> 20, x / 100, "{x}");
        }
        for x in 0..100u64 {
            assert_eq!((x * 103) >> 10, x / 10, "{x}");
        }
        for n in [
            0, 1, 9, 10, 1_234, 10_000, 12_345_678, 99_999_999, 50_000_000,
        ] {
            let digits = ascii(eight_digits(n)).to_le_bytes();
            assert_eq!(digits.as_slice(), format!("{n:08}").as_bytes());
        }
    }

    /// Whole rows: the fast path takes the common ones, and gives up on the others leaving
    /// nothing behind.
    #[test]
    fn a_row_is_written_in_one_piece_or_not_at_all() {
        let mut bytes = b"x\n".to_vec();
        let taken = bytes.push_row(|row| {
            row.f64(12.000_345)?;
            row.byte(b',')?;
            row.int(7u64)?;
            row.byte(b',')?;
            row.f64(-0.0)?;
            row.byte(b',')?;
            row.f64(0.0)?;
            row.byte(b',')?;
            row.f64(-359.5)?;
            row.byte(b'\n')
        });
        assert!(taken);
        assert_eq!(bytes, b"x\n12.000345,7,-0,0,-359.5\n");
        let taken = bytes.push_row(|row| {
            row.f64(1.5)?;
            row.byte(b',')?;
            row.f64(0.1 + 0.2)
        });
        assert!(!taken);
        assert_eq!(bytes, b"x\n12.000345,7,-0,0,-359.5\n");
        // More fields than a row has room for: refused, not a panic.
        let taken = bytes.push_row(|row| {
            for _ in 0..100 {
                row.f64(999_999.999_999_999)?;
            }
            Some(())
        });
        assert!(!taken);
    }

    #[test]
    fn numbers_read_as_display_writes_them() {
        for x in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e-7,
            -1.5e-5,
            123_456.0,
            1e15,
            1e16,
            1.2345e21,
            5e-324,
            0.150_000_000_000_000_02,
            1e-9,
            -1e-9,
            1.5e-9,
            0.000_001,
            123.456_789,
            -0.002,
            999_999.999_999_999,
            1_000_000.000_000_001,
            86_400.000_001,
            18.799_999_999_999_965,
            f64::MAX,
            0.696_266_174_316_406_3,
            3.159_065_246_582_031_3,
            f64::MIN_POSITIVE,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ] {
            assert_eq!(shown(x), x.to_string(), "{x:?}");
        }
    }

    proptest! {
        // Every bit pattern, and the decimals a recording holds (times, ranges in metres).
        #[test]
        fn any_f64_reads_as_display_writes_it(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assert_eq!(shown(x), x.to_string());
        }

        // Floats that came from f32 (rapier's positions) have short exact expansions: ties.
        #[test]
        fn floats_from_f32_read_as_display_writes_them(bits in any::<u32>()) {
            let x = f64::from(f32::from_bits(bits));
            prop_assert_eq!(shown(x), x.to_string());
            let half = x / 2.0 + 0.5;
            prop_assert_eq!(shown(half), half.to_string());
        }

        // The grid's numbers: times to the microsecond, millimetres, nanometres, near 10⁶.
        #[test]
        fn decimals_on_the_grid_read_as_display_writes_them(
            n in -999_999_999_999_999i64..1_000_000_000_000_000, scale in 0u32..10,
        ) {
            let x = n as f64 / 10f64.powi(scale as i32);
            prop_assert_eq!(shown(x), x.to_string());
            let near = f64::from_bits(x.to_bits() + 1);
            prop_assert_eq!(shown(near), near.to_string());
        }

        #[test]
        fn recording_scale_numbers_read_as_display_writes_them(
            x in -1e4f64..1e4, steps in 0u32..1_000_000,
        ) {
            prop_assert_eq!(shown(x), x.to_string());
            let t = f64::from(steps) * 0.01;
            prop_assert_eq!(shown(t), t.to_string());
        }
    }

    /// The shortcut takes nearly every decimal of the grid (else it would be no shortcut), and
    /// nothing off it.
    #[test]
    fn the_grid_is_found() {
        for (x, n) in [
            (0.15, 150_000_000),
            (1.0, 1_000_000_000),
            (0.5, 500_000_000),
        ] {
            assert_eq!(on_grid(x), Some(n), "{x}");
            assert_eq!(on_grid(-x), Some(n), "{x}");
        }
        assert_eq!(on_grid(2.0), Some(2_000_000_000));
        assert_eq!(on_grid(1e-9), Some(1));
        assert_eq!(on_grid(999_999.999_999_999), Some(999_999_999_999_999));
        assert_eq!(on_grid(0.1 + 0.2), None);
        assert_eq!(on_grid(1e6), None);
        assert_eq!(on_grid(f64::NAN), None);
        let mut found = 0;
        let total = 1_000_000;
        for i in 0..total {
            // Microseconds up to 10⁵ s; millimetres.
            let n = (i as i64) * 100_003;
            found += usize::from(on_grid(n as f64 / 1e6).is_some());
            found += usize::from(on_grid((i % 100_000) as f64 / 1e3).is_some_and(|m| m != 0));
        }
        // The margin refuses about 10⁻⁶ of them; one in ten thousand leaves room.
        assert!(found > 2 * total - total / 10_000, "{found}");
    }

    #[test]
    fn integers_read_as_display_writes_them() {
        let mut n = 1u64;
        for _ in 0..20 {
            for m in [n - 1, n, n + 1, n.saturating_mul(7), n / 2 * 3] {
                let mut s = String::new();
                push_int(&mut s, m);
                let mut bytes = Vec::new();
                push_int(&mut bytes, m);
                assert_eq!(s, m.to_string());
                assert_eq!(bytes, m.to_string().into_bytes());
                let mut row = Vec::new();
                assert!(row.push_row(|row| row.int(m)));
                assert_eq!(row, m.to_string().into_bytes());
            }
            n = n.saturating_mul(10);
        }
        for m in [65_535u16, 0, 359] {
            let mut s = String::new();
            push_int(&mut s, m);
            assert_eq!(s, m.to_string());
        }
        let mut s = String::new();
        push_int(&mut s, u64::MAX);
        assert_eq!(s, u64::MAX.to_string());
    }
}
