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
    let power = reflectivity / dropout.reference
        * cos_incidence.abs().powf(dropout.incidence_power)
        / (range_m / dropout.half_loss_range_m).powi(2);
    if power.is_nan() || power <= 0.0 {
        return 1.0;
    }
    // z = −ln(power relative to the threshold's), in units of the scatter.
    let z = -power.ln() / dropout.log_power_spread;
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
    }
}
