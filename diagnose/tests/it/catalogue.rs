//! Each of the catalogue's mount, timing and wheel-geometry entries, concealed in a
//! recording `hilsim` makes with truth, is named with its parameters (and, without truth, the
//! warm-up's constant term and a mount beside wheels' radii); so are the incidence and the slip
//! in forms other than the first-order ones.
//!
//! A short run (17 s: starts, stops, two turns and a reverse in a 4 m × 3 m room with a
//! cylinder and a board) keeps the fits quick; each recording has its own fixed seed. Each
//! diagnosis tries the effects of the concealed one's sensor (the competitors it must beat
//! there, and the rest of the catalogue is the self-test's to exercise; this keeps a debug
//! build's test time to minutes). Tolerances are stated by each assertion.

use std::path::Path;

use hilsim_diagnose::{diagnose, Diagnosis, Effect, Options, Sensor, SimPhysics};
use hilsim_fixtures::rooms::ROOM_4X3;
use hilsim_lidar_emulator::Emulation;
use hilsim_sim::Scenario;

/// The room's furniture (added to [`ROOM_4X3`]'s `[world]`), robot, drive and sensors.
const FURNISHED: &str = r#"cylinders = [{ center = [2.8, 1.9], radius = 0.12 }]
boards = [{ center = [3.2, 0.7], length = 0.8, thickness = 0.02, yaw_deg = 60.0 }]

[robot]
start = { x = 0.8, y = 0.8, yaw_deg = 0.0 }
wheel_base_m = 0.23
turn_rate_deg_s = 60.0

[[drive]]
stop_s = 0.5
[[drive]]
speed_mps = 0.3
distance_m = 1.5
[[drive]]
turn_deg = 90.0
[[drive]]
speed_mps = 0.25
distance_m = 1.0
[[drive]]
stop_s = 0.5
[[drive]]
turn_deg = -135.0
[[drive]]
speed_mps = -0.2
distance_m = 0.6
[[drive]]
stop_s = 0.5

[sensors.lidar]
bias = [0.0525, 0.8838, 0.0584]
noise = [0.003, 0.0, 0.002]
angle_noise_deg = 0.3
[sensors.sonar]
bias = [0.021, 1.028]
noise = [0.008]
max_range_m = 5.0
[sensors.odometer]
slip = 0.01
noise_m = 0.002
"#;

pub(crate) fn room() -> Scenario {
    let text = format!("name = \"catalogue-room\"\nseed = 5\n\n{ROOM_4X3}{FURNISHED}");
    Scenario::from_toml(&text, Path::new("catalogue-room.toml")).expect("the test's scenario")
}

/// The diagnosis of a run of `room()` with `effect` concealed at `params`, trying `tried`.
fn diagnosed(effect: Effect, params: &[f64], seed: u64, tried: &[Effect]) -> Diagnosis {
    diagnosed_with(&[(effect, params)], seed, tried, true)
}

/// As [`diagnosed`], with every effect of `concealed` at its parameters and the recording's
/// `truth.csv` kept or removed (`truth`).
fn diagnosed_with(
    concealed: &[(Effect, &[f64])],
    seed: u64,
    tried: &[Effect],
    truth: bool,
) -> Diagnosis {
    let nominal = room();
    let mut real = nominal.clone();
    for (effect, params) in concealed {
        effect.apply(params, &mut real.effects);
    }
    let mut recording = Emulation::new(&real, seed)
        .expect("the emulation")
        .run()
        .recording;
    if !truth {
        recording.truth = None;
    }
    let physics = SimPhysics::new(&nominal).expect("the physics");
    let options = Options {
        effects: tried.to_vec(),
        ..Options::default()
    };
    diagnose(&physics, &recording, &options).expect("a diagnosis")
}

/// The fitted parameters of `effect` when it is named.
fn named(d: &Diagnosis, effect: Effect) -> Vec<f64> {
    let names: Vec<String> = d.effects.iter().map(|e| e.fit.effect.label()).collect();
    d.effects
        .iter()
        .find(|e| e.fit.effect == effect)
        .unwrap_or_else(|| panic!("{} not named; named {names:?}", effect.label()))
        .fit
        .params
        .clone()
}

