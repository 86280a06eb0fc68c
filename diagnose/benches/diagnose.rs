//! `hilsim diagnose` benchmark: diagnosing a 60 s recording of `diagnose-room` (a lidar
//! revolution every 0.2 s, 108,000 readings, sonar, encoders, truth) with every catalogued effect
//! tried, on one core and on two; the baseline of the same run is recording those 60 s
//! (`Emulation::run`, what `hilsim record` does). Goal: at most 5 s on two cores.
//!
//! ```text
//! cargo bench -p hilsim-diagnose --bench diagnose
//! ```
//!
//! Criterion reports the two-core diagnosis; a summary (wall and CPU time on 1 and 2 threads,
//! the ratio to recording) is measured again and printed at the end. The CPU time shows how many
//! cores the run actually obtained on a shared machine.

use std::time::{Duration, Instant};

use criterion::Criterion;

use cpu_time::ProcessTime;
use hilsim_diagnose::{diagnose, Options, SimPhysics, Verdict};
use hilsim_recording::Recording;
use hilsim_sim::Scenario;

/// The nominal scenario run for 60 s, and a "real" run of it with the lidar's incidence effect.
fn setup() -> (Scenario, Recording) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/diagnose-room.toml"
    );
    let mut nominal = Scenario::load(path.as_ref()).expect("diagnose-room.toml loads");
    nominal.duration_s = Some(60.0);
    let mut real = nominal.clone();
    real.seed = 1234;
    real.effects.lidar_incidence_angle = Some(hilsim_sim::scenario::LidarIncidenceAngle {
        coefficient: 0.02,
        collimated_m: 0.0,
        exponent: 1.0,
    });
    (nominal, record(&real))
}

fn record(s: &Scenario) -> Recording {
    hilsim_lidar_emulator::Emulation::new(s, s.seed)
        .expect("sensors build")
        .run()
        .recording
}

fn run(nominal: &Scenario, real: &Recording) {
    // A fresh physics each time: its beam cache belongs to one diagnosis.
    let physics = SimPhysics::new(nominal).expect("a valid scenario");
    let d = diagnose(&physics, real, &Options::default()).expect("a diagnosis");
    assert!(matches!(d.verdict, Verdict::Effect(_)));
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
}

/// Wall and CPU time of one call.
fn timed(f: impl FnOnce()) -> (f64, Option<f64>) {
    // CPU time of the whole process (all threads), from the OS clock.
    let c0 = ProcessTime::try_now().ok();
    let t0 = Instant::now();
    f();
    let wall = t0.elapsed().as_secs_f64();
    (wall, c0.map(|c| c.elapsed().as_secs_f64()))
}

fn benches(c: &mut Criterion) {
    let (nominal, real) = setup();
    let mut g = c.benchmark_group("diagnose_60s");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(60));
    g.bench_function("two_cores", |b| {
        let two = pool(2);
        b.iter(|| two.install(|| run(&nominal, &real)));
    });
    g.finish();
}

/// The longest a 60 s recording's diagnosis with truth may take on two cores, seconds.
const GOAL_S: f64 = 5.0;

fn summary() {
    let (nominal, real) = setup();
    let (record_s, _) = timed(|| {
        let _ = record(&nominal);
    });
    let cpu = |c: Option<f64>| c.map_or("—".to_string(), |c| format!("{c:.1} s CPU"));
    println!("diagnose a 60 s recording, every effect tried:");
    for threads in [1, 2] {
        let p = pool(threads);
        let (wall, c) = timed(|| p.install(|| run(&nominal, &real)));
        println!(
            "  {threads} thread(s): {wall:.1} s wall ({}), {:.0}× recording it ({record_s:.2} s); goal ≤ {GOAL_S} s on 2: {}",
            cpu(c),
            wall / record_s,
            if threads == 2 && wall > GOAL_S {
                "MISSED"
            } else {
                "ok"
            }
        );
    }
}

fn main() {
    if std::env::var_os("DIAGNOSE_SUMMARY_ONLY").is_none() {
        let mut c = Criterion::default().configure_from_args();
        benches(&mut c);
        c.final_summary();
    }
    summary();
}
