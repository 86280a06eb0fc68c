//! `lidar_dropout`: returns too weak to range are lost, and the unit reports the reading
//! invalid.
//!
//! A triangulation unit ranges from the image of its laser spot on a CMOS line sensor
//! (Konolige et al., "A low-cost laser distance sensor", ICRA 2008); the spot's image must stand
//! above the sensor's noise to be found. The power a diffuse (Lambertian) surface filling the
//! spot sends back into the fixed receiving aperture goes as `ρ cos θ / d²` (reflectivity ρ,
//! incidence θ, range d), so a fixed detection threshold on that power loses the far returns,
//! the grazing ones and those from dark surfaces. With the received power's reading-to-reading
//! scatter (speckle, exposure control) logistic in its logarithm with scale s, the chance that a
//! reading is lost is the logistic of the threshold's excess over the expected log power:
//! `1 / (1 + e^{−z/s})`, `z = 2 ln(d / d½) − ln cos θ − ln(ρ / ρ_ref)`, d½ the range at which
//! half are lost head-on on a surface of reflectivity `ρ_ref`. A surface that is not diffuse
//! returns `cos^m θ` instead (m the dropout's `incidence_power`: above 1 a glossy one's lobe;
//! 0 a unit whose gain is set so that the range alone decides).

use hilsim_sim::scenario::LidarDropout;

/// The chance that a reading of a surface of reflectivity `reflectivity` at `range_m`, met at
/// `|cos θ|` = `cos_incidence`, is lost under `dropout`. A return with no power (ρ of 0, or
/// `cos θ` of 0 when the power falls with the incidence) is always lost; a range of 0 never.
///
/// ```
/// use hilsim_lidar_emulator::effects::dropout_probability;
/// use hilsim_sim::scenario::LidarDropout;
/// let d = LidarDropout {
///     half_loss_range_m: 4.0,
///     log_power_spread: 0.3,
///     reference: 0.8,
///     incidence_power: 1.0,
/// };
/// assert!((dropout_probability(&d, 4.0, 1.0, 0.8) - 0.5).abs() < 1e-12);
/// // Twice as far is a quarter of the power, as is a quarter of the reflectivity.
/// let far = dropout_probability(&d, 8.0, 1.0, 0.8);
/// assert!((far - dropout_probability(&d, 4.0, 1.0, 0.2)).abs() < 1e-12);
/// assert!(far > 0.98);
/// assert!(dropout_probability(&d, 4.0, 0.5, 0.8) > 0.9);
/// // Lost by the range alone: half at 4 m, whatever the incidence.
/// let by_range = LidarDropout { incidence_power: 0.0, ..d };
/// assert!((dropout_probability(&by_range, 4.0, 0.5, 0.8) - 0.5).abs() < 1e-12);
/// ```
#[must_use]
pub fn dropout_probability(
    dropout: &LidarDropout,
    range_m: f64,
    cos_incidence: f64,
    reflectivity: f64,
) -> f64 {
    dropout_probability_of(
        dropout,
        &ReturnLogs::new(range_m, cos_incidence, reflectivity),
    )
}

/// The logarithms of a return's range, `|cos θ|` and reflectivity: its log power apart from
/// the dropout's parameters, taken once for a reading weighed under many dropouts (a fit's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReturnLogs {
    ln_range: f64,
    ln_cos_incidence: f64,
    ln_reflectivity: f64,
}

impl ReturnLogs {
    /// A reading of a surface of reflectivity `reflectivity` at `range_m`, met at `|cos θ|` =
    /// `cos_incidence`.
    #[must_use]
    pub fn new(range_m: f64, cos_incidence: f64, reflectivity: f64) -> Self {
        Self {
            ln_range: range_m.ln(),
            ln_cos_incidence: cos_incidence.abs().ln(),
            ln_reflectivity: reflectivity.ln(),
        }
    }
}