/// The catalogue's effects fitted in `sensor`.
pub(crate) fn of(sensor: Sensor) -> Vec<Effect> {
    Effect::ALL
        .into_iter()
        .filter(|e| e.sensor() == sensor)
        .collect()
}

#[test]
fn a_lidar_mounted_turned_and_off_centre_is_named_with_its_mount() {
    let d = diagnosed(
        Effect::LidarMountOffset,
        &[2.0, 0.02, -0.02],
        11,
        &of(Sensor::Lidar),
    );
    let p = named(&d, Effect::LidarMountOffset);
    // A 2° yaw turns every beam: tens of thousands of readings pin it to hundredths of a
    // degree; 0.1° (5 %) leaves room for the direction noise's 0.3° per reading. The 20 mm
    // offsets move the ranges by at most 20 mm against 5–20 mm of noise: within 5 mm.
    assert!((p[0] - 2.0).abs() < 0.1, "{p:?}");
    assert!((p[1] - 0.02).abs() < 0.005, "{p:?}");
    assert!((p[2] + 0.02).abs() < 0.005, "{p:?}");
}

#[test]
fn each_sensor_stamped_late_is_named_with_its_own_delay() {
    for (sensor, delay, tolerance) in [
        // 50 ms at up to 0.3 m/s and 60°/s moves the lidar's geometry by centimetres over
        // ~20,000 readings, the encoders' travel by 15 mm against 2 mm of noise: within 10 %.
        (Sensor::Lidar, 0.05, 0.005),
        (Sensor::Odometer, 0.05, 0.005),
        // The sonar's ~170 pings (10 Hz) see only the motion along its axis (8 mm noise): within 30 %.
        (Sensor::Sonar, 0.08, 0.024),
    ] {
        let effect = Effect::SensorLatency(sensor);
        let d = diagnosed(effect, &[delay], 12, &of(sensor));
        let p = named(&d, effect);
        assert!((p[0] - delay).abs() < tolerance, "{sensor}: {p:?}");
        // Named in its own sensor only.
        assert!(
            d.effects.iter().all(|e| e.fit.effect.sensor() == sensor),
            "{sensor}: {:?}",
            d.effects.iter().map(|e| e.fit.effect).collect::<Vec<_>>()
        );
    }
}

#[test]
fn wheel_radius_and_wheel_base_are_told_apart_in_the_odometer() {
    // Both compete in the odometer (with slip and the encoders' latency), and the drive is
    // diagnosed on top of them: a motor lag must not be named for their mismatch there.
    let mut tried = of(Sensor::Odometer);
    tried.push(Effect::DriveMotorLag);
    // 2 % and 1 % on ~3 m of travel per wheel: 60 and 30 mm against 2 mm of noise; within a
    // tenth of each departure.
    let d = diagnosed(Effect::OdometerWheelRadius, &[1.02, 0.99], 13, &tried);
    let p = named(&d, Effect::OdometerWheelRadius);
    assert!((p[0] - 1.02).abs() < 0.002, "{p:?}");
    assert!((p[1] - 0.99).abs() < 0.001, "{p:?}");
    assert_eq!(d.effects.len(), 1, "{:?}", d.effects);
    // A base 8 % wider turns the robot 7 % less in 225° of turns: ~20 mm of each wheel's
    // travel; within a tenth of the departure.
    let d = diagnosed(Effect::DriveWheelBase, &[1.08], 14, &tried);
    let p = named(&d, Effect::DriveWheelBase);
    assert!((p[0] - 1.08).abs() < 0.008, "{p:?}");
    assert_eq!(d.effects.len(), 1, "{:?}", d.effects);
}

/// A warm-up whose drift is all in the range's constant term (the housing, not the pointing;
/// how another simulator drifted "the range bias") is named as the warm-up, not as a mount
/// offset, which moves the ranges ahead by a constant too but never those to the sides and
/// never with time.
#[test]
fn a_warmup_of_the_constant_term_is_named_not_a_mount_offset() {
    let d = diagnosed(
        Effect::LidarWarmupDrift,
        &[0.0, 15.0, 0.03],
        13,
        &of(Sensor::Lidar),
    );
    let p = named(&d, Effect::LidarWarmupDrift);
    // 30 mm at power-on, settling over the 17 s run, on ~30,000 readings of 3–10 mm noise:
    // the constant within 3 mm (10 %), the time constant within 30 % (it trades against the
    // constant over a run barely longer than it), and the quadratic term's 2 m error within
    // 3 mm of none.
    assert!((p[2] - 0.03).abs() < 0.003, "{p:?}");
    assert!((p[1] - 15.0).abs() < 4.5, "{p:?}");
    assert!((p[0] * 4.0).abs() < 0.003, "{p:?}");
    assert!(
        d.effects
            .iter()
            .all(|e| e.fit.effect != Effect::LidarMountOffset),
        "{:?}",
        d.effects.iter().map(|e| e.fit.effect).collect::<Vec<_>>()
    );
}

