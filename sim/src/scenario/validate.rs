//! Checks that serde cannot express: ranges, exactly-one-kind drive steps, references, and
//! geometry (the robot must not start inside an obstacle).

use super::check::{fail, toml_number, Check};
use super::locate::{key_path, Key};
use super::metrics;
use super::schema::{DriveStep, LidarModel, Scenario};
use super::validate_effects;
use crate::world::Obstacle;

/// The longest run a scenario may describe, seconds: a day. A recording of a day at the default
/// rates is a few GB; a longer one is a mistake (`duration_s = 1e9`), not an experiment.
pub const MAX_RUN_S: f64 = 86_400.0;
/// The largest coordinate or size in a world, metres: rapier computes in `f32`, whose resolution
/// at 1 km is 0.06 mm, still below the sensors' millimetre; beyond, geometry degrades.
pub const MAX_WORLD_M: f64 = 1_000.0;
/// The largest angle of a pose or mount, degrees (one turn either way; a larger one is a typo).
pub const MAX_ANGLE_DEG: f64 = 360.0;
/// The fastest sonar ping or odometer report, Hz: faster than any ultrasonic ranger's echo or
/// wheel encoder's report, and at most 86.4 million samples in a day's run.
pub const MAX_SENSOR_RATE_HZ: f64 = 1_000.0;

fn angle(path: Vec<Key>, deg: f64) -> Check {
    finite(path.clone(), deg)?;
    if deg.abs() > MAX_ANGLE_DEG {
        return fail(
            path,
            format!("expected an angle within ±{MAX_ANGLE_DEG} degrees, found {deg}"),
        );
    }
    Ok(())
}

fn size(path: Vec<Key>, v: f64) -> Check {
    positive(path.clone(), v)?;
    if v > MAX_WORLD_M {
        return fail(
            path,
            format!("expected at most {MAX_WORLD_M} m (rapier's f32 precision), found {v}"),
        );
    }
    Ok(())
}

fn rate(path: Vec<Key>, hz: f64) -> Check {
    positive(path.clone(), hz)?;
    if hz > MAX_SENSOR_RATE_HZ {
        return fail(
            path,
            format!("expected at most {MAX_SENSOR_RATE_HZ} Hz, found {hz}"),
        );
    }
    Ok(())
}

fn finite(path: Vec<Key>, v: f64) -> Check {
    if v.is_finite() {
        Ok(())
    } else {
        fail(
            path,
            format!("expected a finite number, found {}", toml_number(v)),
        )
    }
}

fn positive(path: Vec<Key>, v: f64) -> Check {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        fail(
            path,
            format!("expected a positive number, found {}", toml_number(v)),
        )
    }
}

fn non_negative(path: Vec<Key>, v: f64) -> Check {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        fail(
            path,
            format!("expected a number ≥ 0, found {}", toml_number(v)),
        )
    }
}

fn point(path: Vec<Key>, p: [f64; 2]) -> Check {
    if !p.iter().all(|c| c.is_finite()) {
        return fail(
            path,
            format!(
                "expected finite coordinates, found [{}, {}]",
                toml_number(p[0]),
                toml_number(p[1])
            ),
        );
    }
    if p.iter().any(|c| c.abs() > MAX_WORLD_M) {
        return fail(
            path,
            format!(
                "expected coordinates within ±{MAX_WORLD_M} m (rapier's f32 precision), found [{}, {}]",
                p[0], p[1]
            ),
        );
    }
    Ok(())
}

/// Polynomial coefficients of eq. (2): finite, and for noise also non-negative (a standard
/// deviation polynomial with negative terms can go negative).
fn polynomial(path: Vec<Key>, coeffs: &[f64], non_negative_terms: bool) -> Check {
    if coeffs.is_empty() {
        return fail(path, "expected at least one coefficient");
    }
    if coeffs.len() > 8 {
        return fail(path, "expected at most 8 coefficients (order 7)");
    }
    for &c in coeffs {
        if !c.is_finite() || (non_negative_terms && c < 0.0) {
            let what = if non_negative_terms {
                "finite coefficients ≥ 0 (a standard deviation)"
            } else {
                "finite coefficients"
            };
            let shown: Vec<String> = coeffs.iter().map(|&c| toml_number(c)).collect();
            return fail(
                path,
                format!("expected {what}, found [{}]", shown.join(", ")),
            );
        }
    }
    Ok(())
}

