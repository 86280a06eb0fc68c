//! `lidar_range_bias` and `sonar_range_bias`: the real unit's range bias differs from the one
//! the scenario declares.
//!
//! Both papers model a range finder's reading as `Σ alpha_i d^i + noise` (eq. 2), the bias
//! polynomial being the unit's calibration: a unit's own differs from a datasheet's or
//! another unit's. A triangulation unit (`d = f b / x`, Konolige et al., ICRA 2008) shows the
//! low orders of that difference directly: an offset of its range origin from the head's axis
//! adds a constant, a baseline or focal length off by a fraction scales every range (`d b'/b`),
//! and a small laser-angle error δ adds `≈ d² δ / b`. The difference is therefore modelled as
//! the polynomial `c + s d + q d²` added to the declared one; the noise is the declared one's.
//! A sonar's is the same polynomial (the EM paper's sonar is affine, `c + s d`): its offset a
//! threshold detection that fires later or earlier in the echo than calibrated.

use hilsim_sim::scenario::RangeBias;

/// The real unit's bias polynomial: the `declared` coefficients (eq. 2's alpha, lowest order
/// first) plus `bias`'s. Exactly `declared` when `bias` is `None`.
///
/// ```
/// use hilsim_lidar_emulator::effects::real_bias;
/// use hilsim_sim::scenario::RangeBias;
/// let declared = [0.0525, 0.8838, 0.0584];
/// assert_eq!(real_bias(&declared, None), declared);
/// let bias = RangeBias { offset_m: 0.03, scale_error: -0.01, quadratic_per_m: 0.0 };
/// let real = real_bias(&[0.0, 1.0], Some(&bias));
/// assert_eq!(real, [0.03, 0.99, 0.0]);
/// ```
#[must_use]
pub fn real_bias(declared: &[f64], bias: Option<&RangeBias>) -> Vec<f64> {
    let mut alpha = declared.to_vec();
    let Some(bias) = bias else {
        return alpha;
    };
    let extra = bias.coefficients();
    if alpha.len() < extra.len() {
        alpha.resize(extra.len(), 0.0);
    }
    for (a, e) in alpha.iter_mut().zip(extra) {
        *a += e;
    }
    alpha
}
