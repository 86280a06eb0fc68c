//! Each catalogued sensor effect, switched on in a scenario's `[effects]`, changes the
//! readings exactly as its physics says, and with every effect off the sensors are the nominal
//! ones bit for bit.
//!
//! The sensors here are noiseless and unbiased (`reading = d`, then whole millimetres), so each
//! reading is a deterministic function of the geometry. Tolerances: millimetre rounding (±0.5 mm)
//! plus rapier's f32 ray casts (a few µm at these ranges); 0.6 mm covers both.

use hilsim_lidar_emulator::effects::{dropout_probability, footprint_range_m, sonar_range_scale};
use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{LidarSample, Recording};
use hilsim_sim::pose::Pose;
use hilsim_sim::{Scenario, World};

/// Rounding to millimetres plus f32 geometry.
const MM_TOL: f64 = 0.6e-3;

const NOISELESS_LIDAR: &str =
    "[sensors.lidar]\nbias = [0.0, 1.0]\nnoise = [0.0]\nangle_noise_deg = 0.0\n";

/// A robot at the origin facing +x in a 6 m × 6 m room with the given extra world keys, sensor
/// tables, drive and effects.
fn scenario(world: &str, rest: &str) -> Scenario {
    let text = format!(
        "name = \"fx\"\nduration_s = 0.25\n[world]\nwalls = [\n  {{ from = [3.0, -3.0], to = [3.0, 3.0] }},\n  \
         {{ from = [3.0, 3.0], to = [-3.0, 3.0] }},\n  {{ from = [-3.0, 3.0], to = [-3.0, -3.0] }},\n  \
         {{ from = [-3.0, -3.0], to = [3.0, -3.0] }},\n]\n{world}\n[robot]\nstart = {{ x = 0.0, y = 0.0 }}\n\
         wheel_base_m = 0.23\n{rest}"
    );
    Scenario::from_toml(&text, "fx.toml".as_ref()).unwrap()
}

fn record(s: &Scenario) -> Recording {
    Emulation::new(s, s.seed).unwrap().run().recording
}

fn lidar(s: &Scenario) -> Vec<LidarSample> {
    record(s).lidar.unwrap()
}

/// The reading at `angle` of the first revolution.
fn at(readings: &[LidarSample], angle: u16) -> &LidarSample {
    readings
        .iter()
        .find(|r| r.angle_deg == f64::from(angle))
        .unwrap()
}

#[test]
fn with_every_effect_off_the_recording_is_the_nominal_one() {
    // An `[effects]` table with nothing in it, and a per-revolution lidar with motion skew (the
    // head turning: each reading at its own instant), are the nominal per-reading lidar.
    let sensors = "[sensors.lidar]\nnoise = [0.01]\nangle_noise_deg = 0.5\n[sensors.sonar]\nnoise = [0.01]\n[sensors.odometer]\nnoise_m = 0.002\n";
    let base = scenario("", sensors);
    let plain = record(&base);
    let mut with_empty = base.clone();
    with_empty.effects = Default::default();
    assert_eq!(record(&with_empty), plain);

    let turning = scenario("", &format!("{sensors}[[drive]]\nturn_deg = 30.0\n"));
    let mut skewed = turning.clone();
    skewed.sensors.lidar.as_mut().unwrap().timing =
        hilsim_sim::scenario::LidarTiming::PerRevolution;
    skewed.effects.lidar_motion_skew = Some(Default::default());
    assert_eq!(record(&skewed).lidar, record(&turning).lidar);
}

