//! The odometry method on the paper's own tuples against its published calibration (Censi,
//! Franchi, Marchionni, Oriolo, IEEE T-RO 29(2), 2013, configuration A):
//!
//! ```text
//! cargo run --release -p hilsim-calibrator --example reproduce_censi -- TUPLES RESULTS.json
//! ```
//!
//! prints each parameter, ours and the published, their standard deviations, the difference in
//! combined standard deviations and the ratio of ours to the published one. Exit 1 when a
//! parameter differs by more than 2 combined standard deviations or ours is more than 3 times
//! the published.

use std::process::ExitCode;

use hilsim_calibrator::odometry::{calibrate_tuples, parse_tuples};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [tuples, results] = args.as_slice() else {
        eprintln!("usage: reproduce_censi TUPLES RESULTS.json");
        return ExitCode::from(2);
    };
    match run(tuples, results) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("reproduce_censi: {e}");
            ExitCode::from(2)
        }
    }
}

fn run(tuples: &str, results: &str) -> Result<bool, String> {
    let text = std::fs::read_to_string(tuples).map_err(|e| format!("{tuples}: {e}"))?;
    let (list, unsound) = parse_tuples(&text, tuples).map_err(|e| e.to_string())?;
    let calibration = calibrate_tuples(&list, unsound).map_err(|e| format!("{tuples}: {e}"))?;
    print!("{}", calibration.describe());
    let published: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(results).map_err(|e| format!("{results}: {e}"))?,
    )
    .map_err(|e| format!("{results}: {e}"))?;
    let Some(ours) = calibration.odometry else {
        return Err("no odometry in the calibration".into());
    };
    let number = |key: &str| {
        published[key]
            .as_f64()
            .ok_or(format!("{results}: no `{key}`"))
    };
    // The published diameters halved: the covariance's first two entries are the radii's.
    let theirs = [
        number("l_diam")? / 2.0,
        number("r_diam")? / 2.0,
        number("axle")?,
        number("l_x")?,
        number("l_y")?,
        number("l_theta")?,
    ];
    let their_sd: Vec<f64> = (0..6)
        .map(|i| {
            published["covariance"][i][i]
                .as_f64()
                .map(|v| v.max(0.0).sqrt())
                .ok_or(format!("{results}: no covariance[{i}][{i}]"))
        })
        .collect::<Result<_, _>>()?;
    let (values, sd) = (ours.parameters(), ours.standard_deviations());
    println!(
        "{:<20} {:>12} {:>10} {:>12} {:>10} {:>8} {:>8}",
        "parameter", "ours", "sd", "published", "sd", "sigmas", "sd ratio"
    );
    let mut within = true;
    for (i, name) in [
        "left radius (mm)",
        "right radius (mm)",
        "wheel base (mm)",
        "lidar x (mm)",
        "lidar y (mm)",
        "lidar yaw (mrad)",
    ]
    .iter()
    .enumerate()
    {
        let combined = sd[i].hypot(their_sd[i]);
        let sigmas = (values[i] - theirs[i]) / combined;
        let ratio = sd[i] / their_sd[i];
        within &= sigmas.abs() <= 2.0 && ratio <= 3.0;
        println!(
            "{name:<20} {:>12.4} {:>10.4} {:>12.4} {:>10.4} {sigmas:>8.2} {ratio:>8.2}",
            values[i] * 1e3,
            sd[i] * 1e3,
            theirs[i] * 1e3,
            their_sd[i] * 1e3
        );
    }
    Ok(within)
}
