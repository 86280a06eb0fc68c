//! SCIP 2.0's character encodings, its check character and the URG-04LX's step geometry.

/// Steps in a whole revolution (`PP` `ARES`, SCIP 2.0 specification section 5).
pub const STEPS_PER_REV: u16 = 1024;
/// The first step the unit measures (`AMIN`).
pub const FIRST_STEP: u16 = 44;
/// The last step the unit measures (`AMAX`).
pub const LAST_STEP: u16 = 725;
/// The step that looks forward (`AFRT`).
pub const FRONT_STEP: u16 = 384;
/// The largest step a request may name (step D of the specification's section 5 table: 768).
pub const MAX_STEP: u16 = 768;
/// The nearest distance the unit reports (`DMIN`); smaller values are error codes.
pub const MIN_DISTANCE_MM: u32 = 20;
/// The farthest distance the unit reports (`DMAX`).
pub const MAX_DISTANCE_MM: u32 = 5600;
/// Error code 0 of the URG-04LX's table (specification table 3): the object is beyond the
/// range ("possibly at 22 m"), the value it sends where nothing returns within range.
pub const NO_OBJECT_CODE: u32 = 0;
/// Error code 19 of the same table: a step the unit does not measure (outside 44–725).
pub const NON_MEASURABLE_CODE: u32 = 19;

/// The check character of `bytes`: the low 6 bits of their byte sum, plus `0x30`.
#[must_use]
pub fn checksum(bytes: &[u8]) -> u8 {
    let sum = bytes
        .iter()
        .fold(0u32, |sum, &b| sum.wrapping_add(u32::from(b)));
    // The mask keeps 6 bits, so the sum fits a byte.
    (sum & 0x3F) as u8 + 0x30
}

/// Appends `value`'s low `6 * chars` bits as `chars` characters, most significant first, each
/// 6 bits plus `0x30`.
pub fn encode(value: u32, chars: usize, out: &mut Vec<u8>) {
    for i in (0..chars).rev() {
        let six = (u64::from(value) >> (6 * i)) & 0x3F;
        out.push(six as u8 + 0x30);
    }
}

/// The value `chars` encode, or `None` when one is outside the encoding's `0x30..=0x6F`.
#[must_use]
pub fn decode(chars: &[u8]) -> Option<u32> {
    chars.iter().try_fold(0u32, |value, &c| {
        let six = c.checked_sub(0x30).filter(|&six| six < 0x40)?;
        Some(value.checked_shl(6)? | u32::from(six))
    })
}

/// The angle of `step` in the unit's convention: counter-clockwise from forward, degrees in
/// [0, 360).
#[must_use]
pub fn step_angle_deg(step: u16) -> f64 {
    let deg = (f64::from(step) - f64::from(FRONT_STEP)) * 360.0 / f64::from(STEPS_PER_REV);
    let wrapped = deg.rem_euclid(360.0);
    // rem_euclid of a tiny negative number can round to 360.0 itself.
    if wrapped >= 360.0 {
        0.0
    } else {
        wrapped
    }
}

/// The step of a reading with place `index` in its revolution (the step less [`FIRST_STEP`]).
#[must_use]
pub fn index_step(index: u32) -> Option<u16> {
    u16::try_from(index)
        .ok()
        .and_then(|i| i.checked_add(FIRST_STEP))
        .filter(|&step| step <= MAX_STEP)
}

/// The value a reading's distance goes out as: the distance within the unit's range and the
/// field's capacity (`field_max`), else [`NO_OBJECT_CODE`].
#[must_use]
pub fn distance_field(distance_mm: u32, field_max: u32) -> u32 {
    if (MIN_DISTANCE_MM..=MAX_DISTANCE_MM.min(field_max)).contains(&distance_mm) {
        distance_mm
    } else {
        NO_OBJECT_CODE
    }
}

/// The unit's millisecond clock at `t_s` seconds after its epoch: 24 bits, wrapping.
#[must_use]
pub fn clock_ms(t_s: f64) -> u32 {
    const WRAP: f64 = (1u32 << 24) as f64;
    let ms = (t_s * 1000.0).floor();
    if ms.is_finite() {
        // In [0, 2^24) after rem_euclid, so the cast is exact.
        ms.rem_euclid(WRAP) as u32 & 0x00FF_FFFF
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodings_match_the_specification_examples() {
        // SCIP 2.0 specification figures 2, 4 and 6.
        let mut out = Vec::new();
        encode(1234, 2, &mut out);
        assert_eq!(out, b"CB");
        out.clear();
        encode(5432, 3, &mut out);
        assert_eq!(out, b"1Dh");
        out.clear();
        encode(16_000_000, 4, &mut out);
        assert_eq!(out, b"m2@0");
        assert_eq!(decode(b"CB"), Some(1234));
        assert_eq!(decode(b"1Dh"), Some(5432));
        assert_eq!(decode(b"m2@0"), Some(16_000_000));
        assert_eq!(decode(b"1D\x7f"), None);
        assert_eq!(decode(b"/"), None);
    }

    #[test]
    fn checksums_match_the_specification_replies() {
        // Status "00" is followed by 'P', "99" by 'b' (specification section 8.1); the PP
        // example lines' sums exclude the ';'.
        assert_eq!(checksum(b"00"), b'P');
        assert_eq!(checksum(b"99"), b'b');
        assert_eq!(checksum(b"DMIN:20"), b'4');
        assert_eq!(checksum(b"AMAX:725"), b'o');
        assert_eq!(checksum(b"SCAN:600"), b'e');
        assert_eq!(checksum(b"LASR:OFF"), b'7');
    }

    #[test]
    fn steps_map_to_the_unit_angles() {
        assert_eq!(step_angle_deg(FRONT_STEP), 0.0);
        assert!((step_angle_deg(FRONT_STEP + 256) - 90.0).abs() < 1e-12);
        assert!((step_angle_deg(FIRST_STEP) - (360.0 - 119.53125)).abs() < 1e-9);
        assert!((step_angle_deg(LAST_STEP) - 119.8828125).abs() < 1e-9);
        assert_eq!(index_step(0), Some(FIRST_STEP));
        assert_eq!(index_step(681), Some(LAST_STEP));
        assert_eq!(index_step(u32::MAX), None);
    }

    #[test]
    fn distances_outside_the_range_or_field_go_out_as_no_object() {
        assert_eq!(distance_field(0, 1 << 18), NO_OBJECT_CODE);
        assert_eq!(distance_field(19, 1 << 18), NO_OBJECT_CODE);
        assert_eq!(distance_field(20, 1 << 18), 20);
        assert_eq!(distance_field(5600, 1 << 18), 5600);
        assert_eq!(distance_field(5601, 1 << 18), NO_OBJECT_CODE);
        assert_eq!(distance_field(4096, 4095), NO_OBJECT_CODE);
    }

    #[test]
    fn the_clock_wraps_at_24_bits() {
        assert_eq!(clock_ms(1.2345), 1234);
        assert_eq!(clock_ms(16_777.216), 0);
        assert_eq!(clock_ms(-0.001), (1 << 24) - 1);
        assert_eq!(clock_ms(f64::NAN), 0);
    }
}
