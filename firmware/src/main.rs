//! An example firmware for `hilsim hil`, written as firmware for a real robot would be: it knows
//! the lidar's device path (`HILSIM_LIDAR_PORT`, a Neato XV-11 stream, or with `--lidar
//! rplidar-a1` a Slamtec RPLIDAR A1 it starts itself) and the robot's command port
//! (`HILSIM_ROBOT_PORT`, the Neato USB command interface), and nothing else of hilsim.
//!
//! It drives straight at whatever is in front of it and stops 0.50 m from it: each lidar
//! revolution gives the distance ahead (the median of the readings within ±5°); while that is
//! above the target it issues `SetMotor` steps of the remaining distance at a speed
//! proportional to it (300 mm/s at most, 30 mm/s at least), and once it is at or below the
//! target it stops, checks two more revolutions, prints a summary and exits.
//!
//! Exit status: 0 target reached; 2 setup failed (a port could not be opened); 3 the ports
//! closed before the target was reached; 4 the lidar stream had gaps in its packet index
//! sequence (the summary line says how many), unless run with `--allow-gaps` (for a link that
//! drops packets, a scenario's `[link]`).

mod robot;
mod rplidar;
mod xv11;

use std::io::{ErrorKind, Read, Write};
use std::process::ExitCode;
use std::sync::mpsc;
use std::thread;
use std::time::Duration;

use robot::RobotPort;
use xv11::{front_mm, Decoder};

/// Where to stop: the distance ahead, mm.
const TARGET_MM: u16 = 500;
/// Speed limits, mm/s.
const MAX_SPEED: i64 = 300;
const MIN_SPEED: i64 = 30;
/// Speed per millimetre still to go, 1/s: the approach slows down exponentially (time
/// constant 0.5 s) so that a distance measured a revolution ago costs little overshoot.
const GAIN: i64 = 2;
/// Half the width of the forward window, degrees.
const FRONT_HALF_WIDTH_DEG: usize = 5;

/// What the lidar thread reports per revolution.
struct Revolution {
    front_mm: Option<u16>,
    index_gaps: u64,
    bad_checksums: u64,
    revolutions: u64,
}