/// Without truth, the same warm-up is named with its size, and nothing in the encoders: the
/// constant term is fitted against the path estimated from the lidar too, and the path is
/// estimated again under it until it settles, which gives back the early position error the
/// matching took it as (the encoders showed it as a wheel radius or slip).
#[test]
fn a_warmup_of_the_constant_term_is_named_without_truth() {
    let tried = [
        Effect::LidarWarmupDrift,
        Effect::OdometerWheelRadius,
        Effect::OdometerWheelSlip,
    ];
    let d = diagnosed_with(
        &[(Effect::LidarWarmupDrift, &[0.0, 5.0, 0.03])],
        13,
        &tried,
        false,
    );
    let p = named(&d, Effect::LidarWarmupDrift);
    // 30 mm at power-on settling with τ = 5 s over the 17 s run: the size at 2 m within 20 %
    // (the self-test's bound; against an estimated path the near readings of the first
    // seconds carry it).
    let size = p[2] + 4.0 * p[0];
    assert!((size - 0.03).abs() < 0.006, "{p:?}");
    // Its own term's shape is the one kept (the two are settled apart against the path), and
    // the other term is reported held, not estimated.
    assert_eq!(p[0], 0.0, "{p:?}");
    let fit = &d.effects[0].fit;
    assert_eq!(fit.param_sd[0], 0.0, "{:?}", fit.param_sd);
    assert!(fit.param_sd[2] > 0.0, "{:?}", fit.param_sd);
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert_eq!(names, [Effect::LidarWarmupDrift], "{names:?}");
}

/// Without truth and with every lidar entry tried, a warm-up settling over most of the run
/// (τ = 12 s over 17 s) is named as the warm-up, and nothing else: on the first estimated path
/// the matching took up most of its early shift, leaving its time-average, which a range bias
/// fits better there (and the encoders read the path's early error as a wheel radius); each
/// settled along its own path, the warm-up explains the readings better.
#[test]
fn without_truth_a_slow_warmup_is_named_not_a_range_bias() {
    let mut tried = of(Sensor::Lidar);
    tried.push(Effect::OdometerWheelRadius);
    let d = diagnosed_with(
        &[(Effect::LidarWarmupDrift, &[0.0, 12.0, 0.03])],
        13,
        &tried,
        false,
    );
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert_eq!(names, [Effect::LidarWarmupDrift], "{names:?}");
    // 30 mm at power-on: within the self-test's 20 %.
    let p = named(&d, Effect::LidarWarmupDrift);
    let size = p[2] + 4.0 * p[0];
    assert!((size - 0.03).abs() < 0.006, "{p:?}");
}

/// A lidar whose range bias is not the one its scenario declares (an offset and a scale
/// error: the low orders of the papers' polynomial, eq. 2) is named as such, not as an
/// incidence-angle error, whose collimated term a constant offset on a room's oblique walls
/// passed for while the catalogue had no range bias.
#[test]
fn an_undeclared_range_bias_is_named_not_the_incidence() {
    // 20 mm at 2 m and a scale error of −1 %: the unit reads 40 mm − 1 % · d more than declared.
    let d = diagnosed(
        Effect::LidarRangeBias,
        &[0.02, -0.01, 0.0],
        15,
        &of(Sensor::Lidar),
    );
    let p = named(&d, Effect::LidarRangeBias);
    let at = |r: f64| p[0] + p[1] * (r - 2.0) + p[2] * (r - 2.0) * (r - 2.0);
    // ~30,000 readings over 0.3–4 m with 3–10 mm of noise: the error at 2 m within 2 mm, at
    // 1 m and 3 m (+30 mm and +10 mm concealed) within 3 mm, and the scale error within 0.3 %
    // (it trades against the curvature over the room's span of ranges).
    assert!((p[0] - 0.02).abs() < 0.002, "{p:?}");
    assert!((at(1.0) - 0.03).abs() < 0.003, "{p:?}");
    assert!((at(3.0) - 0.01).abs() < 0.003, "{p:?}");
    assert!((p[1] + 0.01).abs() < 0.003, "{p:?}");
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert_eq!(names, [Effect::LidarRangeBias], "{names:?}");
}