pub(super) fn validate(s: &Scenario) -> Check {
    if s.name.trim().is_empty() {
        return fail(key_path!["name"], "expected a non-empty name");
    }
    if let Some(d) = s.duration_s {
        positive(key_path!["duration_s"], d)?;
        if d > MAX_RUN_S {
            return fail(
                key_path!["duration_s"],
                format!("expected at most {MAX_RUN_S} s (a day), found {d}"),
            );
        }
    }
    let hz = s.physics.step_hz;
    if !(hz.is_finite() && (10.0..=10_000.0).contains(&hz)) {
        return fail(
            key_path!["physics", "step_hz"],
            format!("expected a rate in 10..=10000 Hz, found {hz}"),
        );
    }
    world(s)?;
    robot(s)?;
    drive(s)?;
    sensors(s)?;
    validate_effects::validate(s)?;
    let lidar = s.sensors.lidar.as_ref().map(|l| (l.rpm, l.rpm_wobble));
    if let Err((key, message)) = s.link.validate(lidar) {
        return fail(key_path!["link", key], message);
    }
    for (i, e) in s.expect.iter().enumerate() {
        if !metrics::is_known(&e.metric) {
            return fail(
                key_path!["expect", i, "metric"],
                format!(
                    "unknown metric `{}` (see scenarios/README.md for the list)",
                    e.metric
                ),
            );
        }
        if e.at_least.is_none() && e.at_most.is_none() {
            return fail(key_path!["expect", i], "expected `at_least` or `at_most`");
        }
        for (key, v) in [("at_least", e.at_least), ("at_most", e.at_most)] {
            if let Some(v) = v {
                finite(key_path!["expect", i, key], v)?;
            }
        }
    }
    start_is_free(s)
}

fn material(s: &Scenario, path: Vec<Key>, name: Option<&String>) -> Check {
    match name {
        Some(n) if n != "default" && !s.world.materials.contains_key(n) => fail(
            path,
            format!("unknown material `{n}`: define it under [world.materials.{n}]"),
        ),
        _ => Ok(()),
    }
}

fn world(s: &Scenario) -> Check {
    let w = &s.world;
    for (name, m) in &w.materials {
        let r = m.reflectivity;
        if !(r.is_finite() && r > 0.0 && r <= 1.0) {
            // The key path holds &'static str; a material's own name is shown in the message.
            return fail(
                key_path!["world", "materials"],
                format!("material `{name}`: reflectivity must be in (0, 1], found {r}"),
            );
        }
    }
    for (i, wall) in w.walls.iter().enumerate() {
        point(key_path!["world", "walls", i, "from"], wall.from)?;
        point(key_path!["world", "walls", i, "to"], wall.to)?;
        if (wall.from[0] - wall.to[0]).hypot(wall.from[1] - wall.to[1]) < 1e-3 {
            return fail(
                key_path!["world", "walls", i],
                "a wall must be at least 1 mm long",
            );
        }
        material(
            s,
            key_path!["world", "walls", i, "material"],
            wall.material.as_ref(),
        )?;
    }
    for (i, c) in w.cylinders.iter().enumerate() {
        point(key_path!["world", "cylinders", i, "center"], c.center)?;
        size(key_path!["world", "cylinders", i, "radius"], c.radius)?;
        material(
            s,
            key_path!["world", "cylinders", i, "material"],
            c.material.as_ref(),
        )?;
        for (j, other) in w.cylinders.iter().enumerate().take(i) {
            let gap = (c.center[0] - other.center[0]).hypot(c.center[1] - other.center[1]);
            if gap < c.radius + other.radius {
                return fail(
                    key_path!["world", "cylinders", i],
                    format!("cylinder {i} overlaps cylinder {j}: landmarks must be separate"),
                );
            }
        }
    }
    for (i, b) in w.boards.iter().enumerate() {
        point(key_path!["world", "boards", i, "center"], b.center)?;
        size(key_path!["world", "boards", i, "length"], b.length)?;
        size(key_path!["world", "boards", i, "thickness"], b.thickness)?;
        angle(key_path!["world", "boards", i, "yaw_deg"], b.yaw_deg)?;
        material(
            s,
            key_path!["world", "boards", i, "material"],
            b.material.as_ref(),
        )?;
    }
    Ok(())
}

