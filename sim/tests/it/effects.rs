//! Every catalogued effect is optional physics a scenario switches on in `[effects]`,
//! off by default (the nominal simulation is exactly what the scenario declares), checked on load
//! with the line of the offending key; motor lag is the simulation's own.

use hilsim_sim::scenario::LidarTiming;
use hilsim_sim::{MotorLag, Scenario, Simulation, WheelCommand};

const ROBOT: &str =
    "name = \"t\"\nduration_s = 1.0\n[robot]\nstart = { x = 0.0, y = 0.0 }\nwheel_base_m = 0.23\n";

fn load(text: &str) -> Result<Scenario, String> {
    Scenario::from_toml(text, "s.toml".as_ref()).map_err(|e| e.to_string())
}

#[test]
fn effects_are_off_by_default_and_the_sonar_is_axis_only() {
    let s = load(&format!("{ROBOT}[sensors.lidar]\n[sensors.sonar]\n")).unwrap();
    assert!(s.effects.is_empty());
    assert_eq!(s.sensors.sonar.as_ref().unwrap().half_angle_deg, 0.0);
    assert_eq!(
        s.sensors.lidar.as_ref().unwrap().timing,
        LidarTiming::PerReading
    );
}

#[test]
fn every_effect_table_loads_with_its_defaults() {
    let text = format!(
        "{ROBOT}[sensors.lidar]\ntiming = \"per_revolution\"\n[sensors.sonar]\n[sensors.odometer]\n\
         [effects.lidar_incidence_angle]\ncoefficient = 0.01\n\
         [effects.lidar_reflectivity]\ncoefficient_m = 0.005\n\
         [effects.lidar_mixed_pixels]\nhalf_width_deg = 0.8\n\
         [effects.lidar_motion_skew]\n\
         [effects.lidar_warmup_drift]\ncoefficient_per_m = 0.004\ntime_constant_s = 15.0\n\
         [effects.sonar_beam_width]\nhalf_angle_deg = 12.0\n\
         [effects.sonar_speed_of_sound]\nair_temperature_c = 2.0\n\
         [effects.odometer_wheel_slip]\ngain_s = 0.05\n\
         [effects.drive_motor_lag]\ntime_constant_s = 0.3\n\
         [effects.lidar_mount_offset]\nyaw_deg = 2.0\n\
         [effects.sensor_latency]\nlidar_s = 0.02\n\
         [effects.odometer_wheel_radius]\nright_scale = 1.01\n\
         [effects.drive_wheel_base]\nscale = 1.05\n"
    );
    let s = load(&text).unwrap();
    assert_eq!(s.effects.active().len(), 13);
    // The mount, timing and wheel tables: each key defaults to no change.
    assert_eq!(s.effects.lidar_mount_offset.unwrap().x_m, 0.0);
    assert_eq!(s.effects.sensor_latency.unwrap().sonar_s, 0.0);
    assert_eq!(s.effects.odometer_wheel_radius.unwrap().left_scale, 1.0);
    assert_eq!(s.effects.lidar_reflectivity.unwrap().reference, 0.8);
    assert_eq!(
        s.effects.sonar_speed_of_sound.unwrap().calibrated_at_c,
        20.0
    );
    assert_eq!(
        s.effects.active()[0..2],
        ["lidar_incidence_angle", "lidar_reflectivity"]
    );
}

#[test]
fn bad_effect_tables_are_refused_at_their_line() {
    let cases: &[(&str, &str)] = &[
        (
            "[effects.drive_motor_lag]\ntime_constant_s = -0.1\n",
            "s.toml:7: effects.drive_motor_lag.time_constant_s: expected seconds in (0, 10], found -0.1",
        ),
        (
            "[effects.drive_motor_lag]\ntime_constant_s = 0.3\ndamping = 0.05\n",
            "s.toml:8: effects.drive_motor_lag.damping: expected a damping ratio in 0.1..=10, found 0.05",
        ),
        // An unknown effect: serde names the key.
        ("[effects.lidar_fog]\ndensity = 1.0\n", "s.toml:6: unknown field `lidar_fog`"),
        // A typo inside a table.
        (
            "[sensors.lidar]\n[effects.lidar_incidence_angle]\ncoeficient = 0.01\n",
            "s.toml:8: unknown field `coeficient`",
        ),
        // An effect of a sensor the robot lacks.
        (
            "[effects.sonar_speed_of_sound]\nair_temperature_c = 0.0\n",
            "s.toml:7: effects.sonar_speed_of_sound.air_temperature_c: this effect needs a [sensors.sonar]",
        ),
        // Motion skew needs a lidar that takes a revolution at one instant.
        (
            "[sensors.lidar]\n[effects.lidar_motion_skew]\n",
            "s.toml:7: effects.lidar_motion_skew: this effect needs `[sensors.lidar] timing = \"per_revolution\"`",
        ),
        (
            "[sensors.lidar]\ntiming = \"sometimes\"\n",
            "s.toml:7: unknown variant `sometimes`",
        ),
        (
            "[sensors.sonar]\n[effects.sonar_beam_width]\nhalf_angle_deg = 95.0\n",
            "s.toml:8: effects.sonar_beam_width.half_angle_deg: expected 0 ≤ half_angle_deg < 90",
        ),
        (
            "[sensors.lidar]\n[effects.lidar_reflectivity]\ncoefficient_m = 0.01\nreference = 0.0\n",
            "s.toml:9: effects.lidar_reflectivity.reference: expected a reflectivity in (0, 1]",
        ),
        (
            "[sensors.lidar]\n[effects.lidar_mount_offset]\nyaw_deg = 90.0\n",
            "s.toml:8: effects.lidar_mount_offset.yaw_deg: expected degrees in -45..=45, found 90",
        ),
        (
            "[effects.sensor_latency]\nsonar_s = 0.1\n",
            "s.toml:7: effects.sensor_latency.sonar_s: this effect needs a [sensors.sonar]",
        ),
        (
            "[sensors.lidar]\n[effects.sensor_latency]\nlidar_s = -0.1\n",
            "s.toml:8: effects.sensor_latency.lidar_s: expected seconds in 0..=1, found -0.1",
        ),
        (
            "[effects.odometer_wheel_radius]\nleft_scale = 0.0\n",
            "s.toml:7: effects.odometer_wheel_radius.left_scale: expected a scale in 0.5..=1.5, found 0",
        ),
        (
            "[effects.drive_wheel_base]\nscale = inf\n",
            "s.toml:7: effects.drive_wheel_base.scale: expected a scale in 0.5..=1.5, found inf",
        ),
        (
            "[sensors.lidar]\n[effects.lidar_mixed_pixels]\nhalf_width_deg = nan\n",
            "s.toml:8: effects.lidar_mixed_pixels.half_width_deg: expected degrees in (0, 5], found nan",
        ),
    ];
    for (tables, expected) in cases {
        let msg = load(&format!("{ROBOT}{tables}")).unwrap_err();
        assert!(
            msg.starts_with(expected),
            "{tables}\n  gave {msg}\n  expected {expected}"
        );
    }
}

