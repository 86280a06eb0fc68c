//! The odometry method on a 10-minute drive, on one core: the `odometry-drive` run (68 s)
//! recorded once and repeated end to end ten times (each copy's time, revolutions and wheel
//! travel continuing the last), then calibrated whole; and the paper-sized estimate alone on
//! 4,400 tuples.
//!
//! ```text
//! cargo bench -p hilsim-calibrator --bench odometry
//! ```
//!
//! Criterion reports each; the goal is a 10-minute drive in 10 s on one core, and the summary
//! printed at the end says how far below it the measured time is.

use std::hint::black_box;
use std::time::Instant;

use criterion::Criterion;
use hilsim_calibrator::odometry::{calibrate, calibrate_intervals, Interval, RecordingOptions};
use hilsim_recording::Recording;

/// The goal: a 10-minute drive in this many seconds on one core.
const GOAL_S: f64 = 10.0;

fn drive() -> Recording {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/odometry-drive.toml"
    );
    let scenario = hilsim_sim::Scenario::load(path.as_ref()).expect("odometry-drive.toml loads");
    hilsim_lidar_emulator::Emulation::new(&scenario, scenario.seed)
        .expect("sensors build")
        .run()
        .recording
}

/// `rec` repeated `copies` times end to end.
fn repeated(rec: &Recording, copies: usize) -> Recording {
    let mut out = rec.clone();
    let span = rec
        .odometry
        .as_ref()
        .and_then(|o| o.last())
        .map_or(0.0, |o| o.t_s)
        + 0.1;
    let (lidar, odometry) = (rec.lidar.clone().unwrap(), rec.odometry.clone().unwrap());
    let revs = lidar.last().map_or(0, |s| s.rev) + 1;
    let (mut all_lidar, mut all_odometry) = (Vec::new(), Vec::new());
    let (mut left, mut right) = (0.0, 0.0);
    for k in 0..copies {
        let shift = span * k as f64;
        all_lidar.extend(lidar.iter().map(|s| hilsim_recording::LidarSample {
            t_s: s.t_s + shift,
            rev: s.rev + revs * k as u64,
            ..*s
        }));
        all_odometry.extend(odometry.iter().map(|o| hilsim_recording::OdometrySample {
            t_s: o.t_s + shift,
            left_m: o.left_m + left,
            right_m: o.right_m + right,
        }));
        let last = odometry.last().unwrap();
        left += last.left_m;
        right += last.right_m;
    }
    out.lidar = Some(all_lidar);
    out.odometry = Some(all_odometry);
    out.truth = None;
    out
}

fn one_core<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a thread pool")
        .install(f)
}

fn benches(c: &mut Criterion) {
    let rec = repeated(&drive(), 10);
    let minutes = rec.odometry.as_ref().unwrap().last().unwrap().t_s / 60.0;
    let options = RecordingOptions::default();
    let mut g = c.benchmark_group("odometry");
    g.sample_size(10);
    g.bench_function("drive_10_min_one_core", |b| {
        b.iter(|| one_core(|| black_box(calibrate(&rec, &options).expect("calibrates"))));
    });
    // The estimate alone on as many intervals as the paper's data set has tuples.
    let intervals: Vec<Interval> = {
        let one = hilsim_calibrator::odometry::drive_intervals(&rec, &options)
            .expect("intervals")
            .intervals;
        one.iter().cycle().take(4400).cloned().collect()
    };
    g.bench_function("estimate_4400_intervals", |b| {
        b.iter(|| black_box(calibrate_intervals(&intervals).expect("calibrates")));
    });
    g.finish();
    let start = Instant::now();
    one_core(|| calibrate(&rec, &options).expect("calibrates"));
    let seconds = start.elapsed().as_secs_f64();
    println!(
        "summary: a {minutes:.1}-minute drive calibrated in {seconds:.2} s on one core, {:.1}x \
         below the goal of {GOAL_S} s for 10 minutes",
        GOAL_S * minutes / 10.0 / seconds
    );
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    benches(&mut c);
    c.final_summary();
}