#[test]
fn incidence_angle_adds_kappa_d_tan_theta() {
    // A wall along y = x − 2 (45° to the 0° beam): the 0° beam meets it at d = 2 m, θ = 45°.
    let world =
        "boards = [{ center = [2.0, 0.0], length = 2.0, thickness = 0.01, yaw_deg = 45.0 }]";
    let nominal = scenario(world, NOISELESS_LIDAR);
    let mut tilted = nominal.clone();
    let kappa = 0.01;
    tilted.effects.lidar_incidence_angle = Some(hilsim_sim::scenario::LidarIncidenceAngle {
        coefficient: kappa,
        collimated_m: 0.0,
        exponent: 1.0,
    });
    let (a, b) = (lidar(&nominal), lidar(&tilted));
    for angle in [0u16, 5, 10] {
        let (ra, rb) = (at(&a, angle), at(&b, angle));
        let d = ra.true_range_m.unwrap();
        // The face runs at 45°: the beam at `angle` meets it at 45° − angle to the face, so at
        // θ = 45° + angle to its normal.
        let theta = (45.0 + f64::from(angle)).to_radians();
        let expected = d + kappa * d * theta.tan();
        assert!((ra.range_m - d).abs() < MM_TOL);
        assert!(
            (rb.range_m - expected).abs() < MM_TOL,
            "{angle}°: {} vs {expected}",
            rb.range_m
        );
    }
    // A beam at normal incidence is unchanged: the 180° beam meets the wall at x = −3 head on
    // (to rapier's f32 normal, tan θ < 1e-3: < 0.03 mm at 3 m).
    assert!((at(&a, 180).range_m - at(&b, 180).range_m).abs() < MM_TOL);
}

#[test]
fn reflectivity_walks_the_range_by_material() {
    let world = "boards = [{ center = [1.5, 0.0], length = 1.0, material = \"dark\" }]\n\
                 [world.materials.dark]\nreflectivity = 0.2";
    let nominal = scenario(world, NOISELESS_LIDAR);
    let mut walked = nominal.clone();
    walked.effects.lidar_reflectivity = Some(hilsim_sim::scenario::LidarReflectivity {
        coefficient_m: 0.01,
        reference: 0.8,
    });
    let (a, b) = (lidar(&nominal), lidar(&walked));
    // The dark board (ρ = 0.2): 0.01 (0.8 / 0.2 − 1) = +30 mm.
    assert!((at(&b, 0).range_m - at(&a, 0).range_m - 0.030).abs() < 2.0 * MM_TOL);
    // The walls are the default material (ρ = 0.8, the reference): no walk.
    assert_eq!(at(&a, 90).range_m, at(&b, 90).range_m);
}

/// The real unit reads `c + s d + q d²` more than its declared bias polynomial says, at every
/// range, whatever that polynomial is (here the landmark paper's XV-11 model, Sec. 4.1).
#[test]
fn range_bias_adds_its_polynomial_to_the_declared_one() {
    let declared =
        "[sensors.lidar]\nbias = [0.0525, 0.8838, 0.0584]\nnoise = [0.0]\nangle_noise_deg = 0.0\n";
    let nominal = scenario(
        "cylinders = [{ center = [1.0, -1.0], radius = 0.2 }]",
        declared,
    );
    let mut biased = nominal.clone();
    let (c, s, q) = (0.03, -0.02, 0.004);
    biased.effects.lidar_range_bias = Some(hilsim_sim::scenario::RangeBias {
        offset_m: c,
        scale_error: s,
        quadratic_per_m: q,
    });
    let (a, b) = (lidar(&nominal), lidar(&biased));
    assert_eq!(a.len(), b.len());
    let mut ranges = Vec::new();
    for angle in [0u16, 45, 90, 180, 315] {
        let (ra, rb) = (at(&a, angle), at(&b, angle));
        let d = ra.true_range_m.unwrap();
        ranges.push(d);
        let expected = c + s * d + q * d * d;
        // Two readings each rounded to the millimetre.
        assert!(
            (rb.range_m - ra.range_m - expected).abs() < 2.0 * MM_TOL,
            "{angle}° at {d:.3} m: {} vs {expected}",
            rb.range_m - ra.range_m
        );
    }
    // The ranges span the cylinder (~1.2 m) to the room's corner (~4.2 m).
    let (lo, hi) = ranges
        .iter()
        .fold((f64::MAX, 0.0f64), |(l, h), &d| (l.min(d), h.max(d)));
    assert!(lo < 1.5 && hi > 4.0, "{ranges:?}");
}

