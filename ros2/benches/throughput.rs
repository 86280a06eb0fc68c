//! Import and export speed (issue 17's goals: import ≥ 50 MB of bag a second on one core;
//! export of a 60 s run under 1 s), each beside a baseline measured in the same run: the bare
//! MCAP read of the same file (the records streamed, nothing decoded) for the import, and
//! writing the recording's CSV files for the export.
//!
//! `cargo bench -p hilsim-ros2 --bench throughput` prints, for a synthetic 60 s run of the
//! straight-board kind (an XV-11 at 5 Hz: 108,000 readings; truth at 100 Hz, odometry at 20 Hz,
//! sonar at 10 Hz) and a 600 s one: the export time, the bag's size, and the import's MB/s of
//! bag (uncompressed and zstd chunks), each the best of five runs.

use std::path::Path;
use std::time::{Duration, Instant};

use hilsim_recording::{
    CommandSample, LidarSample, Meta, Mount, OdometrySample, Recording, SonarMount, SonarSample,
    TruthSample,
};
use hilsim_ros2::{bag, export_with, import, ExportOptions, ImportOptions};

/// A run of `seconds`: the robot reversing at 0.06 m/s from 0.5 m before a board.
fn run(seconds: usize) -> Recording {
    let meta = Meta {
        lidar: Some(Mount::default()),
        sonar: Some(SonarMount {
            x_m: 0.0,
            y_m: 0.0,
            yaw_deg: 0.0,
            half_angle_deg: 15.0,
        }),
        ..Meta::default()
    };
    let mut rec = Recording::new(meta);
    let d = |t: f64| 0.5 + 0.06 * t;
    rec.commands = vec![CommandSample {
        t_s: 0.0,
        left_mps: -0.06,
        right_mps: -0.06,
    }];
    let period = 0.2 / 360.0;
    rec.lidar = Some(
        (0..seconds * 5 * 360)
            .map(|i| {
                let t_s = ((i as f64 * period) * 1e6).round() / 1e6;
                let angle = (i % 360) as f64;
                let wall = (d(t_s) / angle.to_radians().cos()).abs().min(6.0);
                LidarSample {
                    t_s,
                    rev: (i / 360) as u64,
                    angle_deg: angle,
                    range_m: (wall * 1e3).round() / 1e3,
                    strength: 300 + (i % 200) as u16,
                    invalid: i % 17 == 0,
                    warning: false,
                    true_range_m: None,
                }
            })
            .collect(),
    );
    let step = |hz: usize| (0..seconds * hz).map(move |i| i as f64 / hz as f64);
    rec.truth = Some(
        step(100)
            .map(|t_s| TruthSample {
                t_s,
                x_m: d(t_s),
                y_m: 0.0,
                yaw_rad: std::f64::consts::PI,
            })
            .collect(),
    );
    rec.odometry = Some(
        step(20)
            .map(|t_s| OdometrySample {
                t_s,
                left_m: -(0.06 * t_s * 1e3).round() / 1e3,
                right_m: -(0.06 * t_s * 1e3).round() / 1e3,
            })
            .collect(),
    );
    rec.sonar = Some(
        step(10)
            .map(|t_s| SonarSample {
                t_s,
                range_m: (d(t_s) * 1e3).round() / 1e3,
                true_range_m: None,
            })
            .collect(),
    );
    rec
}

fn best_of(runs: usize, mut f: impl FnMut()) -> Duration {
    (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed()
        })
        .min()
        .unwrap_or_default()
}

fn measure(seconds: usize, dir: &Path) {
    let rec = run(seconds);
    for compress in [false, true] {
        let what = if compress { "zstd" } else { "plain" };
        let mcap = dir.join(format!("run-{seconds}-{what}.mcap"));
        let export_time = best_of(5, || {
            let options = ExportOptions {
                compress,
                ..ExportOptions::default()
            };
            export_with(&rec, &options, &mcap).expect("writes");
        });
        let csv_time = best_of(5, || rec.write_dir(&dir.join("csv")).expect("writes"));
        let bytes = std::fs::metadata(&mcap).expect("written").len() as f64;
        let out = dir.join("imported");
        let import_time = best_of(5, || {
            import(&mcap, &out, &ImportOptions::default()).expect("imports");
        });
        let read_time = best_of(5, || {
            bag::count_messages(&mcap).expect("reads");
        });
        let mb = bytes / 1e6;
        println!(
            "{seconds} s run, {what} chunks: export {:.3} s (goal < 1 s for 60 s; writing the \
             CSV recording: {:.3} s, ratio {:.2}); bag {mb:.1} MB; import {:.0} MB/s of bag \
             (goal >= 50), {:.2} x the bare MCAP read ({:.0} MB/s)",
            export_time.as_secs_f64(),
            csv_time.as_secs_f64(),
            export_time.as_secs_f64() / csv_time.as_secs_f64(),
            mb / import_time.as_secs_f64(),
            read_time.as_secs_f64() / import_time.as_secs_f64(),
            mb / read_time.as_secs_f64(),
        );
    }
}

fn main() {
    // `cargo test --benches` runs this with `--bench`; anything else (a filter) runs nothing.
    let dir = tempfile::tempdir().expect("a temporary directory");
    for seconds in [60, 600] {
        measure(seconds, dir.path());
    }
}
