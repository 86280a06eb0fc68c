//! EM calibrator benchmarks: nanoseconds per sample per EM iteration, one smoother pass, and a
//! whole calibration of a 10⁴-sample recording, each against a baseline measured in the same
//! run: a textbook 3-state Kalman filter + RTS smoother pass with fixed-size nalgebra types
//! (the prototype the EM smoother is held to: one full EM iteration within 2× of its pass).
//!
//! ```text
//! cargo bench -p hilsim-calibrator --bench em
//! ```
//!
//! Criterion reports each benchmark; a summary of ratios (measured again, median of
//! repetitions) is printed at the end.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput};
use hilsim_calibrator::em::{self, EStep, EmOptions};
use hilsim_calibrator::kalman_smoother::{
    Gaussian, Observation, Observations, RtsSmoother, StateSpaceModel, Transition,
};
use hilsim_calibrator::target_samples::{self, SampleOptions, TargetSamples};
use hilsim_calibrator::{smoothing, Calibration, Sensor};
use hilsim_fixtures::em_experiment;
use nalgebra::{Matrix2, Vector2};
use nalgebra::{Matrix3, Vector3};

/// Samples of the benchmark recording (the brief's "10⁴-sample recording").
const N: usize = 10_000;

/// The baseline: a 3-state (`[1, d, d²]`) Kalman filter and RTS smoother with one scalar
/// observation per step, constant model, fixed-size types, preallocated storage.
struct Prototype {
    xf: Vec<Vector3<f64>>,
    pf: Vec<Matrix3<f64>>,
    xp: Vec<Vector3<f64>>,
    pp: Vec<Matrix3<f64>>,
    xs: Vec<Vector3<f64>>,
    ps: Vec<Matrix3<f64>>,
}

impl Prototype {
    fn new(n: usize) -> Self {
        Self {
            xf: vec![Vector3::zeros(); n],
            pf: vec![Matrix3::zeros(); n],
            xp: vec![Vector3::zeros(); n],
            pp: vec![Matrix3::zeros(); n],
            xs: vec![Vector3::zeros(); n],
            ps: vec![Matrix3::zeros(); n],
        }
    }

    fn pass(&mut self, ys: &[f64], u: f64) -> f64 {
        let a = Matrix3::new(1.0, 0.0, 0.0, u, 1.0, 0.0, u * u, 2.0 * u, 1.0);
        let q = Matrix3::from_diagonal(&Vector3::new(1e-12, 1e-8, 1e-7));
        let c = Vector3::new(0.05, 0.88, 0.06);
        let r = 1e-4;
        let mut x = Vector3::new(1.0, 0.5, 0.25);
        let mut p = Matrix3::from_diagonal(&Vector3::new(1e-12, 1e-6, 1e-6));
        for (k, &y) in ys.iter().enumerate() {
            self.xp[k] = x;
            self.pp[k] = p;
            let ph = p * c;
            let s = c.dot(&ph) + r;
            let g = ph / s;
            x += g * (y - c.dot(&x));
            p -= g * ph.transpose();
            self.xf[k] = x;
            self.pf[k] = p;
            x = a * x;
            p = a * p * a.transpose() + q;
        }
        let n = ys.len();
        self.xs[n - 1] = self.xf[n - 1];
        self.ps[n - 1] = self.pf[n - 1];
        for k in (0..n - 1).rev() {
            let inv = self.pp[k + 1]
                .try_inverse()
                .unwrap_or_else(Matrix3::identity);
            let j = self.pf[k] * a.transpose() * inv;
            self.xs[k] = self.xf[k] + j * (self.xs[k + 1] - self.xp[k + 1]);
            self.ps[k] = self.pf[k] + j * (self.ps[k + 1] - self.pp[k + 1]) * j.transpose();
        }
        self.xs[0][1]
    }
}

fn samples(rec: &hilsim_recording::Recording) -> TargetSamples {
    target_samples::extract(rec, &SampleOptions::default()).expect("synthetic recording")
}

fn fixed_iterations(variant: EStep, sensors: bool, iterations: usize) -> EmOptions {
    EmOptions {
        use_odometer: sensors,
        use_sonar: sensors,
        e_step: variant,
        max_iterations: iterations,
        accelerate: false,
        // Never converge early: the run must do exactly `iterations` E-steps.
        tolerance: f64::MIN_POSITIVE,
        ..EmOptions::default()
    }
}

/// Median wall time of `f` over enough repetitions to fill ~0.5 s (at least 5).
fn median_time(mut f: impl FnMut()) -> Duration {
    f();
    let t = Instant::now();
    f();
    let once = t.elapsed().max(Duration::from_nanos(1));
    let reps = ((0.5 / once.as_secs_f64()) as usize).clamp(5, 200);
    let mut times: Vec<Duration> = (0..reps)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed()
        })
        .collect();
    times.sort();
    times[reps / 2]
}