#[test]
fn warmup_drift_settles_exponentially() {
    let nominal = scenario("", NOISELESS_LIDAR);
    let mut long = nominal.clone();
    long.duration_s = Some(20.5);
    let mut warm = long.clone();
    let (c, k, tau) = (0.01, 0.004, 5.0);
    warm.effects.lidar_warmup_drift = Some(hilsim_sim::scenario::LidarWarmupDrift {
        coefficient_per_m: k,
        time_constant_s: tau,
        offset_m: c,
        stretch: 1.0,
    });
    let (a, b) = (lidar(&long), lidar(&warm));
    assert_eq!(a.len(), b.len());
    let mut checked = 0;
    for (ra, rb) in a.iter().zip(&b).filter(|(r, _)| r.angle_deg == 0.0) {
        // 3 m to the wall ahead: (c + k d²) e^{−t/τ} = 10 + 36 mm at power-on.
        let d = ra.true_range_m.unwrap();
        let expected = d + (c + k * d * d) * (-ra.t_s / tau).exp();
        assert!((rb.range_m - expected).abs() < MM_TOL, "t = {}", ra.t_s);
        checked += 1;
    }
    assert_eq!(checked, 102);
}

#[test]
fn mixed_pixels_blend_foreground_and_background_at_an_edge() {
    // A board at x = 1 m whose lower edge is at y = 0.01 (0.573° above the 0° beam), in front of
    // the wall at x = 3 m.
    let world =
        "boards = [{ center = [1.0, 0.51], length = 1.0, thickness = 0.002, yaw_deg = 90.0 }]";
    let nominal = scenario(world, NOISELESS_LIDAR);
    let mut mixed = nominal.clone();
    let half_width_deg = 1.0;
    mixed.effects.lidar_mixed_pixels =
        Some(hilsim_sim::scenario::LidarMixedPixels { half_width_deg });
    let (a, b) = (lidar(&nominal), lidar(&mixed));
    // The 0° beam's centre misses the board: nominally the wall, 3 m.
    assert!((at(&a, 0).range_m - 3.0).abs() < MM_TOL);
    // Its footprint (±1°) has the board (face at x = 0.999) from the edge at atan(0.01 / 0.999)
    // up to +1°, the wall below: each weighted by its angular share × ρ cos θ / d² (the same
    // material, cos θ ≈ 1 to 1.5e-4 within ±1°), and the unit reports the weighted harmonic mean.
    let h = half_width_deg.to_radians();
    let edge = (0.01f64 / 0.999).atan();
    let (fg_d, bg_d) = (0.999, 3.0);
    let fg_w = (h - edge) / (fg_d * fg_d);
    let bg_w = (edge + h) / (bg_d * bg_d);
    let expected = (fg_w + bg_w) / (fg_w / fg_d + bg_w / bg_d);
    let got = at(&b, 0).range_m;
    // Each part is represented by the distance of the ray through its middle: within ±1° that
    // differs from the perpendicular distance by d (1/cos 1° − 1) = 0.15 mm/m, a few mm on the
    // mean at most; 3 mm bounds it and is far below the 1.2 m blend being checked.
    assert!((got - expected).abs() < 3e-3, "{got} vs {expected}");
    assert!(got > 1.1 && got < 2.0, "{got}");
    // Beams whose footprint is wholly on one surface are unchanged.
    for angle in [10u16, 90, 180, 355] {
        assert_eq!(at(&a, angle).range_m, at(&b, angle).range_m, "{angle}°");
    }
    // The function the emulator uses, called directly, agrees.
    let world = World::new(&nominal);
    let centre = world.cast_ray([0.0, 0.0], 0.0, 12.0).unwrap();
    let direct = footprint_range_m(&world, [0.0, 0.0], 0.0, h, 12.0, &centre).unwrap();
    assert!((direct - got).abs() < MM_TOL);
}

