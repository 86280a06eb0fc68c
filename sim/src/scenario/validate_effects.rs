//! The checks of the `[effects]` tables: ranges, and the sensors each effect needs.

use super::check::{fail, toml_number, Check};
use super::locate::{key_path, Key};
use super::schema::{LidarTiming, Scenario};

/// `v` must be finite and lie in `[lo, hi]`.
fn within(path: Vec<Key>, v: f64, lo: f64, hi: f64, what: &str) -> Check {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(())
    } else {
        fail(
            path,
            format!("expected {what} in {lo}..={hi}, found {}", toml_number(v)),
        )
    }
}

/// `v` must be finite, positive and at most `hi`.
fn positive_up_to(path: Vec<Key>, v: f64, hi: f64, what: &str) -> Check {
    if v.is_finite() && v > 0.0 && v <= hi {
        Ok(())
    } else {
        fail(
            path,
            format!("expected {what} in (0, {hi}], found {}", toml_number(v)),
        )
    }
}

fn needs(path: Vec<Key>, present: bool, sensor: &str) -> Check {
    if present {
        Ok(())
    } else {
        fail(
            path,
            format!("this effect needs a [sensors.{sensor}]: the robot has no {sensor}"),
        )
    }
}

/// Ranges and references of the `[effects]` tables.
pub(super) fn validate(s: &Scenario) -> Check {
    let e = &s.effects;
    let lidar = s.sensors.lidar.as_ref();
    let has_sonar = s.sensors.sonar.is_some();
    if let Some(x) = e.lidar_incidence_angle {
        let p = |k: &'static str| key_path!["effects", "lidar_incidence_angle", k];
        needs(p("coefficient"), lidar.is_some(), "lidar")?;
        within(p("coefficient"), x.coefficient, -0.2, 0.2, "a coefficient")?;
        within(p("collimated_m"), x.collimated_m, -0.1, 0.1, "metres")?;
        within(p("exponent"), x.exponent, 0.25, 4.0, "an exponent")?;
    }
    if let Some(x) = e.lidar_reflectivity {
        let p = |k: &'static str| key_path!["effects", "lidar_reflectivity", k];
        needs(p("coefficient_m"), lidar.is_some(), "lidar")?;
        within(p("coefficient_m"), x.coefficient_m, -0.1, 0.1, "metres")?;
        positive_up_to(p("reference"), x.reference, 1.0, "a reflectivity")?;
    }
    if let Some(x) = e.lidar_mixed_pixels {
        let p = |k: &'static str| key_path!["effects", "lidar_mixed_pixels", k];
        needs(p("half_width_deg"), lidar.is_some(), "lidar")?;
        positive_up_to(p("half_width_deg"), x.half_width_deg, 5.0, "degrees")?;
    }
    if e.lidar_motion_skew.is_some() {
        let path = key_path!["effects", "lidar_motion_skew"];
        needs(path.clone(), lidar.is_some(), "lidar")?;
        if lidar.is_some_and(|l| l.timing != LidarTiming::PerRevolution) {
            return fail(
                path,
                "this effect needs `[sensors.lidar] timing = \"per_revolution\"`: a per-reading \
                 lidar already takes each reading at its own instant",
            );
        }
    }
    if let Some(x) = e.lidar_warmup_drift {
        let p = |k: &'static str| key_path!["effects", "lidar_warmup_drift", k];
        needs(p("coefficient_per_m"), lidar.is_some(), "lidar")?;
        within(
            p("coefficient_per_m"),
            x.coefficient_per_m,
            -0.1,
            0.1,
            "a coefficient per metre",
        )?;
        positive_up_to(p("time_constant_s"), x.time_constant_s, 3600.0, "seconds")?;
        within(p("offset_m"), x.offset_m, -0.5, 0.5, "an offset in metres")?;
        within(p("stretch"), x.stretch, 0.1, 10.0, "an exponent")?;
    }
    if let Some(x) = e.sonar_beam_width {
        let p = |k: &'static str| key_path!["effects", "sonar_beam_width", k];
        needs(p("half_angle_deg"), has_sonar, "sonar")?;
        if !(x.half_angle_deg.is_finite() && (0.0..90.0).contains(&x.half_angle_deg)) {
            return fail(
                p("half_angle_deg"),
                format!(
                    "expected 0 ≤ half_angle_deg < 90, found {}",
                    toml_number(x.half_angle_deg)
                ),
            );
        }
        within(p("centroid_share"), x.centroid_share, 0.0, 1.0, "a share")?;
    }
    if let Some(x) = e.sonar_speed_of_sound {
        let p = |k: &'static str| key_path!["effects", "sonar_speed_of_sound", k];
        needs(p("air_temperature_c"), has_sonar, "sonar")?;
        within(
            p("air_temperature_c"),
            x.air_temperature_c,
            -50.0,
            60.0,
            "°C",
        )?;
        within(p("calibrated_at_c"), x.calibrated_at_c, -50.0, 60.0, "°C")?;
    }
    if let Some(x) = e.odometer_wheel_slip {
        let p = |k: &'static str| key_path!["effects", "odometer_wheel_slip", k];
        needs(p("gain_s"), s.sensors.odometer.is_some(), "odometer")?;
        within(p("gain_s"), x.gain_s, -1.0, 1.0, "seconds")?;
        if let Some(braking) = x.braking_gain_s {
            within(p("braking_gain_s"), braking, -1.0, 1.0, "seconds")?;
        }
    }
    if let Some(x) = e.drive_motor_lag {
        let p = |k: &'static str| key_path!["effects", "drive_motor_lag", k];
        positive_up_to(p("time_constant_s"), x.time_constant_s, 10.0, "seconds")?;
        if let Some(damping) = x.damping {
            // Below 0.1 a wheel rings for tens of periods; past 10 the response is the
            // first-order lag's to within a tenth of a percent.
            within(p("damping"), damping, 0.1, 10.0, "a damping ratio")?;
        }
    }
    // The bounds below are far beyond any real unit (a lidar 45° off its mount, a wheel half
    // again as large, a second of latency): values outside them are typos.
    if let Some(x) = e.lidar_mount_offset {
        let p = |k: &'static str| key_path!["effects", "lidar_mount_offset", k];
        needs(p("yaw_deg"), lidar.is_some(), "lidar")?;
        within(p("yaw_deg"), x.yaw_deg, -45.0, 45.0, "degrees")?;
        within(p("x_m"), x.x_m, -0.5, 0.5, "metres")?;
        within(p("y_m"), x.y_m, -0.5, 0.5, "metres")?;
    }
    if let Some(x) = e.sensor_latency {
        let p = |k: &'static str| key_path!["effects", "sensor_latency", k];
        for (key, v, present, sensor) in [
            ("lidar_s", x.lidar_s, lidar.is_some(), "lidar"),
            ("sonar_s", x.sonar_s, has_sonar, "sonar"),
            (
                "odometer_s",
                x.odometer_s,
                s.sensors.odometer.is_some(),
                "odometer",
            ),
        ] {
            within(p(key), v, 0.0, 1.0, "seconds")?;
            if v != 0.0 {
                needs(p(key), present, sensor)?;
            }
        }
    }
    if let Some(x) = e.odometer_wheel_radius {
        let p = |k: &'static str| key_path!["effects", "odometer_wheel_radius", k];
        within(p("left_scale"), x.left_scale, 0.5, 1.5, "a scale")?;
        within(p("right_scale"), x.right_scale, 0.5, 1.5, "a scale")?;
    }
    if let Some(x) = e.drive_wheel_base {
        let p = |k: &'static str| key_path!["effects", "drive_wheel_base", k];
        within(p("scale"), x.scale, 0.5, 1.5, "a scale")?;
    }
    for (table, bias, present, sensor) in [
        (
            "lidar_range_bias",
            e.lidar_range_bias,
            lidar.is_some(),
            "lidar",
        ),
        ("sonar_range_bias", e.sonar_range_bias, has_sonar, "sonar"),
    ] {
        let Some(x) = bias else { continue };
        let p = |k: &'static str| key_path!["effects", table, k];
        needs(p("offset_m"), present, sensor)?;
        within(p("offset_m"), x.offset_m, -0.5, 0.5, "metres")?;
        within(p("scale_error"), x.scale_error, -0.5, 0.5, "a scale error")?;
        within(
            p("quadratic_per_m"),
            x.quadratic_per_m,
            -0.1,
            0.1,
            "a coefficient per metre",
        )?;
    }
    if let Some(x) = e.lidar_dropout {
        let p = |k: &'static str| key_path!["effects", "lidar_dropout", k];
        needs(p("half_loss_range_m"), lidar.is_some(), "lidar")?;
        positive_up_to(p("half_loss_range_m"), x.half_loss_range_m, 100.0, "metres")?;
        positive_up_to(p("log_power_spread"), x.log_power_spread, 5.0, "a spread")?;
        positive_up_to(p("reference"), x.reference, 1.0, "a reflectivity")?;
        within(
            p("incidence_power"),
            x.incidence_power,
            0.0,
            4.0,
            "an exponent",
        )?;
    }
    Ok(())
}
