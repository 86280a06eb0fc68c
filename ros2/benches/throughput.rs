//! Import and export speed (the goals: import ≥ 50 MB of bag a second on one core;
//! export of a 60 s run under 1 s), each beside a baseline measured in the same run: the bare
//! MCAP read of the same file (the records streamed, nothing decoded) for the import, and
//! writing the recording's CSV files for the export.
//!
//! `cargo bench -p hilsim-ros2 --bench throughput` prints, for a synthetic 60 s run of the
//! straight-board kind (an XV-11 at 5 Hz: 108,000 readings; truth at 100 Hz, odometry at 20 Hz,
//! sonar at 10 Hz) and a 600 s one: the export time, the bag's size, and the import's MB/s of
//! bag (uncompressed and zstd chunks), each the best of five runs, in wall time and in the
//! process's CPU time (the work of the one core the import runs on, without the wait for the
//! disk to take the synced files). The 600 s run is imported twice: with ranges exact to the
//! millimetre (a smooth room, whose zstd chunks shrink 7 times) and with the XV-11's noise as
//! the built-in scenario draws it (σ = 0.004 d², as a real lidar's ranges: their chunks
//! shrink about 3 times, as the real capture's, `tests/data/captures`, do).

use std::path::Path;
use std::time::{Duration, Instant};

use cpu_time::ProcessTime;
use hilsim_recording::{
    CommandSample, LidarSample, Meta, Mount, OdometrySample, Recording, SonarMount, SonarSample,
    TruthSample,
};
use hilsim_ros2::{bag, export_with, import, ExportOptions, ImportOptions};

/// How the bench's lidar reports its ranges.
#[derive(Clone, Copy, PartialEq)]
enum Ranges {
    /// The true range to the millimetre.
    Exact,
    /// With the built-in scenario's noise, σ = 0.004 d² (`scenarios/straight-board.toml`).
    Noisy,
}

/// A standard normal draw from a counter (SplitMix64, then the sum of twelve uniforms less
/// six): a benchmark's noise, the same on every run, with no generator crate.
fn normal(counter: u64) -> f64 {
    let mut state = counter.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let mut sum = 0.0;
    for _ in 0..12 {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        sum += (z >> 11) as f64 / (1u64 << 53) as f64;
    }
    sum - 6.0
}

/// A run of `seconds`: the robot reversing at 0.06 m/s from 0.5 m before a board.
fn run(seconds: usize, ranges: Ranges) -> Recording {
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
                let noise = match ranges {
                    Ranges::Exact => 0.0,
                    Ranges::Noisy => 0.004 * wall * wall * normal(i as u64),
                };
                let strength = match ranges {
                    Ranges::Exact => 300 + (i % 200) as u16,
                    // Falling with the range, varying from reading to reading.
                    Ranges::Noisy => (900.0 / (1.0 + wall) * (1.0 + 0.1 * normal(!(i as u64))))
                        .clamp(0.0, 65_535.0) as u16,
                };
                LidarSample {
                    t_s,
                    rev: (i / 360) as u64,
                    angle_deg: angle,
                    range_m: ((wall + noise).max(0.02) * 1e3).round() / 1e3,
                    strength,
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

/// The best wall time of `runs` calls of `f`.
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

/// The best wall and CPU times of `runs` imports of `mcap`, each into a new directory (the
/// removal of the previous one not timed: a user's import writes where nothing was).
fn import_times(runs: usize, mcap: &Path, out: &Path) -> (f64, f64) {
    let (mut wall, mut cpu) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..runs {
        let _ = std::fs::remove_dir_all(out);
        let start = Instant::now();
        let start_cpu = ProcessTime::try_now().ok();
        import(mcap, out, &ImportOptions::default()).expect("imports");
        wall = wall.min(start.elapsed().as_secs_f64());
        if let Some(c) = start_cpu.and_then(|c| c.try_elapsed().ok()) {
            cpu = cpu.min(c.as_secs_f64());
        }
    }
    (wall, cpu)
}

fn measure(seconds: usize, ranges: Ranges, dir: &Path) {
    let rec = run(seconds, ranges);
    let kind = match ranges {
        Ranges::Exact => "ranges to the mm",
        Ranges::Noisy => "noisy ranges",
    };
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
        let (wall, cpu) = import_times(5, &mcap, &dir.join("imported"));
        let read_time = best_of(5, || {
            bag::count_messages(&mcap).expect("reads");
        });
        let mb = bytes / 1e6;
        println!(
            "{seconds} s run, {kind}, {what} chunks: export {:.3} s (goal < 1 s for 60 s; \
             writing the CSV recording: {:.3} s, ratio {:.2}); bag {mb:.1} MB; import {:.0} MB/s \
             of bag on one core's CPU time, {:.0} MB/s wall (goal >= 50); the bare MCAP read \
             {:.0} MB/s wall",
            export_time.as_secs_f64(),
            csv_time.as_secs_f64(),
            export_time.as_secs_f64() / csv_time.as_secs_f64(),
            mb / cpu,
            mb / wall,
            mb / read_time.as_secs_f64(),
        );
    }
}

fn main() {
    // `cargo test --benches` runs this with `--bench`; anything else (a filter) runs nothing.
    let dir = tempfile::tempdir().expect("a temporary directory");
    measure(60, Ranges::Exact, dir.path());
    measure(600, Ranges::Exact, dir.path());
    measure(600, Ranges::Noisy, dir.path());
}
