//! Reads real logs and prints what each gave and how long reading took:
//!
//! ```text
//! cargo run --release -p hilsim-logs --example read_logs -- intel.log.gz aces.log.gz exp1.dat
//! ```
//!
//! A `.dat` file is read as a CoreSLAM log, anything else as a CARMEN log (poses as truth).

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use hilsim_logs::{read_carmen, read_coreslam, read_text, CarmenOptions, CoreSlamOptions};

fn main() -> ExitCode {
    let mut status = ExitCode::SUCCESS;
    for path in std::env::args().skip(1) {
        let start = Instant::now();
        let result = read_text(Path::new(&path)).and_then(|text| {
            if path.ends_with(".dat") {
                read_coreslam(&text, &path, &CoreSlamOptions::default()).map(|r| (r, Vec::new()))
            } else {
                read_carmen(&text, &path, &CarmenOptions::default())
            }
        });
        let elapsed = start.elapsed();
        match result {
            Ok((rec, notes)) => {
                let lidar = rec.lidar.as_deref().unwrap_or_default();
                println!(
                    "{path}: {} scans ({} readings), {} truth poses, {} odometry rows, {:.1} s \
                     of log; read in {:.3} s",
                    lidar.last().map_or(0, |s| s.rev + 1),
                    lidar.len(),
                    rec.truth.as_ref().map_or(0, Vec::len),
                    rec.odometry.as_ref().map_or(0, Vec::len),
                    rec.duration_s(),
                    elapsed.as_secs_f64()
                );
                for note in notes {
                    println!("  note: {note}");
                }
            }
            Err(e) => {
                eprintln!("read_logs: {e}");
                status = ExitCode::FAILURE;
            }
        }
    }
    status
}