fn robot(s: &Scenario) -> Check {
    let r = &s.robot;
    finite(key_path!["robot", "start", "x"], r.start.x)?;
    finite(key_path!["robot", "start", "y"], r.start.y)?;
    point(key_path!["robot", "start"], [r.start.x, r.start.y])?;
    angle(key_path!["robot", "start", "yaw_deg"], r.start.yaw_deg)?;
    size(key_path!["robot", "wheel_base_m"], r.wheel_base_m)?;
    size(key_path!["robot", "radius_m"], r.radius_m)?;
    size(key_path!["robot", "wheel_radius_m"], r.wheel_radius_m)?;
    positive(key_path!["robot", "turn_rate_deg_s"], r.turn_rate_deg_s)?;
    let a = r.actuation;
    non_negative(key_path!["robot", "actuation", "scale_sd"], a.scale_sd)?;
    non_negative(key_path!["robot", "actuation", "wander_sd"], a.wander_sd)?;
    if a.scale_sd > 0.2 || a.wander_sd > 0.2 {
        return fail(
            key_path!["robot", "actuation"],
            "expected speed-scale errors of at most 0.2 (20 %)",
        );
    }
    if a.wander_tau_s.is_nan() || a.wander_tau_s <= 0.0 {
        return fail(
            key_path!["robot", "actuation", "wander_tau_s"],
            "expected a positive correlation time",
        );
    }
    Ok(())
}

fn drive(s: &Scenario) -> Check {
    for (i, step) in s.drive.iter().enumerate() {
        drive_step(i, step)?;
    }
    let program_s: f64 = s
        .drive
        .iter()
        .filter_map(|step| step.duration_s(s.robot.turn_rate_deg_s))
        .sum();
    if program_s > MAX_RUN_S {
        return fail(
            key_path!["drive"],
            format!(
                "the drive program lasts {program_s} s; expected at most {MAX_RUN_S} s (a day)"
            ),
        );
    }
    if s.robot.path.is_some() && !s.drive.is_empty() {
        return fail(
            key_path!["drive"],
            "the robot follows `[robot] path`: a drive program would have nothing to drive",
        );
    }
    if s.drive.is_empty() && s.duration_s.is_none() {
        return fail(
            key_path!["drive"],
            "the drive program is empty and `duration_s` is not set: the run would have no end",
        );
    }
    Ok(())
}

fn drive_step(i: usize, step: &DriveStep) -> Check {
    let present: Vec<&str> = [
        ("speed_mps", step.speed_mps.is_some()),
        ("distance_m", step.distance_m.is_some()),
        ("stop_s", step.stop_s.is_some()),
        ("turn_deg", step.turn_deg.is_some()),
    ]
    .iter()
    .filter(|(_, p)| *p)
    .map(|(k, _)| *k)
    .collect();
    let expected = "each step is one kind: `speed_mps` + `distance_m`, `stop_s`, or `turn_deg`";
    match (step.speed_mps, step.distance_m, step.stop_s, step.turn_deg) {
        (Some(v), Some(d), None, None) => {
            finite(key_path!["drive", i, "speed_mps"], v)?;
            if v == 0.0 || v.abs() > 5.0 {
                return fail(
                    key_path!["drive", i, "speed_mps"],
                    format!("expected a non-zero speed within ±5 m/s, found {v}"),
                );
            }
            positive(key_path!["drive", i, "distance_m"], d)
        }
        (None, None, Some(t), None) => non_negative(key_path!["drive", i, "stop_s"], t),
        (None, None, None, Some(a)) => {
            finite(key_path!["drive", i, "turn_deg"], a)?;
            if a == 0.0 {
                return fail(
                    key_path!["drive", i, "turn_deg"],
                    "expected a non-zero angle",
                );
            }
            Ok(())
        }
        (Some(_), None, None, None) => fail(
            key_path!["drive", i, "speed_mps"],
            "`speed_mps` needs `distance_m` in the same step",
        ),
        (None, Some(_), None, None) => fail(
            key_path!["drive", i, "distance_m"],
            "`distance_m` needs `speed_mps` in the same step",
        ),
        (None, None, None, None) => fail(key_path!["drive", i], format!("empty step: {expected}")),
        _ => fail(
            key_path!["drive", i],
            format!("found {}: {expected}", present.join(" and ")),
        ),
    }
}