/// [`dropout_probability`] of a return given by its logarithms.
#[must_use]
pub fn dropout_probability_of(dropout: &LidarDropout, r: &ReturnLogs) -> f64 {
    // cos⁰ θ is 1 whatever θ, a grazing return's too.
    let incidence = if dropout.incidence_power == 0.0 {
        0.0
    } else {
        dropout.incidence_power * r.ln_cos_incidence
    };
    let ln_power = r.ln_reflectivity - dropout.reference.ln() + incidence
        - 2.0 * (r.ln_range - dropout.half_loss_range_m.ln());
    // No power, or none defined (a negative reflectivity, a range of 0 on a black surface).
    if ln_power.is_nan() || ln_power == f64::NEG_INFINITY {
        return 1.0;
    }
    // z = −ln(power relative to the threshold's), in units of the scatter.
    let z = -ln_power / dropout.log_power_spread;
    1.0 / (1.0 + (-z).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The loss grows with the range, the incidence and darkness, and is the logistic of the
    /// log power: 12 % and 88 % lost at ranges `d½ e^{∓s}` head-on.
    #[test]
    fn the_loss_is_logistic_in_the_returned_log_power() {
        let d = LidarDropout {
            half_loss_range_m: 5.0,
            log_power_spread: 0.25,
            reference: 0.8,
            incidence_power: 1.0,
        };
        let logistic = |x: f64| 1.0 / (1.0 + (-x).exp());
        let near = dropout_probability(&d, 5.0 * (-0.25f64).exp(), 1.0, 0.8);
        let far = dropout_probability(&d, 5.0 * 0.25f64.exp(), 1.0, 0.8);
        assert!((near - logistic(-2.0)).abs() < 1e-12, "{near}");
        assert!((far - logistic(2.0)).abs() < 1e-12, "{far}");
        assert!(dropout_probability(&d, 3.0, 0.3, 0.8) > dropout_probability(&d, 3.0, 0.9, 0.8));
        assert!(dropout_probability(&d, 3.0, 1.0, 0.1) > dropout_probability(&d, 3.0, 1.0, 0.8));
        assert_eq!(dropout_probability(&d, 3.0, 0.0, 0.8), 1.0);
        assert_eq!(dropout_probability(&d, 0.0, 1.0, 0.8), 0.0);
        assert_eq!(dropout_probability(&d, f64::NAN, 1.0, 0.8), 1.0);
        assert_eq!(dropout_probability(&d, 3.0, 1.0, 0.0), 1.0);
        assert_eq!(dropout_probability(&d, 3.0, 1.0, -0.2), 1.0);
        assert_eq!(dropout_probability(&d, 0.0, 1.0, 0.0), 1.0);
        // By the range alone, a grazing return is lost as a head-on one is.
        let by_range = LidarDropout {
            incidence_power: 0.0,
            ..d
        };
        assert_eq!(
            dropout_probability(&by_range, 3.0, 0.0, 0.8),
            dropout_probability(&by_range, 3.0, 1.0, 0.8)
        );
    }

    /// Weighed from its logarithms, a return is lost as the power's own formula says,
    /// `ρ cos^m θ / d²` against the threshold's (to rounding).
    #[test]
    fn a_return_weighed_by_its_logarithms_is_the_power_formula() {
        let d = LidarDropout {
            half_loss_range_m: 4.5,
            log_power_spread: 0.3,
            reference: 0.8,
            incidence_power: 1.7,
        };
        for (range_m, cos, rho) in [(0.3, 1.0, 0.8), (4.5, 0.4, 0.5), (9.0_f64, 0.9_f64, 0.1)] {
            let power = rho / d.reference * cos.powf(d.incidence_power) / (range_m / 4.5).powi(2);
            let formula = 1.0 / (1.0 + power.powf(1.0 / d.log_power_spread));
            let p = dropout_probability(&d, range_m, cos, rho);
            assert!((p - formula).abs() < 1e-12, "{p} against {formula}");
        }
    }
}
