//! From raw scans: the whole calibrator on `scenarios/landmarks-5.toml` emulated at several
//! seeds, the paper's estimator and ours.

use std::time::Instant;

use hilsim_calibrator::landmarks::{analyse, Analysis, Estimator, Options};

use crate::Args;

pub fn run(a: &Args) {
    let t = Instant::now();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/landmarks-5.toml");
    let scenario = hilsim_sim::Scenario::load(path.as_ref()).expect("landmarks-5.toml loads");
    println!(
        "## From raw scans: scenarios/landmarks-5.toml, seeds 1..={}\n",
        a.seeds
    );
    println!("| seed | detections | landmarks | worst position error (mm) | order paper / refined | MSE ratio paper | MSE ratio refined |");
    println!("|---|---|---|---|---|---|---|");
    let (mut sp, mut sr, mut n) = (0.0, 0.0, 0.0);
    let cylinders: Vec<[f64; 2]> = scenario.world.cylinders.iter().map(|c| c.center).collect();
    for sd in 1..=a.seeds {
        let rec = hilsim_lidar_emulator::Emulation::new(&scenario, sd)
            .expect("sensors build")
            .run()
            .recording;
        let paper = analyse(
            &rec,
            &Options {
                estimator: Estimator::Paper,
                ..Options::default()
            },
        );
        let refined = analyse(&rec, &Options::default());
        match (paper, refined) {
            (Ok(p), Ok(r)) => {
                let (mp, mr) = row(sd, &p, &r, &cylinders);
                sp += mp;
                sr += mr;
                n += 1.0;
            }
            (p, r) => println!("| {sd} | failed: {:?} / {:?} | | | | | |", p.err(), r.err()),
        }
    }
    println!(
        "\nMean MSE ratio over {n} seeds: paper {:.1}, refined {:.1} ({:.1} s)\n",
        sp / n,
        sr / n,
        t.elapsed().as_secs_f64()
    );
}

/// Prints a seed's row; returns its MSE ratios, paper and refined.
fn row(sd: u64, p: &Analysis, r: &Analysis, cylinders: &[[f64; 2]]) -> (f64, f64) {
    let worst = r
        .calibration
        .landmarks
        .iter()
        .flatten()
        .map(|e| {
            cylinders
                .iter()
                .map(|c| (e[0] - c[0]).hypot(e[1] - c[1]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    let (mp, mr) = (
        p.calibration.metrics.map_or(f64::NAN, |m| m.mse_ratio()),
        r.calibration.metrics.map_or(f64::NAN, |m| m.mse_ratio()),
    );
    println!(
        "| {sd} | {} | {} | {:.1} | {} / {} | {mp:.1} | {mr:.1} |",
        r.detections.len(),
        r.tracks.len(),
        worst * 1e3,
        p.calibration.order.unwrap_or(0),
        r.calibration.order.unwrap_or(0),
    );
    (mp, mr)
}