/// The robot's forward position at `t` on a straight at `v` commanded from rest through a lag
/// of time constant `tau`: `x = v (t − τ (1 − e^{−t/τ}))`.
fn lagged_position(v: f64, tau: f64, t: f64) -> f64 {
    v * (t - tau * (1.0 - (-t / tau).exp()))
}

#[test]
fn motor_lag_delays_the_robot_but_not_where_it_ends() {
    let program = "[[drive]]\nspeed_mps = 0.2\ndistance_m = 1.0\n";
    let text = |effects: &str| {
        format!(
            "name = \"t\"\nduration_s = 8.0\n[robot]\nstart = {{ x = 0.0, y = 0.0 }}\nwheel_base_m = 0.23\n{program}{effects}"
        )
    };
    let tau = 0.4;
    let lagged = load(&text(&format!(
        "[effects.drive_motor_lag]\ntime_constant_s = {tau}\n"
    )))
    .unwrap();
    let ideal = load(&text("")).unwrap();
    let run = |s: &Scenario| {
        let mut sim = Simulation::new(s);
        while sim.step().is_some() {}
        sim
    };
    let (a, b) = (run(&ideal), run(&lagged));
    // The commands as issued are the same: the lag is in the wheels, not the program.
    assert_eq!(a.commands(), b.commands());
    // During the straight (5 s) the lagged robot trails the analytic first-order response. The
    // mean-speed discretisation is exact, so what remains is rapier's f32 integration: ~1e-7
    // relative per step on positions ≤ 1 m over 500 steps, a few µm; 1e-4 m is ample.
    for sample in b.truth().iter().filter(|s| s.t_s <= 5.0) {
        let expected = lagged_position(0.2, tau, sample.t_s);
        assert!(
            (sample.x_m - expected).abs() < 1e-4,
            "t = {}: x = {}, expected {expected}",
            sample.t_s,
            sample.x_m
        );
    }
    // Settled 3 s (7.5 τ, e^-7.5 = 5.5e-4 of the lag's 0.08 m deficit) after the command
    // stopped, it ends where the program says, as the ideal drive does: within 1e-4 m.
    let (end_a, end_b) = (a.pose().x, b.pose().x);
    assert!((end_a - 1.0).abs() < 1e-3, "{end_a}");
    assert!((end_b - end_a).abs() < 1e-4, "{end_b} vs {end_a}");
}

#[test]
fn motor_lag_mean_speed_is_the_exact_integral() {
    // Integrate the lag over one 10 ms step in 10,000 sub-steps: the mean speed `step` returns is
    // the exact integral (to the sub-step's O(dt²) error, 1e-9 here).
    let target = WheelCommand {
        left_mps: 0.3,
        right_mps: -0.1,
    };
    let mut lag = MotorLag::new(0.25);
    let mean = lag.step(target, 0.01);
    let mut v = [0.0f64; 2];
    let mut travel = [0.0f64; 2];
    let n = 10_000;
    let h = 0.01 / f64::from(n);
    for _ in 0..n {
        for (i, u) in [0.3, -0.1].into_iter().enumerate() {
            let next = u + (v[i] - u) * (-h / 0.25f64).exp();
            travel[i] += 0.5 * (v[i] + next) * h;
            v[i] = next;
        }
    }
    assert!((mean.left_mps - travel[0] / 0.01).abs() < 1e-9);
    assert!((mean.right_mps - travel[1] / 0.01).abs() < 1e-9);
    assert!((lag.speeds().left_mps - v[0]).abs() < 1e-12);
}
