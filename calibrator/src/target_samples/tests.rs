use super::*;
use hilsim_recording::{CommandSample, LidarSample, Meta};

fn rec_with(commands: Vec<CommandSample>, revs: u64) -> Recording {
    let mut rec = Recording::new(Meta::default());
    rec.meta.world.target_start_distance_m = Some(0.5);
    rec.commands = commands;
    rec.lidar = Some(
        (0..revs)
            .map(|r| LidarSample {
                t_s: r as f64 * 0.2,
                rev: r,
                angle_deg: 0.0,
                range_m: 1.0,
                strength: 100,
                invalid: r == 1,
                warning: false,
                true_range_m: None,
            })
            .collect(),
    );
    rec
}

#[test]
fn reversing_increases_the_distance_and_commands_hold_until_the_next() {
    let cmds = vec![
        CommandSample {
            t_s: 0.1,
            left_mps: -0.1,
            right_mps: -0.1,
        },
        CommandSample {
            t_s: 0.5,
            left_mps: 0.0,
            right_mps: 0.0,
        },
    ];
    let s = extract(&rec_with(cmds, 5), &SampleOptions::default()).unwrap();
    // Moving at -0.1 m/s from 0.1 s to 0.5 s: +0.04 m in total, 0.01 m by t = 0.2 s.
    let expect = [0.0, 0.01, 0.03, 0.04, 0.04];
    for (c, e) in s.commanded_m.iter().zip(expect) {
        assert!((c - e).abs() < 1e-12, "{c} vs {e}");
    }
    assert_eq!(
        s.lidar_m[1], None,
        "an invalid reading is missing, not zero"
    );
    assert!((s.u(0) - 0.01).abs() < 1e-12);
    assert_eq!(s.dead_reckoning(4), Some(0.54));
}

#[test]
fn metrics_follow_the_papers_nmse() {
    let m = distance_metrics(
        &[1.0, 2.0],
        &[Some(1.1), Some(2.0)],
        &[Some(1.0), Some(2.2)],
    )
    .unwrap();
    assert!((m.mse_raw - 0.005).abs() < 1e-12);
    assert!((m.nmse_calibrated - 0.5 * 0.04 / 4.0).abs() < 1e-12);
}

#[test]
fn a_start_distance_outside_its_range_or_behind_the_commands_is_invalid() {
    let ahead = |t_s| CommandSample {
        t_s,
        left_mps: 0.1,
        right_mps: 0.1,
    };
    let rec = rec_with(vec![ahead(0.0)], 5);
    for d in [1e-300, 0.0, 1e300, f64::NAN] {
        let opts = SampleOptions {
            start_distance_m: Some(d),
            ..SampleOptions::default()
        };
        let err = extract(&rec, &opts).unwrap_err().to_string();
        assert!(
            err.contains("start distance must be from 0.01 to 1000 m"),
            "{d}: {err}"
        );
    }
    // 0.1 m/s for 0.8 s towards a target 0.05 m away: the commands drive through it.
    let opts = SampleOptions {
        start_distance_m: Some(0.05),
        ..SampleOptions::default()
    };
    let err = extract(&rec, &opts).unwrap_err().to_string();
    assert!(
        err.contains("start distance 0.05 m is shorter than the 0.08"),
        "{err}"
    );
}
