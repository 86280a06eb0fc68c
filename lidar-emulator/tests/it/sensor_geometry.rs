//! The lidar must see the world where it is: beams hit cylinders and walls at the analytic
//! distance, never the robot's own body, each reading from the pose at its own instant, through
//! the configured mount.
//!
//! Every expected range here comes from an analytic ray caster written in this file (circle and
//! segment intersection in `f64`), not from rapier.

use hilsim_lidar_emulator::{Emulation, LidarReading};
use hilsim_recording::TruthSample;
use hilsim_sim::Scenario;

/// Geometry tolerance on true ranges, metres. rapier works in `f32`: a coordinate of a few metres
/// carries ~2.4e-7 m of rounding and the yaw ~1e-7 rad; with ranges ≤ 4 m and incidence slopes
/// (dr/dθ = r·tan φ) ≤ ~10 m/rad here, the worst case is a few µm. 1e-4 m is ~20× that margin
/// and still 100× finer than any pose or timing mistake this file guards against.
const GEOMETRY_TOL_M: f64 = 1e-4;

/// A noiseless, unbiased lidar: `reading = d` exactly, then rounded to whole millimetres.
const NOISELESS_LIDAR: &str = "bias = [0.0, 1.0]\nnoise = [0.0]\nangle_noise_deg = 0.0\n";

/// What the analytic caster knows of the world.
#[derive(Default)]
struct Geometry {
    walls: Vec<([f64; 2], [f64; 2])>,
    cylinders: Vec<([f64; 2], f64)>,
}

impl Geometry {
    /// Distance along the unit ray `(origin, heading)` to the first surface, if any within
    /// `max_m`.
    fn cast(&self, origin: [f64; 2], heading: f64, max_m: f64) -> Option<f64> {
        let u = [heading.cos(), heading.sin()];
        let walls = self
            .walls
            .iter()
            .filter_map(|&(a, b)| ray_segment(origin, u, a, b));
        let cylinders = self
            .cylinders
            .iter()
            .filter_map(|&(c, r)| ray_circle(origin, u, c, r));
        walls
            .chain(cylinders)
            .filter(|&t| t <= max_m)
            .min_by(f64::total_cmp)
    }
}

/// Entry distance of the ray `o + t·u` (|u| = 1, t ≥ 0) into the circle (c, r), from outside.
fn ray_circle(o: [f64; 2], u: [f64; 2], c: [f64; 2], r: f64) -> Option<f64> {
    let f = [o[0] - c[0], o[1] - c[1]];
    let b = f[0] * u[0] + f[1] * u[1];
    let cc = f[0] * f[0] + f[1] * f[1] - r * r;
    let disc = b * b - cc;
    if cc < 0.0 || disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t >= 0.0).then_some(t)
}

/// Distance along the ray `o + t·u` to the segment a–b.
fn ray_segment(o: [f64; 2], u: [f64; 2], a: [f64; 2], b: [f64; 2]) -> Option<f64> {
    let e = [b[0] - a[0], b[1] - a[1]];
    let denom = u[0] * e[1] - u[1] * e[0];
    if denom.abs() < 1e-12 {
        return None;
    }
    let w = [a[0] - o[0], a[1] - o[1]];
    let t = (w[0] * e[1] - w[1] * e[0]) / denom;
    let s = (w[0] * u[1] - w[1] * u[0]) / denom;
    (t >= 0.0 && (-1e-12..=1.0 + 1e-12).contains(&s)).then_some(t)
}

/// A scenario with the robot at `start` (an inline TOML table), `top` keys before the tables and
/// `tables` after the robot.
fn scenario(top: &str, start: &str, tables: &str) -> Scenario {
    let text = format!(
        "name = \"geometry\"\n{top}\n[robot]\nstart = {start}\nwheel_base_m = 0.23\n{tables}"
    );
    Scenario::from_toml(&text, "geometry.toml".as_ref()).unwrap()
}

/// Every lidar reading of a run, and the truth.
fn readings(s: &Scenario) -> (Vec<LidarReading>, Vec<TruthSample>) {
    let mut emulation = Emulation::new(s, 3).unwrap();
    let mut out = Vec::new();
    while let Some(samples) = emulation.step() {
        out.extend_from_slice(&samples.lidar);
    }
    (out, emulation.simulation().truth().to_vec())
}