fn summary(rec: &hilsim_recording::Recording, s: &TargetSamples) {
    let ys: Vec<f64> = s.lidar_m.iter().map(|y| y.unwrap_or(0.0)).collect();
    let mut proto = Prototype::new(ys.len());
    let base = median_time(|| {
        black_box(proto.pass(black_box(&ys), 3.5 / N as f64));
    })
    .as_secs_f64()
        * 1e9
        / N as f64;
    println!("\n# EM benchmark summary ({N} samples)\n");
    println!("baseline: prototype 3-state KF+RTS pass: {base:.1} ns/step\n");
    println!("| what | ns per sample | ratio to baseline |\n|---|---|---|");
    let trained = em::calibrate(rec, &EmOptions::default()).expect("calibrates");
    for (label, sensors) in [("lidar", false), ("lidar+odo+sonar", true)] {
        let opts = fixed_iterations(EStep::Paper, sensors, 1);
        let t = median_time(|| {
            black_box(smoothing::smooth_samples(s, &trained, &opts).expect("smooths"));
        })
        .as_secs_f64()
            * 1e9
            / N as f64;
        println!(
            "| one smoother pass (Sec. V), {label} | {t:.1} | {:.2} |",
            t / base
        );
    }
    for variant in [EStep::Paper, EStep::SecondOrder, EStep::Relinearized] {
        for (label, sensors) in [("lidar", false), ("lidar+odo+sonar", true)] {
            let (k1, k2) = (1, 11);
            let t1 = median_time(|| {
                black_box(em::run_samples(
                    s.clone(),
                    &fixed_iterations(variant, sensors, k1),
                ))
                .expect("runs");
            });
            let t2 = median_time(|| {
                black_box(em::run_samples(
                    s.clone(),
                    &fixed_iterations(variant, sensors, k2),
                ))
                .expect("runs");
            });
            let per = (t2.as_secs_f64() - t1.as_secs_f64()) * 1e9 / ((k2 - k1) * N) as f64;
            println!(
                "| one EM iteration (E + M), E-step {}, {label} | {per:.1} | {:.2} |",
                variant.name(),
                per / base
            );
        }
    }
    for (label, sensors) in [("lidar", false), ("lidar+odo+sonar", true)] {
        let opts = EmOptions {
            use_odometer: sensors,
            use_sonar: sensors,
            ..EmOptions::default()
        };
        let mut iterations = 0;
        let t = median_time(|| {
            iterations = em::calibrate(rec, &opts).expect("calibrates").iterations;
        });
        println!(
            "| whole calibration (defaults), {label}: {:.1} ms, {iterations} iterations | {:.1} | {:.1} |",
            t.as_secs_f64() * 1e3,
            t.as_secs_f64() * 1e9 / N as f64,
            t.as_secs_f64() * 1e9 / N as f64 / base
        );
    }
}

/// The E-step's lidar-only model at trained parameters, written out step by step, so that the
/// same model can be handed to pykalman (`benches/pykalman/compare.py`).
struct ExplicitModel {
    prior: Gaussian<2>,
    transitions: Vec<Transition<2>>,
    observations: Vec<Option<Observation<2>>>,
}

impl StateSpaceModel<2> for ExplicitModel {
    fn steps(&self) -> usize {
        self.observations.len()
    }
    fn prior(&self) -> Gaussian<2> {
        self.prior
    }
    fn transition(&self, k: usize) -> Transition<2> {
        self.transitions[k]
    }
    fn observations(&self, k: usize, out: &mut Observations<2>) {
        if let Some(o) = self.observations[k] {
            out.push(o);
        }
    }
}

/// As the EM model (`em/model.rs`): `[d, d²]`, `A = [[1, 0], [2u, 1]]`, the process noise of a
/// speed-scale error q = 0.02 plus the 0.1 mm floor, `R = (β2 d²)²` at dead reckoning.
fn explicit_model(s: &TargetSamples, trained: &Calibration) -> ExplicitModel {
    let lidar = &trained.sensors[&Sensor::Lidar];
    let (a, b2) = (&lidar.alpha, lidar.beta[2]);
    let d0 = s.start_distance_m.expect("start");
    let (q, f) = (0.02, 1e-4);
    let noise = |u: f64, m: f64| {
        let s2 = (q * u) * (q * u);
        let f2 = f * f;
        Matrix2::new(
            s2 + f2,
            2.0 * m * s2,
            2.0 * m * s2,
            4.0 * m * m * s2 + 2.0 * s2 * s2 + 4.0 * m.max(0.1).powi(2) * f2,
        )
    };
    let transitions = (0..s.len())
        .map(|k| {
            let u = s.u(k);
            let m = d0 + s.commanded_m[k] + u;
            Transition {
                a: Matrix2::new(1.0, 0.0, 2.0 * u, 1.0),
                b: Vector2::new(u, u * u + (q * u).powi(2)),
                q: noise(u, m),
            }
        })
        .collect();
    let observations = (0..s.len())
        .map(|k| {
            s.lidar_m[k].map(|y| {
                let d = d0 + s.commanded_m[k];
                Observation {
                    y,
                    offset: a[0],
                    h: Vector2::new(a[1], a[2]),
                    r: (b2 * d * d).powi(2),
                }
            })
        })
        .collect();
    let m0 = d0 + s.commanded_m[0];
    ExplicitModel {
        prior: Gaussian::new(Vector2::new(m0, m0 * m0), noise(0.0, m0)),
        transitions,
        observations,
    }
}

