//! Lidar throughput, rays per second, in worlds of 5, 50 and 500 cylinders, as a ratio over bare
//! `World::cast_ray` calls on the same world (the same 360 headings from the same origin, the
//! same cast limit), measured in the same run.
//!
//! `cargo bench -p hilsim-lidar-emulator --bench lidar_rays` prints criterion's timings and then,
//! timed here with the two loops interleaved, `lidar/bare = x.xx` per world (goal ≥ 0.7).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput};
use hilsim_lidar_emulator::{Lidar, LidarReading};
use hilsim_sim::{Pose, Scenario, StepState, WheelCommand, World};

/// One revolution: 360 readings at 300 rpm.
const REV_S: f64 = 0.2;
/// The lidar's cast limit with the default 6 m maximum range (it casts to twice that).
const CAST_LIMIT_M: f64 = 12.0;

/// A world of `n` cylinders on a golden-angle (Vogel) spiral between 1 m and 10 m from the robot,
/// which stands at the origin with a noisy lidar (the straight-board scenario's model).
fn scenario(n: usize) -> Scenario {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let cylinders: Vec<String> = (0..n)
        .map(|i| {
            let r = 1.0 + 9.0 * ((i as f64 + 0.5) / n as f64).sqrt();
            let a = golden * i as f64;
            let radius = 0.1 + 0.05 * (i % 3) as f64;
            format!(
                "{{ center = [{}, {}], radius = {radius} }}",
                r * a.cos(),
                r * a.sin()
            )
        })
        .collect();
    let text = format!(
        "name = \"lidar-rays-{n}\"\nduration_s = 1.0\n[world]\ncylinders = [{}]\n[robot]\n\
         start = {{ x = 0.0, y = 0.0 }}\nwheel_base_m = 0.23\n[sensors.lidar]\n\
         bias = [0.0525, 0.8838, 0.0584]\nnoise = [0.0, 0.0, 0.004]\nangle_noise_deg = 0.5\n",
        cylinders.join(", ")
    );
    Scenario::from_toml(&text, "lidar-rays.toml".as_ref()).expect("a valid scenario")
}

/// A lidar spinning on a robot that stands at the origin, one revolution per call.
struct Spinning {
    lidar: Lidar,
    step: StepState,
    out: Vec<LidarReading>,
}

impl Spinning {
    fn new(scenario: &Scenario) -> Self {
        let config = scenario.sensors.lidar.as_ref().expect("a lidar");
        let pose = Pose::new(0.0, 0.0, 0.0);
        Self {
            lidar: Lidar::new(config, 1).expect("a valid lidar"),
            step: StepState {
                index: 0,
                t0: -REV_S,
                t1: 0.0,
                pose0: pose,
                pose1: pose,
                command: WheelCommand::default(),
                wheels0: [0.0; 2],
                wheels1: [0.0; 2],
            },
            out: Vec::with_capacity(400),
        }
    }

    /// Takes one revolution of readings; returns how many.
    fn revolution(&mut self, world: &World) -> usize {
        self.step.index += 1;
        self.step.t0 += REV_S;
        self.step.t1 += REV_S;
        self.out.clear();
        self.lidar.observe(world, &self.step, &mut self.out);
        black_box(&self.out);
        self.out.len()
    }
}

/// The baseline: 360 bare casts, one per degree.
fn bare_revolution(world: &World) -> usize {
    let mut hits = 0;
    for deg in 0..360 {
        let heading = f64::from(deg).to_radians();
        hits += usize::from(black_box(world.cast_ray([0.0, 0.0], heading, CAST_LIMIT_M)).is_some());
    }
    black_box(hits);
    360
}

fn criterion_benches(c: &mut Criterion, worlds: &[(usize, Scenario, World)]) {
    let mut group = c.benchmark_group("lidar_rays");
    group.throughput(Throughput::Elements(360));
    for (n, scenario, world) in worlds {
        let mut spinning = Spinning::new(scenario);
        group.bench_function(format!("lidar/{n}_cylinders"), |b| {
            b.iter(|| spinning.revolution(world));
        });
        group.bench_function(format!("bare_cast_ray/{n}_cylinders"), |b| {
            b.iter(|| bare_revolution(world));
        });
    }
    group.finish();
}

/// Rays per second of the lidar and of the bare casts: the median of `rounds` interleaved
/// batches of `revs` revolutions each.
fn interleaved(scenario: &Scenario, world: &World, rounds: usize, revs: usize) -> (f64, f64) {
    let mut spinning = Spinning::new(scenario);
    let mut lidar = Vec::with_capacity(rounds);
    let mut bare = Vec::with_capacity(rounds);
    for _ in 0..rounds {
        let t = Instant::now();
        let rays: usize = (0..revs).map(|_| spinning.revolution(world)).sum();
        lidar.push(rays as f64 / t.elapsed().as_secs_f64());
        let t = Instant::now();
        let rays: usize = (0..revs).map(|_| bare_revolution(world)).sum();
        bare.push(rays as f64 / t.elapsed().as_secs_f64());
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    (median(lidar), median(bare))
}

fn main() {
    let worlds: Vec<(usize, Scenario, World)> = [5, 50, 500]
        .into_iter()
        .map(|n| {
            let s = scenario(n);
            let w = World::new(&s);
            (n, s, w)
        })
        .collect();
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(2))
        .configure_from_args();
    criterion_benches(&mut c, &worlds);
    c.final_summary();

    // Criterion runs each routine once under `cargo test --benches` or `-- --test`; time the
    // ratios only when benchmarking for real.
    let args: Vec<String> = std::env::args().collect();
    if !args.iter().any(|a| a == "--bench") || args.iter().any(|a| a == "--test" || a == "--list") {
        return;
    }
    println!();
    // Small batches (~0.3 ms), many of them, interleaved: a scheduler time slice lost to another
    // process spoils a few batches of either loop, not the median.
    println!("lidar_rays: median of 401 interleaved batches of 5 revolutions (1,800 rays)");
    for (n, scenario, world) in &worlds {
        let hit = (0..360)
            .filter(|&deg| {
                world
                    .cast_ray([0.0, 0.0], f64::from(deg).to_radians(), CAST_LIMIT_M)
                    .is_some()
            })
            .count();
        let (lidar, bare) = interleaved(scenario, world, 401, 5);
        println!(
            "  {n:>3} cylinders ({hit:>3}/360 beams hit): lidar {:>5.2} M rays/s, bare cast_ray \
             {:>5.2} M rays/s, lidar/bare = {:.2}  (goal >= 0.70)",
            lidar / 1e6,
            bare / 1e6,
            lidar / bare
        );
    }
}
