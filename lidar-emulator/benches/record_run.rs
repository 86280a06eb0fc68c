//! A whole recording: a 60 s straight-board run (physics at 100 Hz; lidar, sonar and odometer;
//! CSV and meta written with `Recording::write_dir` into a temporary directory), in simulated
//! seconds per wall second.
//!
//! `cargo bench -p hilsim-lidar-emulator --bench record_run` prints criterion's timing and then
//! `record_run = N x real time` (goal ≥ 500×), with the split between emulating and writing.

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::Criterion;
use hilsim_lidar_emulator::Emulation;
use hilsim_recording::Recording;
use hilsim_sim::Scenario;

/// The straight-board scenario (the EM paper's experiment, `scenarios/straight-board.toml`)
/// stretched to 60 s: the robot stands 1 s, reverses slowly from 0.5 m to 4 m in front of the
/// board, and stands 1 s.
const SCENARIO: &str = r#"
name = "record-run"
seed = 7
[world]
boards = [{ center = [-0.009, 0.0], length = 1.2, thickness = 0.018, yaw_deg = 90.0, material = "plywood" }]
walls = [
    { from = [-0.5, -3.0], to = [9.0, -3.0] },
    { from = [9.0, -3.0], to = [9.0, 3.0] },
    { from = [9.0, 3.0], to = [-0.5, 3.0] },
    { from = [-0.5, 3.0], to = [-0.5, -3.0] },
]
[world.materials.plywood]
reflectivity = 0.55
[robot]
start = { x = 0.5, y = 0.0, yaw_deg = 180.0 }
wheel_base_m = 0.23
[[drive]]
stop_s = 1.0
[[drive]]
speed_mps = -0.0603448275862069   # 3.5 m in 58 s
distance_m = 3.5
[[drive]]
stop_s = 1.0
[sensors.lidar]
bias = [0.0525, 0.8838, 0.0584]
noise = [0.0, 0.0, 0.004]
angle_noise_deg = 0.5
[sensors.sonar]
bias = [0.021, 1.028]
noise = [0.008]
half_angle_deg = 15.0
max_range_m = 5.0
[sensors.odometer]
slip = 0.027
noise_m = 0.004
"#;

fn emulate(scenario: &Scenario) -> Recording {
    Emulation::new(scenario, scenario.seed)
        .expect("valid sensors")
        .run()
        .recording
}

fn record(scenario: &Scenario, dir: &Path) {
    let recording = emulate(scenario);
    recording
        .write_dir(dir)
        .expect("a writable temporary directory");
    black_box(recording);
}

fn main() {
    let scenario = Scenario::from_toml(SCENARIO, "record-run.toml".as_ref()).expect("valid");
    let simulated_s = scenario.run_steps() as f64 * scenario.step_s();
    assert!((simulated_s - 60.0).abs() < 1e-9, "{simulated_s}");
    let tmp = tempfile::tempdir().expect("a temporary directory");
    let dir = tmp.path().join("run");

    let mut c = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5))
        .configure_from_args();
    c.bench_function("record_run_60s", |b| b.iter(|| record(&scenario, &dir)));
    c.final_summary();

    // Criterion runs the routine once under `cargo test --benches` or `-- --test`; time the
    // whole only when benchmarking for real.
    let args: Vec<String> = std::env::args().collect();
    if !args.iter().any(|a| a == "--bench") || args.iter().any(|a| a == "--test" || a == "--list") {
        return;
    }
    let rounds = 11;
    let mut emulating = Vec::with_capacity(rounds);
    let mut writing = Vec::with_capacity(rounds);
    let mut formatting = Vec::with_capacity(rounds);
    let mut whole = Vec::with_capacity(rounds);
    let mut rows = 0;
    for _ in 0..rounds {
        let t = Instant::now();
        let recording = emulate(&scenario);
        let emulated = t.elapsed();
        recording
            .write_dir(&dir)
            .expect("a writable temporary directory");
        let total = t.elapsed();
        emulating.push(emulated);
        writing.push(total - emulated);
        whole.push(total);
        // The CSV text alone, without touching the disk.
        let t = Instant::now();
        black_box(recording.tables());
        formatting.push(t.elapsed());
        rows = recording.lidar.as_ref().map_or(0, Vec::len)
            + recording.sonar.as_ref().map_or(0, Vec::len)
            + recording.odometry.as_ref().map_or(0, Vec::len)
            + recording.truth.as_ref().map_or(0, Vec::len);
    }
    let median = |mut v: Vec<Duration>| {
        v.sort();
        v[v.len() / 2]
    };
    let (emulating, writing, whole) = (median(emulating), median(writing), median(whole));
    let formatting = median(formatting);
    let bytes: u64 = std::fs::read_dir(&dir)
        .expect("the recording")
        .map(|e| e.expect("an entry").metadata().expect("metadata").len())
        .sum();
    println!();
    println!(
        "record_run: {simulated_s} simulated s, {rows} rows, {:.1} MB written; median of {rounds}",
        bytes as f64 / 1e6
    );
    println!(
        "  emulating {:.1} ms ({:.0} x), writing {:.1} ms ({:.0} x) of which formatting the CSV \
         text {:.1} ms and the files' I/O (each file synced) {:.1} ms",
        emulating.as_secs_f64() * 1e3,
        simulated_s / emulating.as_secs_f64(),
        writing.as_secs_f64() * 1e3,
        simulated_s / writing.as_secs_f64(),
        formatting.as_secs_f64() * 1e3,
        writing.saturating_sub(formatting).as_secs_f64() * 1e3
    );
    println!(
        "record_run = {:.0} x real time  (goal >= 500 x; {:.1} ms per recording)",
        simulated_s / whole.as_secs_f64(),
        whole.as_secs_f64() * 1e3
    );
}