#[test]
fn a_per_revolution_lidar_takes_the_revolution_from_its_start_pose() {
    // Turning in place at 45°/s: a revolution (0.2 s) turns the robot by 9°.
    let lidar_table = format!("{NOISELESS_LIDAR}timing = \"per_revolution\"\n");
    let mut s = scenario("", &format!("{lidar_table}[[drive]]\nturn_deg = 90.0\n"));
    s.duration_s = Some(2.0);
    let rec = record(&s);
    let readings = rec.lidar.as_ref().unwrap();
    let truth = rec.truth.as_ref().unwrap();
    let world = World::new(&s);
    let mut checked = 0;
    for rev in [0u64, 3, 7] {
        let rows: Vec<&LidarSample> = readings.iter().filter(|r| r.rev == rev).collect();
        assert_eq!(rows.len(), 360);
        // The readings keep their per-reading timestamps; the geometry is the pose at the
        // revolution's start (its reading 0), interpolated in the 100 Hz truth.
        let t0 = rows[0].t_s;
        assert!(rows[359].t_s > t0 + 0.19);
        let k = truth.partition_point(|p| p.t_s <= t0) - 1;
        let (p, q) = (truth[k], truth[k + 1]);
        let u = (t0 - p.t_s) / (q.t_s - p.t_s);
        let start = Pose::new(p.x_m, p.y_m, p.yaw_rad).lerp(&Pose::new(q.x_m, q.y_m, q.yaw_rad), u);
        for r in rows.iter().step_by(7) {
            let heading = start.yaw + r.angle_deg.to_radians();
            let d = world
                .cast_ray([start.x, start.y], heading, 12.0)
                .unwrap()
                .distance;
            assert!(
                (r.true_range_m.unwrap() - d).abs() < 1e-4,
                "rev {rev} {}°",
                r.angle_deg
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 3 * 52);
    // The per-reading lidar's readings late in a revolution see a turned room: they differ.
    let mut turning = s.clone();
    turning.sensors.lidar.as_mut().unwrap().timing = Default::default();
    let per_reading = record(&turning).lidar.unwrap();
    let late_differs = readings
        .iter()
        .zip(&per_reading)
        .filter(|(a, b)| a.angle_deg > 300.0 && a.rev == 2 && (a.range_m - b.range_m).abs() > 0.01)
        .count();
    assert!(late_differs > 20, "{late_differs}");
}

#[test]
fn a_wider_sonar_cone_sees_the_nearer_object_off_axis() {
    // A cylinder 1.5 m ahead and 0.5 m to the left (18.4° off the axis); the wall 3 m ahead.
    let world = "cylinders = [{ center = [1.5, 0.5], radius = 0.1 }]";
    let sonar = "[sensors.sonar]\nbias = [0.0, 1.0]\nnoise = [0.0]\n";
    let axis_only = scenario(world, sonar);
    let mut wide = axis_only.clone();
    wide.effects.sonar_beam_width = Some(hilsim_sim::scenario::SonarBeamWidth {
        half_angle_deg: 20.0,
        centroid_share: 0.0,
    });
    let a = record(&axis_only).sonar.unwrap();
    let b = record(&wide).sonar.unwrap();
    assert!((a[0].range_m - 3.0).abs() < MM_TOL, "{}", a[0].range_m);
    // Nearest point of the cylinder: |(1.5, 0.5)| − 0.1, inside the 20° cone.
    let nearest = 1.5f64.hypot(0.5) - 0.1;
    assert!((b[0].range_m - nearest).abs() < MM_TOL, "{}", b[0].range_m);
    // The recording's metadata keeps the declared (axis-only) cone: the effect is what the
    // model left out, not what the robot's builder wrote down.
    assert_eq!(record(&wide).meta.sonar.unwrap().half_angle_deg, 0.0);
}

#[test]
fn a_sonar_timing_its_echoes_centre_reads_between_the_near_object_and_the_wall() {
    // The cylinder of the test above, 18.4° off the axis inside a 20° cone, and the wall 3 m
    // ahead: the nearest echo is the cylinder's; the lobe's centroid is pulled towards the wall,
    // whose echoes fill the lobe's centre, and the cylinder's 1/d² spreading pulls it back.
    let world = "cylinders = [{ center = [1.5, 0.5], radius = 0.1 }]";
    let sonar = "[sensors.sonar]\nbias = [0.0, 1.0]\nnoise = [0.0]\n";
    let with_share = |share: f64| {
        let mut s = scenario(world, sonar);
        s.effects.sonar_beam_width = Some(hilsim_sim::scenario::SonarBeamWidth {
            half_angle_deg: 20.0,
            centroid_share: share,
        });
        record(&s).sonar.unwrap()[0].range_m
    };
    let nearest = 1.5f64.hypot(0.5) - 0.1;
    let (onset, half, centre) = (with_share(0.0), with_share(0.5), with_share(1.0));
    assert!((onset - nearest).abs() < MM_TOL, "{onset}");
    assert!(centre > nearest + 0.5 && centre < 3.1, "{centre}");
    // The share blends the two linearly.
    // Each reading is rounded to the millimetre.
    assert!(
        (half - (onset + centre) / 2.0).abs() < 1.5e-3,
        "{half} {onset} {centre}"
    );
}

#[test]
fn cold_air_makes_the_sonar_read_long() {
    let sonar = "[sensors.sonar]\nbias = [0.0, 1.0]\nnoise = [0.0]\n";
    let nominal = scenario("", sonar);
    let mut cold = nominal.clone();
    cold.effects.sonar_speed_of_sound = Some(hilsim_sim::scenario::SonarSpeedOfSound {
        air_temperature_c: 0.0,
        calibrated_at_c: 20.0,
    });
    let a = record(&nominal).sonar.unwrap();
    let b = record(&cold).sonar.unwrap();
    // 3 m at c(20 °C) / c(0 °C) = √(293.15 / 273.15) = 1.03595: 107.9 mm long.
    let scale = (293.15f64 / 273.15).sqrt();
    assert!((sonar_range_scale(0.0, 20.0) - scale).abs() < 1e-12);
    assert!(
        (b[0].range_m - 3.0 * scale).abs() < MM_TOL,
        "{}",
        b[0].range_m
    );
    assert!((a[0].range_m - 3.0).abs() < MM_TOL);
}

/// The sonar's range bias adds its polynomial to the declared one (the EM paper's affine sonar):
/// an offset of 40 mm and a scale error of −2 % at the wall 3 m ahead.
#[test]
fn sonar_range_bias_adds_its_polynomial_to_the_declared_one() {
    let sonar = "[sensors.sonar]\nbias = [0.021, 1.028]\nnoise = [0.0]\n";
    let nominal = scenario("", sonar);
    let mut biased = nominal.clone();
    biased.effects.sonar_range_bias = Some(hilsim_sim::scenario::RangeBias {
        offset_m: 0.04,
        scale_error: -0.02,
        quadratic_per_m: 0.0,
    });
    let a = record(&nominal).sonar.unwrap();
    let b = record(&biased).sonar.unwrap();
    assert!(
        (a[0].range_m - (0.021 + 1.028 * 3.0)).abs() < MM_TOL,
        "{}",
        a[0].range_m
    );
    // 0.04 − 0.02 · 3 m = −20 mm, between two readings rounded each to the millimetre.
    assert!(
        (b[0].range_m - a[0].range_m + 0.02).abs() < 2.0 * MM_TOL,
        "{} vs {}",
        b[0].range_m,
        a[0].range_m
    );
}

#[test]
fn accelerating_wheels_slip_and_the_encoders_lead_by_gain_times_speed() {
    let odometer = "[sensors.odometer]\nnoise_m = 0.0\ntick_m = 1e-6\n";
    let drive = "[[drive]]\nstop_s = 0.5\n[[drive]]\nspeed_mps = 0.2\ndistance_m = 0.4\n[[drive]]\nstop_s = 1.0\n";
    let text_nominal = scenario("", &format!("{odometer}{drive}"));
    let mut nominal = text_nominal.clone();
    nominal.duration_s = Some(3.5);
    let mut slipping = nominal.clone();
    let gain = 0.05;
    slipping.effects.odometer_wheel_slip = Some(hilsim_sim::scenario::OdometerWheelSlip {
        gain_s: gain,
        braking_gain_s: None,
    });
    let a = record(&nominal).odometry.unwrap();
    let b = record(&slipping).odometry.unwrap();
    for (ra, rb) in a.iter().zip(&b) {
        let moving = ra.t_s >= 0.5 && ra.t_s < 2.5;
        // While the wheels turn at 0.2 m/s the encoders lead by 0.05 s × 0.2 m/s = 10 mm; at rest
        // (before the start and after the stop) they agree. Tick 1 µm: tolerance 2 µm.
        let lead = if moving { gain * 0.2 } else { 0.0 };
        assert!(
            (rb.left_m - ra.left_m - lead).abs() < 2e-6,
            "t = {}",
            ra.t_s
        );
        assert!(
            (rb.right_m - ra.right_m - lead).abs() < 2e-6,
            "t = {}",
            ra.t_s
        );
    }
}

/// A slip that differs between speeding up and braking: after two 0.4 m stages (each from rest
/// to 0.2 m/s and back), the encoders lead by what the braking did not give back, `(g − g_b)
/// 0.2 m/s` a stage: none for even gains, `g 0.2` a stage for slip only while speeding up, twice
/// that for gains of opposite sign (a lead gained at every change of speed).
#[test]
fn a_slip_that_braking_does_not_give_back_accumulates_stage_by_stage() {
    let odometer = "[sensors.odometer]\nnoise_m = 0.0\ntick_m = 1e-6\n";
    let stage = "[[drive]]\nspeed_mps = 0.2\ndistance_m = 0.4\n[[drive]]\nstop_s = 1.0\n";
    let mut nominal = scenario("", &format!("{odometer}{stage}{stage}"));
    nominal.duration_s = Some(6.0);
    let gain = 0.05;
    let last = |s: &hilsim_sim::Scenario| *record(s).odometry.unwrap().last().unwrap();
    let at_rest = last(&nominal);
    for (braking, stages_lead) in [(gain, 0.0), (0.0, gain * 0.2), (-gain, 2.0 * gain * 0.2)] {
        let mut slipping = nominal.clone();
        slipping.effects.odometer_wheel_slip = Some(hilsim_sim::scenario::OdometerWheelSlip {
            gain_s: gain,
            braking_gain_s: Some(braking),
        });
        let end = last(&slipping);
        // Two stages; tick 1 µm, a motor-less drive's speed steps exactly: tolerance 5 µm.
        let lead = end.left_m - at_rest.left_m;
        assert!(
            (lead - 2.0 * stages_lead).abs() < 5e-6,
            "braking gain {braking}: lead {lead}"
        );
        assert!((end.right_m - at_rest.right_m - lead).abs() < 1e-9);
    }
}

/// The lidar's dropout loses each reading with the chance its returned power gives
/// (`dropout_probability`), and the readings it keeps are the nominal lidar's, noise and all
/// (its losses are drawn from a stream of their own).
#[test]
fn dropout_loses_readings_by_returned_power_and_keeps_the_rest_as_they_were() {
    let noisy = "[sensors.lidar]\nnoise = [0.01]\nangle_noise_deg = 0.0\n";
    let mut nominal = scenario("", noisy);
    nominal.duration_s = Some(10.0);
    let mut dropping = nominal.clone();
    let dropout = hilsim_sim::scenario::LidarDropout {
        half_loss_range_m: 3.5,
        log_power_spread: 0.3,
        reference: 0.8,
        incidence_power: 1.0,
    };
    dropping.effects.lidar_dropout = Some(dropout);
    let (a, b) = (lidar(&nominal), lidar(&dropping));
    assert_eq!(a.len(), b.len());
    let (mut lost, mut expected, mut variance) = (0.0, 0.0, 0.0);
    for (ra, rb) in a.iter().zip(&b) {
        assert_eq!((ra.rev, ra.angle_deg), (rb.rev, rb.angle_deg));
        if !rb.invalid {
            assert_eq!(ra, rb);
            continue;
        }
        assert!(
            !ra.invalid,
            "every reading of the nominal lidar is valid in this room"
        );
        lost += 1.0;
    }
    for ra in &a {
        // From the room's centre a wall at bearing φ is met at cos θ = max(|cos φ|, |sin φ|).
        let phi = ra.angle_deg.to_radians();
        let cos_incidence = phi.cos().abs().max(phi.sin().abs());
        let d = ra.true_range_m.unwrap();
        let p = dropout_probability(&dropout, d, cos_incidence, 0.8);
        expected += p;
        variance += p * (1.0 - p);
    }
    // ~18,000 readings at 3–4.2 m and 0–45°: the count lost within 5 standard deviations of
    // the count the model expects.
    assert!(
        (lost - expected).abs() < 5.0 * variance.sqrt(),
        "lost {lost}, expected {expected} ± {}",
        variance.sqrt()
    );
    assert!(
        expected > 1000.0 && expected < a.len() as f64 - 1000.0,
        "{expected}"
    );
}
