//! A calibration for people.

use std::fmt::Write;

use crate::{Calibration, Method, OdometryModel};

impl Calibration {
    /// One line per sensor, the metrics, the notes.
    #[must_use]
    pub fn describe(&self) -> String {
        let mut s = String::new();
        // Writing to a String cannot fail.
        let _ = self.write_description(&mut s);
        s
    }

    fn write_description(&self, s: &mut String) -> std::fmt::Result {
        writeln!(
            s,
            "{}: {} iteration(s), {}",
            self.method.name(),
            self.iterations,
            if self.converged {
                "converged"
            } else {
                "NOT converged"
            }
        )?;
        for (sensor, model) in &self.sensors {
            writeln!(
                s,
                "  {:<9} alpha {}  beta {}",
                format!("{sensor:?}").to_lowercase(),
                coefficients(&model.alpha, &model.alpha_sd),
                coefficients(&model.beta, &model.beta_sd)
            )?;
        }
        if let Some(order) = self.order {
            writeln!(s, "  order {order}")?;
        }
        if let Some(o) = &self.odometry {
            write_odometry(s, o)?;
        }
        if let Some(landmarks) = &self.landmarks {
            for (i, [x, y]) in landmarks.iter().enumerate() {
                writeln!(s, "  landmark {i}: ({x:.3}, {y:.3}) m")?;
            }
        }
        if let Some(m) = self.metrics {
            // What the first figures measure: EM's is its smoothed distance (eq. 31 of the
            // paper's comparison), which fuses every sensor and the commands.
            let what = match self.method {
                Method::Em => "smoothed distance (all sensors and commands)",
                Method::Landmarks | Method::Groundtruth | Method::Odometry => "lidar distance",
            };
            writeln!(
                s,
                "  {what}: MSE raw {:.3e} m², calibrated {:.3e} m² (ratio {:.2}); NMSE raw {:.3e}, calibrated {:.3e}",
                m.mse_raw,
                m.mse_calibrated,
                m.mse_ratio(),
                m.nmse_raw,
                m.nmse_calibrated
            )?;
            if let (Method::Em, Some(l)) = (self.method, m.lidar_model) {
                writeln!(
                    s,
                    "  lidar model alone (each raw reading inverted through it): MSE raw {:.3e} m², calibrated {:.3e} m² (ratio {:.2}, {} readings)",
                    l.mse_raw, l.mse_calibrated, l.mse_ratio, l.readings
                )?;
            }
        }
        // The passed checks in one line, each failed one with what it means.
        let passed: Vec<&str> = self
            .checks
            .iter()
            .filter(|c| c.pass)
            .map(|c| c.name.as_str())
            .collect();
        if !passed.is_empty() {
            writeln!(s, "  checks passed: {}", passed.join(", "))?;
        }
        for check in self.checks.iter().filter(|c| !c.pass) {
            writeln!(s, "  check FAILED: {}: {}", check.name, check.detail)?;
        }
        for note in &self.notes {
            writeln!(s, "  note: {note}")?;
        }
        Ok(())
    }
}

/// `[a, b]`, or `[a ± sa, b ± sb]` with standard errors (a coefficient held at 0 has none).
fn coefficients(c: &[f64], sd: &[f64]) -> String {
    let parts: Vec<String> = c
        .iter()
        .enumerate()
        .map(|(i, v)| match sd.get(i) {
            Some(sd) if *sd > 0.0 => format!("{v:.5} ± {sd:.5}"),
            _ => format!("{v:.5}"),
        })
        .collect();
    format!("[{}]", parts.join(", "))
}

/// The wheels and the mount with their standard deviations, in millimetres and milliradians
/// (the sizes a robot's owner measures them in).
fn write_odometry(s: &mut String, o: &OdometryModel) -> std::fmt::Result {
    let sd = o.standard_deviations();
    writeln!(
        s,
        "  wheel radius   left {:.3} ± {:.3} mm   right {:.3} ± {:.3} mm",
        o.left_wheel_radius_m * 1e3,
        sd[0] * 1e3,
        o.right_wheel_radius_m * 1e3,
        sd[1] * 1e3
    )?;
    if let Some([left, right]) = o.wheel_scale {
        writeln!(
            s,
            "  wheel scale    left {left:.5}   right {right:.5}   (real travel over recorded)"
        )?;
    }
    if let Some(latency) = o.lidar_latency_s {
        let sd = o
            .lidar_latency_sd_s
            .map_or(String::new(), |sd| format!(" ± {:.1}", sd * 1e3));
        writeln!(
            s,
            "  lidar latency  {:+.1}{sd} ms   (its stamps against the encoders')",
            latency * 1e3
        )?;
    }
    writeln!(
        s,
        "  wheel base     {:.3} ± {:.3} mm",
        o.wheel_base_m * 1e3,
        sd[2] * 1e3
    )?;
    writeln!(
        s,
        "  lidar mount    x {:.2} ± {:.2} mm   y {:.2} ± {:.2} mm   yaw {:.2} ± {:.2} mrad ({:.3}°)",
        o.lidar_x_m * 1e3,
        sd[3] * 1e3,
        o.lidar_y_m * 1e3,
        sd[4] * 1e3,
        o.lidar_yaw_rad * 1e3,
        sd[5] * 1e3,
        o.lidar_yaw_rad.to_degrees()
    )
}