fn sensors(s: &Scenario) -> Check {
    if let Some(l) = &s.sensors.lidar {
        let p = |k: &'static str| key_path!["sensors", "lidar", k];
        polynomial(p("bias"), &l.bias, false)?;
        polynomial(p("noise"), &l.noise, true)?;
        non_negative(p("angle_noise_deg"), l.angle_noise_deg)?;
        // The packet's rpm field is rpm × 64 in 16 bits: at most 1023 rpm.
        if !(l.rpm.is_finite() && l.rpm > 0.0 && l.rpm <= 1000.0) {
            return fail(
                p("rpm"),
                format!("expected 0 < rpm ≤ 1000, found {}", l.rpm),
            );
        }
        if l.model != LidarModel::Xv11 {
            let spec = l.model.spec();
            let (low, high) = (spec.rev_hz_range.0 * 60.0, spec.rev_hz_range.1 * 60.0);
            // A thousandth of slack: datasheet ranges are written in Hz, files in rpm.
            if l.rpm < low * 0.999 || l.rpm > high * 1.001 {
                return fail(
                    p("rpm"),
                    format!(
                        "the {} turns at {low:.0}–{high:.0} rpm, found {}",
                        spec.title, l.rpm
                    ),
                );
            }
            if l.schedule.is_some() {
                return fail(
                    p("schedule"),
                    "a schedule replays a log's scans, a model takes its unit's: set one",
                );
            }
        }
        non_negative(p("rpm_wobble"), l.rpm_wobble)?;
        if l.rpm_wobble >= l.rpm {
            return fail(p("rpm_wobble"), "the wobble must be smaller than the rpm");
        }
        non_negative(p("min_range_m"), l.min_range_m)?;
        positive(p("max_range_m"), l.max_range_m)?;
        // The XV-11's 14 bits of millimetres; a log's scans (never on its wire) 16 bits.
        let largest = if l.schedule.is_some() { 65.535 } else { 16.383 };
        if l.max_range_m > largest || l.min_range_m >= l.max_range_m {
            return fail(
                p("max_range_m"),
                if l.schedule.is_some() {
                    "expected min_range_m < max_range_m ≤ 65.535 (16 bits of mm)"
                } else {
                    "expected min_range_m < max_range_m ≤ 16.383 (14 bits of mm)"
                },
            );
        }
        mount(key_path!["sensors", "lidar", "mount"], l.mount)?;
    }
    if let Some(u) = &s.sensors.sonar {
        let p = |k: &'static str| key_path!["sensors", "sonar", k];
        polynomial(p("bias"), &u.bias, false)?;
        polynomial(p("noise"), &u.noise, true)?;
        if !(u.half_angle_deg.is_finite() && (0.0..90.0).contains(&u.half_angle_deg)) {
            return fail(
                p("half_angle_deg"),
                format!(
                    "expected 0 ≤ half_angle_deg < 90, found {}",
                    u.half_angle_deg
                ),
            );
        }
        rate(p("rate_hz"), u.rate_hz)?;
        positive(p("max_range_m"), u.max_range_m)?;
        mount(key_path!["sensors", "sonar", "mount"], u.mount)?;
    }
    if let Some(o) = &s.sensors.odometer {
        let p = |k: &'static str| key_path!["sensors", "odometer", k];
        if !(o.slip.is_finite() && o.slip > -1.0 && o.slip < 1.0) {
            return fail(
                p("slip"),
                format!("expected -1 < slip < 1, found {}", o.slip),
            );
        }
        non_negative(p("noise_m"), o.noise_m)?;
        positive(p("tick_m"), o.tick_m)?;
        rate(p("rate_hz"), o.rate_hz)?;
    }
    Ok(())
}

fn mount(path: Vec<Key>, m: super::schema::Mount) -> Check {
    for v in [m.x_m, m.y_m, m.yaw_deg] {
        finite(path.clone(), v)?;
    }
    point(path.clone(), [m.x_m, m.y_m])?;
    angle(path, m.yaw_deg)
}

/// The robot's disc must not overlap any obstacle at t = 0.
fn start_is_free(s: &Scenario) -> Check {
    let (x, y, r) = (s.robot.start.x, s.robot.start.y, s.robot.radius_m);
    let Some(overlap) = s.robot_overlap([x, y]) else {
        return Ok(());
    };
    let what = match overlap.obstacle {
        Obstacle::Wall(i) => format!("inside wall {i} ({:.3} m from it)", overlap.clearance_m),
        Obstacle::Cylinder(i) => format!("inside or touching cylinder {i}"),
        Obstacle::Board(i) => format!("inside or touching board {i}"),
        Obstacle::Map => "inside an occupied cell of the map".to_string(),
    };
    fail(
        key_path!["robot", "start"],
        format!("the robot (radius {r} m) starts {what}"),
    )
}

/// Distance from point `p` to segment `a`–`b`.
pub(crate) fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (abx, aby) = (b[0] - a[0], b[1] - a[1]);
    let len2 = abx * abx + aby * aby;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * abx + (p[1] - a[1]) * aby) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p[0] - a[0] - t * abx).hypot(p[1] - a[1] - t * aby)
}
