//! The world alone: simulated seconds per wall second of `Simulation::step` (physics at 100 Hz,
//! the drive program, truth and contact logging) in a 50-cylinder world with the robot driving,
//! as a ratio over a bare rapier2d loop stepping the same bodies, measured in the same run.
//!
//! `cargo bench -p hilsim-sim --bench world_step` prints criterion's timings of both and then the
//! ratio, timed here by interleaving the two loops so that both see the same machine state:
//! `sim/bare = x.xx` (goal ≥ 0.8).

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BatchSize, Criterion};
use hilsim_sim::{DriveProgram, Scenario, Simulation};
use rapier2d::prelude::*;

/// Physics steps per measured run: 10 simulated seconds.
const STEPS: u64 = 1000;
/// Cylinders in the world.
const CYLINDERS: usize = 50;
const ROBOT_RADIUS: f32 = 0.165;
const WHEEL_BASE: f64 = 0.23;

/// Centre and radius of cylinder `i` of `n`: a golden-angle (Vogel) spiral between 2.5 m and
/// 9 m from the origin, clear of the robot's 1 m square path and of each other.
fn cylinder(i: usize, n: usize) -> ([f64; 2], f64) {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let r = 2.5 + 6.5 * ((i as f64 + 0.5) / n as f64).sqrt();
    let a = golden * i as f64;
    ([r * a.cos(), r * a.sin()], 0.1 + 0.05 * (i % 3) as f64)
}

/// The robot drives a 1 m square (straight, turn 90°, …) over and over: 40 × 4 sides of 2 s plus
/// 4 turns of 1 s, 480 s in all, far more than one measured run.
fn scenario() -> Scenario {
    let cylinders: Vec<String> = (0..CYLINDERS)
        .map(|i| {
            let ([x, y], r) = cylinder(i, CYLINDERS);
            format!("{{ center = [{x}, {y}], radius = {r} }}")
        })
        .collect();
    let lap = "[[drive]]\nspeed_mps = 0.5\ndistance_m = 1.0\n[[drive]]\nturn_deg = 90.0\n";
    let text = format!(
        "name = \"world-step\"\n[world]\ncylinders = [{}]\n[robot]\n\
         start = {{ x = -0.5, y = -0.5 }}\nwheel_base_m = {WHEEL_BASE}\nturn_rate_deg_s = 90.0\n{}",
        cylinders.join(", "),
        lap.repeat(4 * 40)
    );
    Scenario::from_toml(&text, "world-step.toml".as_ref()).expect("a valid scenario")
}

/// The bare loop: the same 50 fixed cylinders and one dynamic ball in a rapier2d `PhysicsWorld`
/// (zero gravity, dt 0.01), its velocity set each step from the same wheel commands.
struct Bare {
    physics: PhysicsWorld,
    ball: RigidBodyHandle,
    /// Body twist (v, ω) per step.
    twists: Vec<(f32, f32)>,
    step: usize,
}

impl Bare {
    fn new(scenario: &Scenario, ccd: bool) -> Self {
        let mut physics = PhysicsWorld {
            gravity: Vector::ZERO,
            integration_parameters: IntegrationParameters {
                dt: 0.01,
                ..IntegrationParameters::default()
            },
            ..PhysicsWorld::default()
        };
        let fixed = physics.insert_body(RigidBodyBuilder::fixed());
        for c in &scenario.world.cylinders {
            let center = Vector::new(c.center[0] as f32, c.center[1] as f32);
            physics.insert_collider(
                ColliderBuilder::ball(c.radius as f32).translation(center),
                Some(fixed),
            );
        }
        let start = scenario.robot.start;
        let (ball, _) = physics.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(start.x as f32, start.y as f32))
                .can_sleep(false)
                .ccd_enabled(ccd),
            ColliderBuilder::ball(ROBOT_RADIUS).friction(0.0),
        );
        let program = DriveProgram::new(scenario);
        let twists = (0..program.total_steps())
            .map(|i| {
                let c = program.command_at(i);
                let v = (c.left_mps + c.right_mps) / 2.0;
                let omega = (c.right_mps - c.left_mps) / WHEEL_BASE;
                (v as f32, omega as f32)
            })
            .collect();
        Self {
            physics,
            ball,
            twists,
            step: 0,
        }
    }

    fn step(&mut self) {
        let (v, omega) = self.twists[self.step];
        self.step += 1;
        let body = &mut self.physics.bodies[self.ball];
        let (sin, cos) = body.rotation().angle().sin_cos();
        body.set_linvel(Vector::new(v * cos, v * sin), true);
        body.set_angvel(omega, true);
        self.physics.step();
    }
}

