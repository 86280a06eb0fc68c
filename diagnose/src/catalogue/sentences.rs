//! The sentence each effect's verdict is told in.

use hilsim_sim::scenario::RangeBias;

use super::{range_bias, Effect, REFERENCE_REFLECTIVITY};

impl Effect {
    /// One sentence: the physics the simulation left out, with the fitted parameters (and the
    /// declared sonar cone the beam width replaces).
    #[must_use]
    pub fn explanation(self, params: &[f64], declared_half_angle_deg: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        match self {
            Effect::LidarIncidenceAngle => format!(
                "The simulated lidar ranges every surface as if it met it head-on; the real one's \
                 range error grows with the angle of incidence ({:+.1} mm at 45° at 1 m, {:+.1} mm \
                 at 4 m{}).",
                (p(0) + p(1)) * 1000.0,
                (p(0) * 4.0 + p(1)) * 1000.0,
                incidence_form(p(2))
            ),
            Effect::LidarReflectivity => format!(
                "The simulated lidar ranges every material alike; the real one's range walks with \
                 the surface's reflectivity ({:+.1} mm on a surface of half the reference's).",
                p(0) * 1000.0
            ),
            Effect::LidarMixedPixels => format!(
                "The simulated lidar's beam is a line; the real beam is {:.2}° wide, and where it \
                 grazes an edge it returns a range between foreground and background.",
                2.0 * p(0)
            ),
            Effect::LidarMotionSkew => format!(
                "The simulated lidar takes a whole revolution at one instant; the real one turns \
                 for {:.2} s while the robot moves.",
                p(0)
            ),
            Effect::LidarWarmupDrift => format!(
                "The simulated lidar is warm from power-on; the real one's range bias drifts as it \
                 warms up ({:+.1} mm at 0.5 m and {:+.1} mm at 4 m at power-on, settling with a \
                 {:.0} s time constant).",
                (p(2) + p(0) * 0.25) * 1000.0,
                (p(2) + p(0) * 16.0) * 1000.0,
                p(1)
            ),
            Effect::SonarBeamWidth if declared_half_angle_deg > 0.0 => format!(
                "The simulated sonar's cone is ±{declared_half_angle_deg:.1}°; the real one \
                 returns the nearest echo anywhere in a cone of ±{:.1}°.",
                p(0)
            ),
            Effect::SonarBeamWidth => format!(
                "The simulated sonar sees along its axis only; the real one returns the nearest \
                 echo anywhere in a cone of ±{:.1}°.",
                p(0)
            ),
            Effect::SonarSpeedOfSound => format!(
                "The simulated sonar assumes sound travels at its calibration temperature (20 °C); \
                 the real air was at {:.1} °C, which scales every range.",
                p(0)
            ),
            Effect::OdometerWheelSlip => slip_sentence(p(0), params.get(1).copied()),
            Effect::DriveMotorLag if p(1) >= 0.1 => format!(
                "The simulated wheels reach a commanded speed at once; the real ones reach \
                 1 − 1/e of a step in {:.2} s through a second-order response of damping {:.2}{}.",
                p(0),
                1.0 / p(1),
                if p(1) > 1.0 {
                    ", overshooting before they settle"
                } else {
                    ""
                }
            ),
            Effect::DriveMotorLag => format!(
                "The simulated wheels reach a commanded speed at once; the real ones follow it \
                 with a first-order lag of {:.2} s.",
                p(0)
            ),
            Effect::LidarMountOffset => format!(
                "The simulated lidar sits where the scenario says; the real one is turned \
                 {:+.2}° and moved {:+.1} mm forward, {:+.1} mm left of that.",
                p(0),
                p(1) * 1000.0,
                p(2) * 1000.0
            ),
            Effect::SensorLatency(sensor) => format!(
                "The simulated {sensor} is stamped when it measures; the real one's timestamps \
                 come {:.0} ms later.",
                p(0) * 1000.0
            ),
            Effect::OdometerWheelRadius => format!(
                "The simulated wheels have their nominal radius; the real left one is {:.1} % \
                 and the right one {:.1} % of it, so the robot moves that much of its command \
                 while the encoders report the command.",
                p(0) * 100.0,
                p(1) * 100.0
            ),
            Effect::DriveWheelBase => format!(
                "The simulated wheels turn the robot about the nominal wheel base; the real \
                 effective base is {:.1} % of it, so every turn comes out {:.1} % as large.",
                p(0) * 100.0,
                100.0 / p(0)
            ),
            Effect::LidarRangeBias => range_bias_sentence(&range_bias(params)),
            Effect::SonarRangeBias => format!(
                "The real sonar reads {:+.1} mm more than the scenario's range bias declares, at \
                 every range: its echo is detected that much later than its calibration says.",
                p(0) * 1000.0
            ),
            Effect::LidarDropout => format!(
                "The simulated lidar reads every surface within its range; the real one loses \
                 returns too weak to range: half of them at {:.1} m head-on on a surface of \
                 reflectivity {REFERENCE_REFLECTIVITY}, nearer at grazing incidence and on darker \
                 surfaces (head-on, from 12 % lost at {:.1} m to 88 % at {:.1} m).",
                p(0),
                p(0) * (-p(1)).exp(),
                p(0) * p(1).exp()
            ),
        }
    }
}