/// A sonar reading a constant more than its declared (affine) bias is named `sonar_range_bias`,
/// and a scale of every range still the speed of sound: the offset and the scale of the EM
/// paper's affine sonar are the two entries' parameters, neither able to pass for the other.
#[test]
fn a_sonar_offset_and_a_sonar_scale_are_each_named_as_theirs() {
    let d = diagnosed(Effect::SonarRangeBias, &[0.04], 16, &of(Sensor::Sonar));
    let p = named(&d, Effect::SonarRangeBias);
    // ~170 pings of 8 mm noise: the offset's standard error is under 1 mm; within 4 mm.
    assert!((p[0] - 0.04).abs() < 0.004, "{p:?}");
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert_eq!(names, [Effect::SonarRangeBias], "{names:?}");
    let d = diagnosed(Effect::SonarSpeedOfSound, &[0.0], 16, &of(Sensor::Sonar));
    let p = named(&d, Effect::SonarSpeedOfSound);
    // 20 °C colder: 3.6 % on ranges up to 4 m; within 3 °C.
    assert!(p[0].abs() < 3.0, "{p:?}");
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert_eq!(names, [Effect::SonarSpeedOfSound], "{names:?}");
}

/// A sonar reading a constant more beside a scale of every range: the scale, named first,
/// takes up part of the offset over a room's ranges, so the offset fitted on top of it comes
/// out too small to name; refitted jointly with it, both are named at their own values.
#[test]
fn a_sonar_offset_beside_a_sonar_scale_are_both_named() {
    let d = diagnosed_with(
        &[
            (Effect::SonarRangeBias, &[0.025]),
            (Effect::SonarSpeedOfSound, &[0.0]),
        ],
        16,
        &of(Sensor::Sonar),
        true,
    );
    let offset = named(&d, Effect::SonarRangeBias);
    let air = named(&d, Effect::SonarSpeedOfSound);
    // ~170 pings of 8 mm noise: the offset within 5 mm and the air within 3 °C, as alone
    // (the two trade, so each is a little looser than alone).
    assert!((offset[0] - 0.025).abs() < 0.005, "{offset:?}");
    assert!(air[0].abs() < 3.0, "{air:?}");
}

/// The mount and the wheels' effects it competes with in the encoders.
const MOUNT_AND_WHEELS: [Effect; 4] = [
    Effect::LidarMountOffset,
    Effect::OdometerWheelRadius,
    Effect::DriveWheelBase,
    Effect::OdometerWheelSlip,
];