fn run_sim(sim: &mut Simulation) {
    for _ in 0..STEPS {
        black_box(sim.step());
    }
}

fn run_bare(bare: &mut Bare) {
    for _ in 0..STEPS {
        bare.step();
    }
    black_box(bare.physics.bodies[bare.ball].translation());
}

fn criterion_benches(c: &mut Criterion, scenario: &Scenario) {
    let mut group = c.benchmark_group("world_step_1000");
    group.bench_function("simulation", |b| {
        b.iter_batched(
            || Simulation::new(scenario),
            |mut sim| run_sim(&mut sim),
            BatchSize::LargeInput,
        );
    });
    group.bench_function("bare_rapier", |b| {
        b.iter_batched(
            || Bare::new(scenario, false),
            |mut bare| run_bare(&mut bare),
            BatchSize::LargeInput,
        );
    });
    group.bench_function("bare_rapier_ccd", |b| {
        b.iter_batched(
            || Bare::new(scenario, true),
            |mut bare| run_bare(&mut bare),
            BatchSize::LargeInput,
        );
    });
    group.finish();
}

/// Median wall time of `rounds` runs of each loop, the loops interleaved.
fn interleaved(scenario: &Scenario, rounds: usize) -> [Duration; 3] {
    let mut times: [Vec<Duration>; 3] = Default::default();
    for _ in 0..rounds {
        let mut sim = Simulation::new(scenario);
        let t = Instant::now();
        run_sim(&mut sim);
        times[0].push(t.elapsed());
        for (k, ccd) in [(1, false), (2, true)] {
            let mut bare = Bare::new(scenario, ccd);
            let t = Instant::now();
            run_bare(&mut bare);
            times[k].push(t.elapsed());
        }
    }
    times.map(|mut v| {
        v.sort();
        v[v.len() / 2]
    })
}

fn main() {
    let scenario = scenario();
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .configure_from_args();
    criterion_benches(&mut c, &scenario);
    c.final_summary();

    // Criterion runs each routine once under `cargo test --benches` or `-- --test`; time the
    // ratio only when benchmarking for real.
    let args: Vec<String> = std::env::args().collect();
    if !args.iter().any(|a| a == "--bench") || args.iter().any(|a| a == "--test" || a == "--list") {
        return;
    }
    let [sim, bare, bare_ccd] = interleaved(&scenario, 31);
    let simulated = STEPS as f64 * scenario.step_s();
    let speed = |d: Duration| simulated / d.as_secs_f64();
    println!();
    println!("world_step: {STEPS} steps ({simulated} simulated s), median of 31 interleaved runs");
    println!(
        "  simulation:       {:>9.0} simulated s per wall s",
        speed(sim)
    );
    println!(
        "  bare rapier:      {:>9.0} simulated s per wall s",
        speed(bare)
    );
    println!(
        "  bare rapier+CCD:  {:>9.0} simulated s per wall s",
        speed(bare_ccd)
    );
    println!(
        "sim/bare = {:.2}  (goal >= 0.80; the robot's body has CCD on: sim/bare_ccd = {:.2})",
        speed(sim) / speed(bare),
        speed(sim) / speed(bare_ccd)
    );
}
