//! Run r of a dataset must be a function of (S, r) alone, and each varied value of
//! (S, r, KEY) alone, drawn uniformly in its range; a `--vary` that cannot work is refused
//! before any run, naming the key.

use std::collections::HashSet;
use std::path::Path;

use super::common::*;
use hilsim_dataset::{draw, run_seed, Dataset, Error, Vary, MAX_SEED};
use hilsim_sim::Scenario;

#[test]
fn run_seeds_depend_on_the_dataset_seed_and_the_run_alone() {
    // SplitMix64 seeded with 0 and 11: its documented first outputs, shifted right by one.
    assert_eq!(run_seed(0, 0), 0xe220_a839_7b1d_cdaf >> 1);
    assert_eq!(run_seed(0, 1), 0x6e78_9e6a_a1b9_65f4 >> 1);
    let seeds: HashSet<u64> = (0..100_000).map(|r| run_seed(11, r)).collect();
    assert_eq!(seeds.len(), 100_000, "distinct");
    assert!(seeds.iter().all(|&s| s <= MAX_SEED), "TOML integers");
    assert_ne!(run_seed(11, 5), run_seed(12, 5));
    // The dataset's own seeds are these, whatever N is.
    let small = small_room(3, &[]);
    let large = small_room(3000, &[]);
    for r in 0..3 {
        assert_eq!(
            small.run_seed(r),
            run_seed(5, r),
            "the scenario's seed is S"
        );
        assert_eq!(small.run_seed(r), large.run_seed(r));
    }
}

#[test]
fn varied_values_are_uniform_in_range_and_independent_of_other_keys() {
    let (lo, hi) = (0.5, 1.5);
    let n = 20_000;
    let xs: Vec<f64> = (0..n)
        .map(|r| draw(11, r, "robot.start.x", lo, hi))
        .collect();
    assert!(xs.iter().all(|x| (lo..=hi).contains(x)));
    // Mean of U(lo, hi) is the midpoint; standard error (hi − lo)/√(12 n); allow 5 of them.
    let mean = xs.iter().sum::<f64>() / n as f64;
    let se = (hi - lo) / (12.0 * n as f64).sqrt();
    assert!(
        (mean - 1.0).abs() < 5.0 * se,
        "mean {mean}, 5 SE = {}",
        5.0 * se
    );
    // Each tenth of the range holds a tenth of the draws: binomial SD √(n·0.1·0.9); 5 SD.
    for decile in 0..10 {
        let a = lo + 0.1 * f64::from(decile);
        let count = xs.iter().filter(|&&x| x >= a && x < a + 0.1).count() as f64;
        let sd = (n as f64 * 0.1 * 0.9).sqrt();
        assert!(
            (count - n as f64 * 0.1).abs() < 5.0 * sd,
            "decile {decile}: {count}"
        );
    }
    // Another key has another stream; adding a key changes no other key's values.
    assert_ne!(xs[0], draw(11, 0, "robot.start.y", lo, hi));
    let one = small_room(50, &["robot.start.x=-0.5..0.5"]);
    let two = small_room(
        50,
        &[
            "sensors.lidar.angle_noise_deg=0..2",
            "robot.start.x=-0.5..0.5",
        ],
    );
    for r in 0..50 {
        assert_eq!(one.values(r)[0], two.values(r)[1]);
        assert!((0.0..=2.0).contains(&two.values(r)[0]));
    }
    // A degenerate range is a constant.
    let fixed = small_room(3, &["robot.start.x=0.25..0.25"]);
    assert_eq!(fixed.values(2), [0.25]);
}

#[test]
fn each_run_scenario_holds_its_seed_and_values_and_is_valid() {
    let d = small_room(
        20,
        &[
            "robot.start.x=-0.5..0.5",
            "sensors.lidar.noise[2]=0.001..0.01",
            "robot.start.yaw_deg=-180..180", // absent from the file: added
        ],
    );
    for r in 0..20 {
        let (text, scenario) = d.scenario(r).unwrap();
        let values = d.values(r);
        assert_eq!(scenario.seed, d.run_seed(r));
        assert_eq!(scenario.robot.start.x, values[0]);
        assert_eq!(scenario.sensors.lidar.as_ref().unwrap().noise[2], values[1]);
        assert_eq!(scenario.robot.start.yaw_deg, values[2]);
        // The text is a scenario file in its own right: it reads back to the same scenario.
        assert_eq!(
            Scenario::from_toml(&text, Path::new("scenario.toml")).unwrap(),
            scenario
        );
        assert!(
            text.starts_with(&format!("# Run {r} of a hilsim dataset")),
            "{text}"
        );
    }
}

fn refusal(varies: &[&str]) -> String {
    let varies: Vec<Vary> = varies.iter().map(|v| v.parse().unwrap()).collect();
    let err =
        Dataset::from_toml(SMALL_ROOM, Path::new("small-room.toml"), None, 4, varies).unwrap_err();
    assert!(matches!(err, Error::Vary { .. }), "{err:?}");
    err.to_string()
}

#[test]
fn unusable_varies_are_refused_before_any_run_naming_the_key() {
    for (vary, fragment) in [
        (
            "sensors.lidar.rmp=100..200",
            "--vary `sensors.lidar.rmp=100..200`: unknown field `rmp`, expected one of",
        ),
        (
            "robot.actuation.scale_sd=0..0.1",
            "no table `robot.actuation`",
        ),
        ("name=0..1", "`name` is a string, not a number"),
        (
            "world.cylinders[3].radius=0.1..0.2",
            "`world.cylinders` has 1 element(s)",
        ),
        (
            "sensors.lidar.angle_noise_deg=-1..1",
            "at -1: sensors.lidar.angle_noise_deg: expected a number ≥ 0, found -1",
        ),
        (
            "physics.step_hz=5..50",
            "no table `physics` in the scenario",
        ),
        (
            "sensors.odometer.slip=0..1.5",
            "at 1.5: sensors.odometer.slip: expected -1 < slip < 1",
        ),
    ] {
        let err = refusal(&[vary]);
        assert!(err.contains(fragment), "{vary}: {err}");
    }
    let err = refusal(&["robot.start.x=0..1", "robot.start.x=2..3"]);
    assert!(err.contains("the key is varied twice"), "{err}");
}

#[test]
fn bad_dataset_parameters_are_refused() {
    let err = Dataset::from_toml(SMALL_ROOM, Path::new("s.toml"), None, 0, vec![]).unwrap_err();
    assert!(
        err.to_string().contains("--runs: expected at least 1 run"),
        "{err}"
    );
    let err =
        Dataset::from_toml(SMALL_ROOM, Path::new("s.toml"), Some(u64::MAX), 1, vec![]).unwrap_err();
    assert!(err.to_string().contains("largest TOML integer"), "{err}");
    let err = Dataset::from_toml("name = 3\n", Path::new("bad.toml"), None, 1, vec![]).unwrap_err();
    assert!(err.to_string().starts_with("bad.toml:1: "), "{err}");
    let err = Dataset::load(Path::new("no-such.toml"), None, 1, vec![]).unwrap_err();
    assert!(
        err.to_string().starts_with("no-such.toml: cannot read"),
        "{err}"
    );
}
