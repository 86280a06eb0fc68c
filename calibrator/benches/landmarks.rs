//! Landmark calibrator benchmarks: the paper's 1,000-run Monte Carlo (Sec. 4.1, pure maths) on
//! one core and on two, with runs per second and the 2-core over 1-core speed-up; the paper's
//! estimator alone (no refinement) as the baseline of the same run; and a whole calibration
//! from raw scans of one `landmarks-5` recording.
//!
//! ```text
//! cargo bench -p hilsim-calibrator --bench landmarks
//! ```
//!
//! Criterion reports each benchmark; a summary (wall and CPU time of 1,000 runs on 1 and 2
//! threads, runs per second, speed-up, and the projected time of the whole Fig. 9 grid) is
//! measured again and printed at the end (alone with `LANDMARKS_SUMMARY_ONLY=1`). The CPU time
//! shows how many cores the run actually obtained: on a shared machine the wall-time speed-up
//! is capped by the other processes, the CPU-time ratio is not.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput};
use hilsim_calibrator::landmarks::estimate::EstimatorConfig;
use hilsim_calibrator::landmarks::{calibrate, Options};
use hilsim_fixtures::landmark_study::{monte_carlo, Setup};

use cpu_time::ProcessTime;

/// Runs of one Monte Carlo point, as in the paper ("each point is the average of 1000
/// simulations").
const RUNS: usize = 1000;

/// Points of the Fig. 9 grid in `reproduce_landmarks` (5 σs × 5 σθ).
const FIG9_POINTS: usize = 25;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
}

/// A Fig. 9 point (L = 2, σs = 1 cm, σθ = 1°), refined or the paper's estimator alone.
fn setup(refine: bool) -> Setup {
    let mut s = Setup::paper().landmarks(2).noise(0.01, 1.0);
    s.estimator = EstimatorConfig {
        refine,
        ..EstimatorConfig::default()
    };
    s
}

fn landmarks5() -> hilsim_recording::Recording {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/landmarks-5.toml");
    let scenario = hilsim_sim::Scenario::load(path.as_ref()).expect("landmarks-5.toml loads");
    hilsim_lidar_emulator::Emulation::new(&scenario, scenario.seed)
        .expect("sensors build")
        .run()
        .recording
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("monte_carlo_1000_runs");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(20))
        .throughput(Throughput::Elements(RUNS as u64));
    for threads in [1, 2] {
        let p = pool(threads);
        let s = setup(true);
        g.bench_function(format!("refined_{threads}_threads"), |b| {
            b.iter(|| p.install(|| black_box(monte_carlo(&s, RUNS, 1))))
        });
    }
    let p = pool(1);
    let s = setup(false);
    g.bench_function("paper_only_1_thread", |b| {
        b.iter(|| p.install(|| black_box(monte_carlo(&s, RUNS, 1))))
    });
    g.finish();
    let rec = landmarks5();
    let mut g = c.benchmark_group("calibrate");
    g.sample_size(20);
    g.bench_function("landmarks5_from_raw_scans", |b| {
        b.iter(|| black_box(calibrate(&rec, &Options::default()).expect("calibrates")))
    });
    g.finish();
}

/// Median wall time of `reps` repetitions, and the mean CPU time of one (user + system, all
/// threads): CPU over wall time is the number of cores actually obtained, below the thread count
/// when other processes hold cores.
fn median_time(reps: usize, mut f: impl FnMut()) -> (f64, Option<f64>) {
    // CPU time of the whole process (all threads), from the OS clock.
    let c0 = ProcessTime::try_now().ok();
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64()
        })
        .collect();
    let cpu = c0.map(|c| c.elapsed().as_secs_f64() / reps as f64);
    t.sort_by(f64::total_cmp);
    (t[t.len() / 2], cpu)
}

fn summary() {
    let s = setup(true);
    let one = pool(1);
    let two = pool(2);
    let (t1, c1) = median_time(3, || {
        one.install(|| black_box(monte_carlo(&s, RUNS, 2)));
    });
    let (t2, c2) = median_time(3, || {
        two.install(|| black_box(monte_carlo(&s, RUNS, 2)));
    });
    let sp = setup(false);
    let (tp, _) = median_time(3, || {
        one.install(|| black_box(monte_carlo(&sp, RUNS, 2)));
    });
    let rec = landmarks5();
    let (tc, _) = median_time(5, || {
        black_box(calibrate(&rec, &Options::default()).expect("calibrates"));
    });
    let cores = |c: Option<f64>, wall: f64| {
        c.map_or(String::new(), |c| {
            format!(", CPU {c:.3} s = {:.2} cores obtained", c / wall)
        })
    };
    println!("\nlandmarks summary (median of repetitions, this machine, this load):");
    println!(
        "  1,000-run Monte Carlo, refined, 1 thread : {t1:7.3} s  ({:6.0} runs/s{})",
        RUNS as f64 / t1,
        cores(c1, t1)
    );
    println!(
        "  1,000-run Monte Carlo, refined, 2 threads: {t2:7.3} s  ({:6.0} runs/s{})",
        RUNS as f64 / t2,
        cores(c2, t2)
    );
    println!("  speed-up 2 threads over 1 (wall)       : {:.2}x", t1 / t2);
    if let (Some(a), Some(b)) = (c1, c2) {
        // With both cores free, 2 threads would take (CPU time on 2 threads) / 2.
        println!(
            "  CPU-time ratio 1 thread / 2 threads    : {:.2} (parallel overhead {:+.0} %); \
             speed-up with two free cores: {:.2}x",
            a / b,
            (b / a - 1.0) * 100.0,
            2.0 * a / b
        );
    }
    println!(
        "  paper's estimator alone, 1 thread       : {tp:7.3} s  (refinement costs {:.1}x)",
        t1 / tp
    );
    println!(
        "  Fig. 9 grid ({FIG9_POINTS} points x {RUNS} runs) on 2 threads: ~{:.0} s",
        FIG9_POINTS as f64 * t2
    );
    println!(
        "  calibrate(landmarks-5) from raw scans   : {:7.1} ms",
        tc * 1e3
    );
}

fn main() {
    if std::env::var_os("LANDMARKS_SUMMARY_ONLY").is_some() {
        summary();
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    benches(&mut c);
    c.final_summary();
    // `cargo test --benches` runs each benchmark once with `--test`: no summary then.
    if !std::env::args().any(|a| a == "--test" || a == "--list") {
        summary();
    }
}