/// Writes the explicit model and the Rust smoother's output and timing for
/// `benches/pykalman/compare.py`.
fn export_for_pykalman(dir: &std::path::Path, model: &ExplicitModel, ns_per_step: f64) {
    use std::fmt::Write as _;
    let mut smoother = RtsSmoother::<2>::new();
    smoother.run(model).expect("runs");
    let mut csv = String::from(
        "a00,a01,a10,a11,b0,b1,q00,q01,q10,q11,y,h0,h1,offset,r,d_smoothed,d2_smoothed,var_d\n",
    );
    for k in 0..model.steps() {
        let t = model.transitions[k];
        let (y, h0, h1, off, r) = match model.observations[k] {
            Some(o) => (o.y, o.h[0], o.h[1], o.offset, o.r),
            None => (f64::NAN, 0.0, 0.0, 0.0, 1.0),
        };
        let (m, p) = (smoother.smoothed_means()[k], smoother.smoothed_covs()[k]);
        let _ = writeln!(
            csv,
            "{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
            t.a[(0, 0)], t.a[(0, 1)], t.a[(1, 0)], t.a[(1, 1)], t.b[0], t.b[1],
            t.q[(0, 0)], t.q[(0, 1)], t.q[(1, 0)], t.q[(1, 1)],
            y, h0, h1, off, r, m[0], m[1], p[(0, 0)]
        );
    }
    let prior = format!(
        "{:e},{:e},{:e},{:e},{:e},{:e}\n{ns_per_step}\n",
        model.prior.mean[0],
        model.prior.mean[1],
        model.prior.cov[(0, 0)],
        model.prior.cov[(0, 1)],
        model.prior.cov[(1, 0)],
        model.prior.cov[(1, 1)]
    );
    std::fs::create_dir_all(dir).expect("export directory");
    std::fs::write(dir.join("model.csv"), csv).expect("writes model.csv");
    std::fs::write(dir.join("prior_and_rust_ns.txt"), prior).expect("writes prior");
}

fn main() {
    let rec =
        em_experiment::synthetic_recording(N, &mut hilsim_sim::rng::stream(1, "issue-5-synthetic"));
    let s = samples(&rec);
    // `EM_BENCH_PYKALMAN_DIR=DIR cargo bench -p hilsim-calibrator --bench em -- --list` (any
    // filter) exports the model for the pykalman comparison and times the Rust pass on it.
    if let Some(dir) = std::env::var_os("EM_BENCH_PYKALMAN_DIR") {
        let trained = em::calibrate(&rec, &EmOptions::default()).expect("calibrates");
        let model = explicit_model(&s, &trained);
        let mut smoother = RtsSmoother::<2>::new();
        let ns = median_time(|| {
            black_box(smoother.run(&model).expect("runs"));
        })
        .as_secs_f64()
            * 1e9
            / N as f64;
        export_for_pykalman(dir.as_ref(), &model, ns);
        println!(
            "exported the model to {}; Rust RTS pass: {ns:.1} ns/step",
            dir.to_string_lossy()
        );
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    {
        let mut g = c.benchmark_group("em");
        g.throughput(Throughput::Elements(N as u64));
        let ys: Vec<f64> = s.lidar_m.iter().map(|y| y.unwrap_or(0.0)).collect();
        let mut proto = Prototype::new(N);
        g.bench_function("baseline_prototype_pass", |b| {
            b.iter(|| proto.pass(black_box(&ys), 3.5 / N as f64));
        });
        for (name, sensors) in [("lidar", false), ("three_sensors", true)] {
            g.bench_function(format!("ten_iterations_{name}"), |b| {
                b.iter(|| em::run_samples(s.clone(), &fixed_iterations(EStep::Paper, sensors, 10)));
            });
        }
        g.sample_size(10);
        g.bench_function("calibrate_10k", |b| {
            b.iter(|| em::calibrate(black_box(&rec), &EmOptions::default()));
        });
        g.finish();
    }
    c.final_summary();
    summary(&rec, &s);
}
