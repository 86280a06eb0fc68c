//! Numbers as CSV text, exactly as `Display` writes them (the shortest decimal that reads back
//! as the same `f64`, in plain notation), faster: formatting was half the time of `hilsim
//! record` (issue 18). The shortest digits come from Żmij (`zmij`, by the author of `ryu` and
//! `itoa`); only its notation and its rounding of exact ties are changed here, to `Display`'s,
//! so recordings keep their bytes.

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
pub(crate) fn push_f64(out: &mut String, x: f64) {
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
    fn push_plain(&self, out: &mut String, negative: bool) {
        if negative {
            out.push('-');
        }
        let digits = std::str::from_utf8(&self.digits).unwrap_or_default();
        let n = i64::try_from(digits.len()).unwrap_or(i64::MAX);
        let zeros = |count: i64| std::iter::repeat_n('0', usize::try_from(count).unwrap_or(0));
        if self.point <= 0 {
            out.push_str("0.");
            out.extend(zeros(-self.point));
            out.push_str(digits);
        } else if self.point >= n {
            out.push_str(digits);
            out.extend(zeros(self.point - n));
        } else {
            let split = usize::try_from(self.point).unwrap_or(0);
            out.push_str(&digits[..split]);
            out.push('.');
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

/// Appends an integer as `Display` writes it.
pub(crate) fn push_int(out: &mut String, n: impl itoa::Integer) {
    out.push_str(itoa::Buffer::new().format(n));
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn shown(x: f64) -> String {
        let mut s = String::new();
        push_f64(&mut s, x);
        s
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

        #[test]
        fn recording_scale_numbers_read_as_display_writes_them(
            x in -1e4f64..1e4, steps in 0u32..1_000_000,
        ) {
            prop_assert_eq!(shown(x), x.to_string());
            let t = f64::from(steps) * 0.01;
            prop_assert_eq!(shown(t), t.to_string());
        }
    }

    #[test]
    fn integers_read_as_display_writes_them() {
        for n in [0u64, 7, 359, 65_535, u64::MAX] {
            let mut s = String::new();
            push_int(&mut s, n);
            assert_eq!(s, n.to_string());
        }
    }
}
