//! Dataset throughput on `scenarios/landmarks-5.toml` (52 simulated seconds a run; lidar and
//! odometer; two varied parameters): runs per second with 1 and 2 worker threads, the scaling
//! between them (aim ≥ 1.8× on 2 cores), the share of a run spent emulating (the rest is writing
//! each file with an fsync, and hashing), and the bytes written per simulated second.
//!
//! `cargo bench -p hilsim-dataset --bench dataset` prints the figures (best of 3 rounds of 12 runs
//! per thread count). Without `--bench` (e.g. `cargo test --benches`) it makes 2 runs as a smoke
//! test.

use std::path::Path;
use std::time::{Duration, Instant};

use hilsim_dataset::{Dataset, Options, Vary};
use hilsim_sim::Scenario;

fn main() {
    let bench = std::env::args().any(|a| a == "--bench");
    let (runs, rounds) = if bench { (12, 3) } else { (2, 1) };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/landmarks-5.toml");
    let scenario = Scenario::load(&path).expect("the checked-in scenario");
    let simulated_s = scenario.run_steps() as f64 * scenario.step_s();
    let varies: Vec<Vary> = [
        "robot.start.y=-0.2..0.2",
        "sensors.lidar.angle_noise_deg=0..1",
    ]
    .iter()
    .map(|v| v.parse().expect("a valid vary"))
    .collect();
    let dataset = Dataset::load(&path, None, runs, varies).expect("a valid dataset");

    // The baseline: emulating alone, in memory, one thread.
    let t = Instant::now();
    for r in 0..runs {
        std::hint::black_box(dataset.emulate(r).expect("a valid run"));
    }
    let emulate_per_run = t.elapsed() / runs as u32;

    let mut best = Vec::new();
    let mut bytes = 0;
    for jobs in [1usize, 2] {
        let mut fastest = Duration::MAX;
        for _ in 0..rounds {
            let tmp = tempfile::tempdir().expect("a temporary directory");
            let dir = tmp.path().join("d");
            let options = Options {
                jobs: std::num::NonZeroUsize::new(jobs),
                ..Options::default()
            };
            let t = Instant::now();
            let summary = dataset
                .generate(&dir, &options, &mut ())
                .expect("a writable temporary directory");
            fastest = fastest.min(t.elapsed());
            assert_eq!(summary.made, runs);
            bytes = run_bytes(&dir);
        }
        best.push((jobs, fastest));
    }

    let per_s = |d: Duration| runs as f64 / d.as_secs_f64();
    println!(
        "dataset: landmarks-5, {simulated_s} simulated s a run, {runs} runs, best of {rounds}"
    );
    for &(jobs, d) in &best {
        println!(
            "  {jobs} job(s): {:.2} runs/s ({:.0} ms a run of wall time, {:.0} x real time)",
            per_s(d),
            d.as_secs_f64() * 1e3 / runs as f64,
            per_s(d) * simulated_s
        );
    }
    let scaling = per_s(best[1].1) / per_s(best[0].1);
    println!("  scaling 1 -> 2 jobs: {scaling:.2} x  (aim >= 1.8 x)");
    let one_job = best[0].1 / runs as u32;
    println!(
        "  a run on 1 job: emulating {:.0} ms ({:.0} %), writing (fsync per file) and hashing {:.0} ms",
        emulate_per_run.as_secs_f64() * 1e3,
        100.0 * emulate_per_run.as_secs_f64() / one_job.as_secs_f64(),
        one_job.saturating_sub(emulate_per_run).as_secs_f64() * 1e3
    );
    println!(
        "  written: {:.2} MB a run, {:.1} kB per simulated second",
        bytes as f64 / runs as f64 / 1e6,
        bytes as f64 / runs as f64 / simulated_s / 1e3
    );
}

/// Bytes in the run directories (the recordings and their scenario files).
fn run_bytes(dir: &Path) -> u64 {
    let mut total = 0;
    for entry in std::fs::read_dir(dir).expect("the dataset") {
        let entry = entry.expect("an entry");
        if entry.file_name().to_string_lossy().starts_with("run-") {
            for file in std::fs::read_dir(entry.path()).expect("a run") {
                total += file.expect("a file").metadata().expect("metadata").len();
            }
        }
    }
    total
}
