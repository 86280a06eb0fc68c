//! How long reading a 100,000-row `lidar.csv` takes (best of 15), for comparing readers:
//! `cargo test --release -p hilsim-recording --test read_timing -- --ignored --nocapture`.

use std::time::{Duration, Instant};

use hilsim_recording::{CommandSample, LidarSample, Meta, Recording};

/// A recording whose lidar table has `rows` rows of values like the simulator's: times and true
/// ranges at full precision, ranges in millimetres.
fn synthetic(rows: usize) -> Recording {
    let mut rec = Recording::new(Meta::default());
    rec.commands.push(CommandSample {
        t_s: 0.0,
        left_mps: 0.1,
        right_mps: 0.1,
    });
    rec.lidar = Some(
        (0..rows)
            .map(|i| {
                let true_range_m = 1.0 + 0.5 * (i as f64 * 0.013).sin() + 1e-7 * i as f64;
                LidarSample {
                    t_s: i as f64 / 1800.0,
                    rev: (i / 360) as u64,
                    angle_deg: (i % 360) as f64,
                    range_m: (true_range_m * 1000.0).round() / 1000.0,
                    strength: (1000 + i % 3000) as u16,
                    invalid: i % 97 == 0,
                    warning: i % 89 == 0,
                    true_range_m: Some(true_range_m),
                }
            })
            .collect(),
    );
    rec
}

#[test]
#[ignore = "a measurement, run by hand in release"]
fn read_100k_lidar_rows() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rec");
    let rec = synthetic(100_000);
    rec.write_dir(&out).unwrap();
    let size = std::fs::metadata(out.join("lidar.csv")).unwrap().len();
    let mut best = Duration::MAX;
    for _ in 0..15 {
        let start = Instant::now();
        let read = Recording::read_dir(&out).unwrap();
        best = best.min(start.elapsed());
        assert_eq!(read, rec);
    }
    println!("lidar.csv: 100000 rows, {size} bytes; read_dir best of 15: {best:?}");
}

/// Reads the recording directory `$HILSIM_READ_DIR`, for measuring peak memory by hand:
/// `HILSIM_READ_DIR=rec /usr/bin/time -v target/release/deps/read_timing-* --ignored read_env_dir`.
#[test]
#[ignore = "a measurement, run by hand"]
fn read_env_dir() {
    let Some(dir) = std::env::var_os("HILSIM_READ_DIR") else {
        return;
    };
    let rec = Recording::read_dir(dir.as_ref()).unwrap();
    println!("{} lidar rows", rec.lidar.map_or(0, |l| l.len()));
}