/// The range bias's sentence: what the real lidar reads more than the scenario declares, as
/// `c + s·d` (and `q·d²` where the quadratic term is a millimetre or more at 2 m), with its size
/// at 1 m and 4 m.
fn range_bias_sentence(bias: &RangeBias) -> String {
    let [offset_m, scale_error, quadratic_per_m] = bias.coefficients();
    let at = |d: f64| (offset_m + scale_error * d + quadratic_per_m * d * d) * 1000.0;
    let quadratic = if (quadratic_per_m * 4.0).abs() >= 0.001 {
        format!(" {:+.1} mm/m² · d²", quadratic_per_m * 1000.0)
    } else {
        String::new()
    };
    format!(
        "The real lidar reads {:+.1} mm {:+.2} % · d{quadratic} more than the scenario's range \
         bias declares ({:+.1} mm at 1 m, {:+.1} mm at 4 m): its calibration differs from the \
         declared one.",
        offset_m * 1000.0,
        scale_error * 100.0,
        at(1.0),
        at(4.0)
    )
}

/// How the incidence's error grows past 45°, where its form departs from the catalogue's
/// first-order `tan θ` (the footprint's depth) by more than its grid resolves; else nothing.
fn incidence_form(exponent: f64) -> String {
    // A tenth of the fit's √2 grid step in the power.
    if !exponent.is_finite() || (exponent - 1.0).abs() < 0.04 {
        return String::new();
    }
    let pace = if exponent > 1.0 { "faster" } else { "slower" };
    format!(
        "; it grows as tan^{exponent:.2} θ, {pace} than the footprint's depth: the shape differs \
         from the catalogue's tan θ"
    )
}

/// The slip's sentence: its driving gain, and how braking departs from giving back the lead
/// when the braking share (the braking gain over the driving one) is not even.
fn slip_sentence(gain_s: f64, braking_share: Option<f64>) -> String {
    let ms = gain_s * 1000.0;
    let even = "The simulated wheels grip perfectly; the real ones slip as they accelerate, so";
    // Within a tenth of the fit's 0.5 grid step of even.
    match braking_share {
        Some(share) if share.is_finite() && (share - 1.0).abs() >= 0.05 => {
            let braking = if share.abs() < 0.05 {
                "braking gives none of it back".to_string()
            } else if share < 0.0 {
                format!(
                    "braking adds {:.0} ms × the change of speed to the lead instead of giving it \
                     back",
                    -share * ms
                )
            } else {
                format!("braking gives back {:.0} % of it", share * 100.0)
            };
            format!(
                "{even} the encoders gain {ms:.0} ms × the change of speed on speeding up, and \
                 {braking}: the shape differs from the catalogue's even slip."
            )
        }
        _ => format!("{even} the encoders lead the true travel by {ms:.0} ms × the wheel's speed."),
    }
}