/// The true pose at `t`, linearly interpolated between the per-step truth samples (the heading
/// along the shorter arc).
fn truth_at(truth: &[TruthSample], t: f64) -> (f64, f64, f64) {
    let i = truth
        .partition_point(|s| s.t_s <= t)
        .clamp(1, truth.len() - 1);
    let (a, b) = (&truth[i - 1], &truth[i]);
    let u = ((t - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0);
    let dyaw = (b.yaw_rad - a.yaw_rad + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
        - std::f64::consts::PI;
    (
        a.x_m + (b.x_m - a.x_m) * u,
        a.y_m + (b.y_m - a.y_m) * u,
        a.yaw_rad + dyaw * u,
    )
}

/// The lidar's default cast limit: twice the default 6 m maximum range.
const CAST_LIMIT_M: f64 = 12.0;

/// Checks one reading against the analytic range; returns whether the beam hit something.
fn check_reading(r: &LidarReading, expected: Option<f64>) -> bool {
    match (expected, r.true_range_m) {
        (None, None) => {
            assert!(
                r.error_code.is_some(),
                "no target yet a valid reading: {r:?}"
            );
            false
        }
        (Some(e), Some(d)) => {
            assert!(
                (d - e).abs() <= GEOMETRY_TOL_M,
                "true range {d} m, analytic {e} m: {r:?}"
            );
            if r.error_code.is_none() {
                let mm = f64::from(r.distance_mm);
                // Noiseless and unbiased: the report is d rounded to whole millimetres, so it is
                // within the 0.5 mm quantum of the true range, and of the analytic range within
                // that plus the geometry tolerance.
                assert!((mm - d * 1000.0).abs() <= 0.5 + 1e-9, "{r:?}");
                assert!(
                    (mm - e * 1000.0).abs() <= 0.5 + GEOMETRY_TOL_M * 1000.0,
                    "{r:?}"
                );
            }
            true
        }
        (e, d) => panic!("analytic {e:?} but emulated {d:?}: {r:?}"),
    }
}

#[test]
fn beams_hit_cylinders_at_the_analytic_distance() {
    // The robot stands at an odd pose among three cylinders of different radii and distances;
    // nothing else is in the world, so most beams see nothing.
    let geometry = Geometry {
        walls: vec![],
        cylinders: vec![([2.0, 0.5], 0.3), ([-1.2, 1.9], 0.11), ([0.4, -3.1], 0.5)],
    };
    let s = scenario(
        "duration_s = 0.4",
        "{ x = 0.3, y = -0.2, yaw_deg = 23.0 }",
        &format!(
            "[world]\ncylinders = [\n{{ center = [2.0, 0.5], radius = 0.3 }},\n\
             {{ center = [-1.2, 1.9], radius = 0.11 }},\n{{ center = [0.4, -3.1], radius = 0.5 }},\n]\n\
             [sensors.lidar]\n{NOISELESS_LIDAR}"
        ),
    );
    let (readings, truth) = readings(&s);
    // 0.4 s at 1,800 readings/s: two whole revolutions.
    assert_eq!(readings.len(), 720);
    let mut hits = 0;
    for r in &readings {
        let (x, y, yaw) = truth_at(&truth, r.t_s);
        let beam = yaw + r.angle_deg.to_radians();
        hits += usize::from(check_reading(r, geometry.cast([x, y], beam, CAST_LIMIT_M)));
    }
    // Angular widths 2·asin(r/D): 9.7° + 5.9° + 18.6° ≈ 34 beams per revolution; ask for most of
    // them so that a lidar seeing nothing cannot pass.
    assert!(hits >= 2 * 30, "only {hits} readings hit a cylinder");
}

#[test]
fn the_robot_never_sees_its_own_body_even_turning_beside_walls() {
    // A 0.5 m × 0.5 m box around a robot of radius 0.165 m: every beam hits a wall between
    // 0.25 m and 0.354 m, so a beam stopped by the robot's own disc (0 m from the inside, or
    // 0.165 m) would stand out. The minimum range is 0 so that such a reading would be valid.
    let s = scenario(
        "",
        "{ x = 0.0, y = 0.0, yaw_deg = 0.0 }",
        &format!(
            "turn_rate_deg_s = 90.0\n[world]\nwalls = [\n\
             {{ from = [-0.25, -0.25], to = [0.25, -0.25] }},\n{{ from = [0.25, -0.25], to = [0.25, 0.25] }},\n\
             {{ from = [0.25, 0.25], to = [-0.25, 0.25] }},\n{{ from = [-0.25, 0.25], to = [-0.25, -0.25] }},\n]\n\
             [[drive]]\nturn_deg = 360.0\n[[drive]]\nturn_deg = -180.0\n\
             [sensors.lidar]\n{NOISELESS_LIDAR}min_range_m = 0.0\n"
        ),
    );
    assert_eq!(s.robot.radius_m, 0.165);
    let (readings, _) = readings(&s);
    // 6 s of turning at 1,800 readings/s.
    assert_eq!(readings.len(), 10_800);
    for r in &readings {
        let d = r
            .true_range_m
            .expect("a closed box: every beam hits a wall");
        // The nearest wall point is 0.25 m from the centre; 1e-4 m is the geometry tolerance.
        assert!(d >= 0.25 - GEOMETRY_TOL_M, "a beam stopped at {d} m: {r:?}");
        assert!(r.error_code.is_none(), "{r:?}");
        assert!(f64::from(r.distance_mm) >= 250.0 - 0.5, "{r:?}");
    }
}

/// A 4 m × 3 m room, off-centre around the robot, so that the range changes with the heading.
const ROOM: &str = "[world]\nwalls = [\n\
    { from = [-2.0, -1.5], to = [2.0, -1.5] },\n{ from = [2.0, -1.5], to = [2.0, 1.5] },\n\
    { from = [2.0, 1.5], to = [-2.0, 1.5] },\n{ from = [-2.0, 1.5], to = [-2.0, -1.5] },\n]\n";

fn room() -> Geometry {
    let c = [[-2.0, -1.5], [2.0, -1.5], [2.0, 1.5], [-2.0, 1.5]];
    Geometry {
        walls: (0..4).map(|i| (c[i], c[(i + 1) % 4])).collect(),
        cylinders: vec![],
    }
}

#[test]
fn during_a_turn_each_reading_follows_the_pose_at_its_own_instant() {
    // Turning in place at 90°/s, the head (5 rev/s) sweeps 18° of robot yaw per revolution.
    let s = scenario(
        "",
        "{ x = 0.3, y = -0.2, yaw_deg = 10.0 }",
        &format!(
            "turn_rate_deg_s = 90.0\n{ROOM}[[drive]]\nturn_deg = 360.0\n\
             [sensors.lidar]\n{NOISELESS_LIDAR}"
        ),
    );
    let (readings, truth) = readings(&s);
    assert_eq!(readings.len(), 7200, "4 s of turning");
    let geometry = room();
    // The robot's yaw at the start of each revolution: the instant of its 0° reading.
    let rev_start_yaw: Vec<f64> = readings
        .iter()
        .filter(|r| r.index == 0)
        .map(|r| truth_at(&truth, r.t_s).2)
        .collect();
    assert_eq!(rev_start_yaw.len(), 20, "4 s at 5 rev/s");
    let mut wrong_with_rev_start_pose = 0;
    let mut worst_with_rev_start_pose: f64 = 0.0;
    for r in &readings {
        let (x, y, yaw) = truth_at(&truth, r.t_s);
        let angle = r.angle_deg.to_radians();
        check_reading(r, geometry.cast([x, y], yaw + angle, CAST_LIMIT_M));
        // The same reading predicted from the pose at the start of its revolution.
        let stale = geometry
            .cast([x, y], rev_start_yaw[r.rev as usize] + angle, CAST_LIMIT_M)
            .unwrap();
        let error = (stale - r.true_range_m.unwrap()).abs();
        worst_with_rev_start_pose = worst_with_rev_start_pose.max(error);
        if error > 100.0 * GEOMETRY_TOL_M {
            wrong_with_rev_start_pose += 1;
        }
    }
    // Sanity of the test itself: had the emulator used the revolution's start pose, the check
    // above would fail for most readings (the heading lags by up to 18°: errors of decimetres).
    assert!(
        wrong_with_rev_start_pose > readings.len() * 3 / 4,
        "only {wrong_with_rev_start_pose} readings would differ by > 1 cm"
    );
    assert!(
        worst_with_rev_start_pose > 0.2,
        "{worst_with_rev_start_pose}"
    );
}

#[test]
fn mount_offsets_are_honoured() {
    // The lidar sits 0.12 m forward and 0.05 m left of the centre, turned 90° to the left.
    let (mx, my, myaw) = (0.12, 0.05, 90f64.to_radians());
    let s = scenario(
        "duration_s = 0.4",
        "{ x = 0.3, y = -0.2, yaw_deg = 30.0 }",
        &format!(
            "{ROOM}cylinders = [{{ center = [1.0, 0.8], radius = 0.2 }}]\n\
             [sensors.lidar]\n{NOISELESS_LIDAR}mount = {{ x_m = 0.12, y_m = 0.05, yaw_deg = 90.0 }}\n"
        ),
    );
    let (readings, truth) = readings(&s);
    assert_eq!(readings.len(), 720);
    let mut geometry = room();
    geometry.cylinders.push(([1.0, 0.8], 0.2));
    let mut wrong_without_mount = 0;
    for r in &readings {
        let (x, y, yaw) = truth_at(&truth, r.t_s);
        let (sin, cos) = yaw.sin_cos();
        let sensor = [x + cos * mx - sin * my, y + sin * mx + cos * my];
        let angle = r.angle_deg.to_radians();
        check_reading(r, geometry.cast(sensor, yaw + myaw + angle, CAST_LIMIT_M));
        let unmounted = geometry.cast([x, y], yaw + angle, CAST_LIMIT_M).unwrap();
        if (unmounted - r.true_range_m.unwrap()).abs() > 100.0 * GEOMETRY_TOL_M {
            wrong_without_mount += 1;
        }
    }
    // Sanity of the test itself: a lidar that ignored its mount would be off by > 1 cm on
    // almost every beam (its 0° axis would point 90° away).
    assert!(
        wrong_without_mount > readings.len() * 9 / 10,
        "only {wrong_without_mount} readings would differ"
    );
}
