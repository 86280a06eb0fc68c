//! The calibrations as HTML tables: each coefficient with its unit and standard error, the
//! quality figures, the checks and the notes.

use std::fmt::Write as _;

use hilsim_calibrator::Calibration;

use crate::svg::{escape, fmt_sig};

/// The unit of coefficient `i` of eq. (2): the term α_i d^i is metres, so α_i is m^(1−i).
fn unit(i: usize) -> &'static str {
    match i {
        0 => "m",
        1 => "",
        2 => "1/m",
        3 => "1/m²",
        _ => "m^(1−i)",
    }
}

/// "0.0123 ± 0.0004 m".
fn coefficient(value: f64, sd: Option<f64>, unit: &str) -> String {
    let sd = match sd {
        Some(sd) if sd > 0.0 && sd.is_finite() => format!(" ± {}", fmt_sig(sd)),
        _ => String::new(),
    };
    format!("{}{sd} {unit}", fmt_sig(value))
        .trim_end()
        .to_string()
}

/// One HTML section per calibration.
#[must_use]
pub fn calibration_tables(calibrations: &[Calibration]) -> String {
    let mut s = String::new();
    for c in calibrations {
        let _ = writeln!(
            s,
            "<h3>{} <span class=\"muted\">({} iterations, {})</span></h3>",
            escape(c.method.name()),
            c.iterations,
            if c.converged {
                "converged"
            } else {
                "not converged"
            }
        );
        if let Some(o) = &c.odometry {
            s.push_str(&odometry_table(o));
        }
        if !c.sensors.is_empty() {
            let _ = writeln!(
            s,
            "<table><tr><th>sensor</th><th>bias α (reading = Σ α<sub>i</sub> d<sup>i</sup>)</th><th>noise β (σ = Σ β<sub>i</sub> d<sup>i</sup>)</th></tr>"
        );
            for (sensor, m) in &c.sensors {
                let list = |values: &[f64], sds: &[f64], symbol: &str| -> String {
                    values
                        .iter()
                        .enumerate()
                        .map(|(i, v)| {
                            format!(
                                "{symbol}<sub>{i}</sub> = {}",
                                escape(&coefficient(*v, sds.get(i).copied(), unit(i)))
                            )
                        })
                        .collect::<Vec<_>>()
                        .join("<br>")
                };
                let _ = writeln!(
                    s,
                    "<tr><td>{}</td><td>{}</td><td>{}</td></tr>",
                    sensor.name(),
                    list(&m.alpha, &m.alpha_sd, "α"),
                    list(&m.beta, &m.beta_sd, "β")
                );
            }
            let _ = writeln!(s, "</table>");
        }
        if let Some(m) = &c.metrics {
            let rms = |mse: f64| fmt_sig(mse.max(0.0).sqrt() * 1000.0);
            let _ = writeln!(
                s,
                "<p>Distance estimates against the truth: RMS error {} mm raw, {} mm calibrated (MSE {} → {} m², ratio {}).",
                rms(m.mse_raw),
                rms(m.mse_calibrated),
                fmt_sig(m.mse_raw),
                fmt_sig(m.mse_calibrated),
                fmt_sig(m.mse_ratio())
            );
            if let Some(l) = &m.lidar_model {
                let _ = write!(
                    s,
                    " The lidar model alone, over {} readings: RMS {} mm raw, {} mm calibrated (ratio {}).",
                    l.readings,
                    rms(l.mse_raw),
                    rms(l.mse_calibrated),
                    fmt_sig(l.mse_ratio)
                );
            }
            let _ = writeln!(s, "</p>");
        }
        if !c.checks.is_empty() {
            let _ = writeln!(
                s,
                "<table><tr><th>check</th><th>value</th><th>bound</th><th></th><th>what it means</th></tr>"
            );
            for k in &c.checks {
                let _ = writeln!(
                    s,
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"{}\">{}</td><td>{}</td></tr>",
                    escape(&k.name),
                    fmt_sig(k.value),
                    fmt_sig(k.threshold),
                    if k.pass { "pass" } else { "fail" },
                    if k.pass { "pass" } else { "FAIL" },
                    escape(&k.detail)
                );
            }
            let _ = writeln!(s, "</table>");
        }
        for note in &c.notes {
            let _ = writeln!(s, "<p class=\"muted\">note: {}</p>", escape(note));
        }
    }
    s
}

/// The wheels and the lidar's mount with their standard deviations, in the units they are
/// measured in on a robot (millimetres, milliradians and degrees).
fn odometry_table(o: &hilsim_calibrator::OdometryModel) -> String {
    let sd = o.standard_deviations();
    let mut s = String::from(
        "<table><tr><th>parameter</th><th>estimate</th><th>standard deviation</th></tr>\n",
    );
    let rows = [
        (
            "left wheel radius",
            o.left_wheel_radius_m * 1e3,
            sd[0] * 1e3,
            "mm",
        ),
        (
            "right wheel radius",
            o.right_wheel_radius_m * 1e3,
            sd[1] * 1e3,
            "mm",
        ),
        ("wheel base", o.wheel_base_m * 1e3, sd[2] * 1e3, "mm"),
        ("lidar x (forward)", o.lidar_x_m * 1e3, sd[3] * 1e3, "mm"),
        ("lidar y (left)", o.lidar_y_m * 1e3, sd[4] * 1e3, "mm"),
        (
            "lidar yaw",
            o.lidar_yaw_rad.to_degrees(),
            sd[5].to_degrees(),
            "°",
        ),
    ];
    for (name, value, sd, unit) in rows {
        // The estimate to the standard deviation's second significant digit.
        let decimals = if sd > 0.0 && sd.is_finite() {
            (1 - sd.log10().floor() as i32).clamp(0, 9) as usize
        } else {
            3
        };
        let _ = writeln!(
            s,
            "<tr><td>{name}</td><td>{value:.decimals$} {unit}</td><td>± {sd:.decimals$} {unit}</td></tr>"
        );
    }
    if let Some([left, right]) = o.wheel_scale {
        let _ = writeln!(
            s,
            "<tr><td>wheel scale (real travel over recorded)</td><td>left {}, right {}</td><td></td></tr>",
            fmt_sig(left),
            fmt_sig(right)
        );
    }
    s.push_str("</table>\n");
    s
}