fn main() -> ExitCode {
    let (Some(lidar_path), Some(robot_path)) = (
        std::env::var_os("HILSIM_LIDAR_PORT"),
        std::env::var_os("HILSIM_ROBOT_PORT"),
    ) else {
        eprintln!("example-firmware: HILSIM_LIDAR_PORT and HILSIM_ROBOT_PORT must be set");
        return ExitCode::from(2);
    };
    let lidar = serialport::new(lidar_path.to_string_lossy(), 115_200)
        .timeout(Duration::from_millis(500))
        .open();
    let robot = RobotPort::open(&robot_path.to_string_lossy());
    let (mut lidar, mut robot) = match (lidar, robot) {
        (Ok(lidar), Ok(robot)) => (lidar, robot),
        (Err(err), _) => {
            eprintln!("example-firmware: lidar port: {err}");
            return ExitCode::from(2);
        }
        (_, Err(err)) => {
            eprintln!("example-firmware: robot port: {err}");
            return ExitCode::from(2);
        }
    };

    let (tx, revolutions) = mpsc::channel();
    let rplidar = std::env::args()
        .collect::<Vec<_>>()
        .windows(2)
        .any(|w| w[0] == "--lidar" && w[1] == "rplidar-a1");
    if rplidar {
        if let Err(err) = lidar.write_all(&rplidar::START) {
            eprintln!("example-firmware: lidar port: {err}");
            return ExitCode::from(2);
        }
    }
    thread::spawn(move || {
        let mut xv11 = Decoder::new();
        let mut rplidar_decoder = rplidar::Decoder::default();
        let mut buf = [0u8; 4096];
        loop {
            match lidar.read(&mut buf) {
                Ok(0) => return,
                Ok(n) => {
                    let mut reports = Vec::new();
                    if rplidar {
                        let decoder = &mut rplidar_decoder;
                        let mut fronts = Vec::new();
                        decoder.feed(&buf[..n], |scan| {
                            fronts.push(rplidar::front_mm(scan, FRONT_HALF_WIDTH_DEG as f64))
                        });
                        reports.extend(fronts.into_iter().map(|front| Revolution {
                            front_mm: front,
                            index_gaps: 0,
                            bad_checksums: decoder.bad_nodes,
                            revolutions: decoder.revolutions,
                        }));
                    } else {
                        let mut fronts = Vec::new();
                        xv11.feed(&buf[..n], |scan| {
                            fronts.push(front_mm(scan, FRONT_HALF_WIDTH_DEG))
                        });
                        reports.extend(fronts.into_iter().map(|front| Revolution {
                            front_mm: front,
                            index_gaps: xv11.index_gaps,
                            bad_checksums: xv11.bad_checksums,
                            revolutions: xv11.revolutions,
                        }));
                    }
                    for report in reports {
                        if tx.send(report).is_err() {
                            return;
                        }
                    }
                }
                Err(e) if e.kind() == ErrorKind::TimedOut || e.kind() == ErrorKind::Interrupted => {
                }
                // The port went away (the run is over).
                Err(_) => return,
            }
        }
    });

    let outcome = approach(&mut robot, &revolutions);
    let last = outcome.last.as_ref();
    let gaps = last.map_or(0, |r| r.index_gaps);
    let travel = robot.wheel_positions_mm().ok();
    println!(
        "example-firmware: {}; front {} mm after {} SetMotor steps; odometer {}; \
         revolutions {}, index gaps {gaps}, bad checksums {}",
        if outcome.reached {
            "reached the target"
        } else {
            "did not reach the target"
        },
        last.and_then(|r| r.front_mm)
            .map_or("?".into(), |f| f.to_string()),
        outcome.steps,
        travel.map_or("?".into(), |[l, r]| format!("{l}/{r} mm")),
        last.map_or(0, |r| r.revolutions),
        last.map_or(0, |r| r.bad_checksums),
    );
    let _ = robot.request("TestMode Off");
    if !outcome.reached {
        ExitCode::from(3)
    } else if gaps > 0 && !std::env::args().any(|a| a == "--allow-gaps") {
        ExitCode::from(4)
    } else {
        ExitCode::SUCCESS
    }
}

struct Outcome {
    reached: bool,
    steps: u64,
    last: Option<Revolution>,
}

/// Drives to the target; returns once stopped there (or when a port closes).
fn approach(robot: &mut RobotPort, revolutions: &mpsc::Receiver<Revolution>) -> Outcome {
    let mut outcome = Outcome {
        reached: false,
        steps: 0,
        last: None,
    };
    if let Err(err) = robot.request("TestMode On") {
        eprintln!("example-firmware: TestMode On: {err}");
        return outcome;
    }
    let mut settled = 0;
    while let Ok(revolution) = revolutions.recv() {
        let front = revolution.front_mm;
        outcome.last = Some(revolution);
        let Some(front) = front else {
            continue;
        };
        if outcome.reached {
            // Two more revolutions at rest confirm where it stopped.
            settled += 1;
            if settled == 2 {
                break;
            }
            continue;
        }
        let command = if front <= TARGET_MM {
            outcome.reached = true;
            "SetMotor LWheelDist 0 RWheelDist 0 Speed 0".to_string()
        } else {
            let remaining = i64::from(front - TARGET_MM);
            let speed = (GAIN * remaining).clamp(MIN_SPEED, MAX_SPEED);
            outcome.steps += 1;
            format!("SetMotor LWheelDist {remaining} RWheelDist {remaining} Speed {speed}")
        };
        eprintln!("example-firmware: front {front} mm: {command}");
        if let Err(err) = robot.request(&command) {
            eprintln!("example-firmware: {command}: {err}");
            outcome.reached = false;
            break;
        }
    }
    outcome
}