/// Without truth, a lidar turned and off-centre beside wheels whose radii are not nominal: the
/// path estimated from the lidar takes the mount up, and the encoders show it beside the
/// radii. Alone, the mount gains less there than the radii, so it must be named beside them.
#[test]
fn without_truth_a_mount_beside_wheel_radii_is_named_with_them() {
    let d = diagnosed_with(
        &[
            (Effect::LidarMountOffset, &[-2.4, -0.011, -0.014]),
            (Effect::OdometerWheelRadius, &[0.972, 0.980]),
        ],
        17,
        &MOUNT_AND_WHEELS,
        false,
    );
    let mount = named(&d, Effect::LidarMountOffset);
    let radius = named(&d, Effect::OdometerWheelRadius);
    // The yaw within the self-test's 20 % (measured −2.35°); the offset within 5 mm, half the
    // mount's least offset named against an estimated path (measured within 1.6 mm); the
    // radii within 0.2 % (measured within 0.08 %: the encoders' millimetres over the run's
    // 3 m of travel).
    assert!((mount[0] + 2.4).abs() < 0.48, "{mount:?}");
    assert!((mount[1] + 0.011).abs() < 0.005, "{mount:?}");
    assert!((mount[2] + 0.014).abs() < 0.005, "{mount:?}");
    assert!((radius[0] - 0.972).abs() < 0.002, "{radius:?}");
    assert!((radius[1] - 0.980).abs() < 0.002, "{radius:?}");
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

/// The same radii without a mount: the mount tried beside them finds nothing to add.
#[test]
fn without_truth_wheel_radii_alone_are_named_without_a_mount() {
    let d = diagnosed_with(
        &[(Effect::OdometerWheelRadius, &[0.972, 0.980])],
        17,
        &MOUNT_AND_WHEELS,
        false,
    );
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert_eq!(names, [Effect::OdometerWheelRadius], "{names:?}");
}

/// An incidence error of a collimated beam (the same at every range, `c tan θ`) is named as
/// the incidence, with its term: the diverging beam's `κ d tan θ` alone would overshoot on far
/// walls.
#[test]
fn a_collimated_beams_incidence_is_named_with_its_own_term() {
    let d = diagnosed(
        Effect::LidarIncidenceAngle,
        &[0.0, 0.02],
        14,
        &of(Sensor::Lidar),
    );
    let p = named(&d, Effect::LidarIncidenceAngle);
    // 20 mm at 45° on every oblique wall and the board over ~30,000 readings of 3–10 mm
    // noise: within 2 mm (10 %), and κ, searched as the alternative, left at zero.
    assert!((p[1] - 0.02).abs() < 0.002, "{p:?}");
    assert_eq!(p[0], 0.0, "{p:?}");
}

/// An incidence error that grows as `tan² θ` (a centroid whose skew grows with the footprint)
/// is named as the incidence with its power, not left unexplained for differing from the
/// first-order `tan θ`.
#[test]
fn an_incidence_growing_faster_than_the_footprint_is_named_with_its_power() {
    let d = diagnosed(
        Effect::LidarIncidenceAngle,
        &[0.0, 0.01, 2.0],
        15,
        &of(Sensor::Lidar),
    );
    let p = named(&d, Effect::LidarIncidenceAngle);
    // 10 mm at 45°, 30 mm at 60°, on the oblique walls, the board and the post over ~30,000
    // readings of 3–10 mm noise: c within 15 % and the power within 0.2 (a tenth of it; the
    // fit's grid steps by √2).
    assert!((p[1] - 0.01).abs() < 0.0015, "{p:?}");
    assert!((p[2] - 2.0).abs() < 0.2, "{p:?}");
}

/// Wheels that slip only while speeding up (braking gives nothing back) are named as a slip of
/// that form, not as wheels of another radius, which the lead that stays after each stop would
/// otherwise look like.
#[test]
fn a_slip_that_braking_does_not_give_back_is_named_as_slip_not_radius() {
    let mut tried = of(Sensor::Odometer);
    tried.push(Effect::DriveMotorLag);
    let d = diagnosed(Effect::OdometerWheelSlip, &[0.08, 0.0], 16, &tried);
    let p = named(&d, Effect::OdometerWheelSlip);
    // 0.08 s × 0.3 m/s = 24 mm a start against 2 mm of noise: the gain within 15 % and the
    // braking share within 0.25 of zero (half the fit's grid step).
    assert!((p[0] - 0.08).abs() < 0.012, "{p:?}");
    assert!(p[1].abs() < 0.25, "{p:?}");
    assert!(
        d.effects
            .iter()
            .all(|e| e.fit.effect != Effect::OdometerWheelRadius),
        "{:?}",
        d.effects
    );
}

/// Wheels whose response overshoots (a second-order drive of damping 0.5) are named as a
/// motor lag of that form: the first-order lag cannot overshoot, and without its form the
/// drive was left unexplained.
#[test]
fn a_drive_that_overshoots_is_named_as_a_lag_with_its_damping() {
    let d = diagnosed(Effect::DriveMotorLag, &[0.25, 2.0], 16, &of(Sensor::Drive));
    let p = named(&d, Effect::DriveMotorLag);
    // The response time within 10 % and the underdamping within 0.5 (a grid step) of 2.
    assert!((p[0] - 0.25).abs() < 0.025, "{p:?}");
    assert!((p[1] - 2.0).abs() < 0.5, "{p:?}");
}

/// A sparse world: five thin cylinders, walls up to 6 m away, the robot stopping every 0.3 m
/// along a line (the `landmarks-5` scenario, cut to five moves).
fn sparse_stops() -> Scenario {
    const WORLD: &str = r#"
name = "sparse-stops"
seed = 5

[world]
cylinders = [
    { center = [1.0, 1.2], radius = 0.12 },
    { center = [2.0, -1.1], radius = 0.12 },
    { center = [3.0, 1.6], radius = 0.12 },
    { center = [4.2, -0.5], radius = 0.12 },
    { center = [0.2, -1.5], radius = 0.12 },
]
walls = [
    { from = [-1.5, -3.0], to = [6.0, -3.0] },
    { from = [6.0, -3.0], to = [6.0, 3.0] },
    { from = [6.0, 3.0], to = [-1.5, 3.0] },
    { from = [-1.5, 3.0], to = [-1.5, -3.0] },
]

[robot]
start = { x = 0.0, y = 0.0, yaw_deg = 0.0 }
wheel_base_m = 0.23

[sensors.lidar]
bias = [0.0525, 0.8838, 0.0584]
noise = [0.002625, 0.04419, 0.00292]
angle_noise_deg = 0.5
[sensors.odometer]
slip = 0.0
noise_m = 0.002
"#;
    let stop = "[[drive]]\nstop_s = 2.0\n";
    let stops = format!(
        "{WORLD}{stop}{}",
        format!("[[drive]]\nspeed_mps = 0.1\ndistance_m = 0.3\n{stop}").repeat(5)
    );
    Scenario::from_toml(&stops, Path::new("sparse-stops.toml")).expect("the test's scenario")
}

/// Without truth, a faithful run in a sparse world names nothing in the encoders. There one
/// revolution pins the pose poorly and the path estimated from the lidar errs by about a
/// centimetre for many seconds; read as independent errors, the encoders' 540 readings took
/// that wander for wheels of 99.6 % of their radius or a slip (seeds 5 and 6 named them before
/// the path's error was modelled as one process shared by neighbouring readings).
#[test]
fn a_faithful_sparse_run_without_truth_names_nothing_in_the_encoders() {
    let scenario = sparse_stops();
    let physics = SimPhysics::new(&scenario).expect("the physics");
    let options = Options {
        effects: vec![
            Effect::OdometerWheelRadius,
            Effect::OdometerWheelSlip,
            Effect::SensorLatency(Sensor::Odometer),
        ],
        ..Options::default()
    };
    for seed in [5, 6] {
        let mut recording = Emulation::new(&scenario, seed)
            .expect("the emulation")
            .run()
            .recording;
        recording.truth = None;
        let d = diagnose(&physics, &recording, &options).expect("a diagnosis");
        let names: Vec<String> = d.effects.iter().map(|e| e.fit.effect.label()).collect();
        assert!(names.is_empty(), "seed {seed}: named {names:?}");
    }
}

/// A lidar that loses its weak returns (half of them at 3 m head-on, a log-power spread of
/// 0.3) is named `lidar_dropout` with its half-loss range and spread; the same room recorded
/// without it names nothing in the lidar.
#[test]
fn a_lidar_losing_weak_returns_is_named_dropout_and_a_faithful_one_is_not() {
    let d = diagnosed(Effect::LidarDropout, &[3.0, 0.3], 17, &of(Sensor::Lidar));
    let p = named(&d, Effect::LidarDropout);
    // ~20,000 reads and losses: each parameter's standard error is under 1 %; within 5 %
    // (the half-loss range) and 10 % (the spread).
    assert!((p[0] - 3.0).abs() < 0.15, "{p:?}");
    assert!((p[1] - 0.3).abs() < 0.03, "{p:?}");
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert_eq!(names, [Effect::LidarDropout], "{names:?}");
    let nominal = room();
    let recording = Emulation::new(&nominal, 17)
        .expect("the emulation")
        .run()
        .recording;
    let physics = SimPhysics::new(&nominal).expect("the physics");
    let options = Options {
        effects: vec![Effect::LidarDropout],
        ..Options::default()
    };
    let faithful = diagnose(&physics, &recording, &options).expect("a diagnosis");
    assert!(faithful.effects.is_empty(), "{:?}", faithful.verdict);
}
