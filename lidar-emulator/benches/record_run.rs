//! A whole recording as `hilsim record` makes it (the emulation on one thread, the CSV text
//! made and written on another, each file synced), in simulated seconds per wall second, and as
//! a ratio to the bare physics + ray-cast loop it is built on, measured in the same run: the
//! physics steps and one ray per lidar reading, without noise, effects, odometry, sonar or
//! output. The ratio says what hilsim adds to the engine it cannot be faster than, and is steadier
//! than either time on a shared machine.
//!
//! `cargo bench -p hilsim-lidar-emulator --bench record_run` prints criterion's timing, then
//! `record_run = N x real time` (goal >= 1000 x) for a 60 s straight-board run and the
//! same for every checked-in scenario (`scenarios/*.toml`).

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::Criterion;
use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{BackgroundStream, RecordingStream};
use hilsim_sim::{Scenario, Simulation};

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

/// What `hilsim record` does, into `dir`.
fn record(scenario: &Scenario, dir: &Path) {
    let emulation = Emulation::new(scenario, scenario.seed).expect("valid sensors");
    let stream = RecordingStream::create(dir, emulation.meta().clone(), emulation.tables())
        .expect("a writable temporary directory");
    let mut sink = BackgroundStream::spawn(stream).expect("a thread");
    emulation.record_into(&mut sink).expect("writable");
    sink.finish().expect("writable");
}

/// The physics steps and one ray per lidar reading (at the scenario's motor speed, from the
/// robot's centre), nothing else; returns the rays' summed distance so none is optimised away.
fn bare_loop(scenario: &Scenario) -> f64 {
    let readings_per_s = scenario
        .sensors
        .lidar
        .as_ref()
        .map_or(0.0, |l| l.rpm / 60.0 * 360.0);
    let mut sim = Simulation::new(scenario);
    let mut next_reading = 0.0_f64;
    let mut beam = 0.0_f64;
    let mut sum = 0.0;
    while let Some(step) = sim.step() {
        while readings_per_s > 0.0 && next_reading < step.t1 {
            let p = step.pose1;
            if let Some(hit) = sim.world().cast_ray([p.x, p.y], p.yaw + beam, 6.0) {
                sum += hit.distance;
            }
            beam += 1f64.to_radians();
            next_reading += 1.0 / readings_per_s;
        }
    }
    sum
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// Median wall times of `rounds` recordings and of `rounds` bare loops, interleaved so that both
/// see the same machine.
fn measure(scenario: &Scenario, dir: &Path, rounds: usize) -> (Duration, Duration) {
    let mut recording = Vec::with_capacity(rounds);
    let mut bare = Vec::with_capacity(rounds);
    for _ in 0..rounds {
        let t = Instant::now();
        record(scenario, dir);
        recording.push(t.elapsed());
        let t = Instant::now();
        black_box(bare_loop(scenario));
        bare.push(t.elapsed());
    }
    (median(recording), median(bare))
}

fn report(name: &str, scenario: &Scenario, dir: &Path, rounds: usize) {
    let simulated_s = scenario.run_steps() as f64 * scenario.step_s();
    let (recording, bare) = measure(scenario, dir, rounds);
    println!(
        "{name:<22} {simulated_s:>6.1} s  {:>7.1} ms  {:>5.0} x real time  {:>5.2} x the bare loop \
         ({:.1} ms, {:.0} x real time)",
        recording.as_secs_f64() * 1e3,
        simulated_s / recording.as_secs_f64(),
        recording.as_secs_f64() / bare.as_secs_f64(),
        bare.as_secs_f64() * 1e3,
        simulated_s / bare.as_secs_f64(),
    );
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
    let (recording, bare) = measure(&scenario, &dir, rounds);
    println!();
    println!("median of {rounds}; the bare loop is the physics and one ray per lidar reading");
    println!(
        "record_run = {:.0} x real time  (goal >= 1000 x; {:.1} ms per 60 s recording, {:.2} x \
         the bare loop's {:.1} ms)",
        simulated_s / recording.as_secs_f64(),
        recording.as_secs_f64() * 1e3,
        recording.as_secs_f64() / bare.as_secs_f64(),
        bare.as_secs_f64() * 1e3,
    );
    println!();
    println!("the checked-in scenarios (hilsim record without the process's start):");
    let scenarios = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios");
    let mut paths: Vec<_> = std::fs::read_dir(&scenarios)
        .expect("scenarios/")
        .map(|e| e.expect("an entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml") && !p.ends_with("Cargo.toml"))
        .collect();
    paths.sort();
    for path in paths {
        let scenario = Scenario::load(&path).expect("a checked-in scenario");
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        report(&name.unwrap_or_default(), &scenario, &dir, rounds);
    }
}
