//! Robot command port latency, printed as figures and a ratio: the round trip of a
//! `GetMotors` request through the pty to its complete reply (up to the Ctrl-Z), while the
//! simulation runs in real time and the lidar streams to a reader on the other port:
//!
//! - back to back, `HILSIM_BENCH_REQUESTS` requests (default 2000);
//! - paced at 100 Hz, as a firmware's control loop would poll (half as many);
//! - the baseline, measured in the same run and interleaved request by request with the above
//!   (so that both see the same machine load): a bare pty pair whose other end, a thread
//!   blocked in `read`, answers each line at once with a reply of the same length.
//!
//! Median, 99th percentile and maximum of each; the ratios of hilsim's to the bare pty's.
//!
//! `cargo bench -p hilsim-hil --bench command_latency`

use std::io::{ErrorKind, Read, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::{Duration, Instant};

use hilsim_hil::hil_run::{run, FloodLimits, HilConfig, HilPorts, HilWorld};
use hilsim_sim::Scenario;
use serialport::SerialPort;

const SCENARIO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../scenarios/hil-approach.toml"
);

/// Sends `line` and reads to the reply's Ctrl-Z; returns the round trip and the reply length.
fn round_trip(port: &mut dyn SerialPort, line: &[u8], buf: &mut [u8]) -> (Duration, usize) {
    let start = Instant::now();
    port.write_all(line).expect("request written");
    let mut len = 0;
    loop {
        match port.read(buf) {
            Ok(n) => {
                len += n;
                if buf[n - 1] == 0x1A {
                    return (start.elapsed(), len);
                }
            }
            Err(e) if e.kind() == ErrorKind::TimedOut => panic!("no reply within 1 s"),
            Err(e) => panic!("{e}"),
        }
    }
}

fn quantiles(mut samples: Vec<Duration>) -> (Duration, Duration, Duration) {
    samples.sort_unstable();
    let at =
        |q: f64| samples[((samples.len() as f64 * q).ceil() as usize).clamp(1, samples.len()) - 1];
    (at(0.5), at(0.99), *samples.last().unwrap())
}

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

fn print(label: &str, samples: &[Duration]) -> (Duration, Duration) {
    let (p50, p99, max) = quantiles(samples.to_vec());
    println!(
        "  {label:<33} median {:7.1} µs   p99 {:7.1} µs   max {:8.1} µs   ({} requests)",
        us(p50),
        us(p99),
        us(max),
        samples.len()
    );
    (p50, p99)
}

/// The baseline: a bare pty pair, the far end answering each line with `reply_len` bytes.
/// Returns the client side; the answering thread ends when the client closes it.
fn bare_pty(reply_len: usize) -> Box<dyn SerialPort> {
    let (mut master, slave) = serialport::TTYPort::pair().expect("a pty pair");
    let path = slave.name().expect("a slave path");
    thread::spawn(move || {
        let _slave = slave;
        let mut reply = vec![b'x'; reply_len];
        *reply.last_mut().unwrap() = 0x1A;
        master.set_timeout(Duration::from_secs(3600)).unwrap();
        let mut buf = [0u8; 256];
        while let Ok(n) = master.read(&mut buf) {
            if buf[..n].contains(&b'\n') {
                master.write_all(&reply).unwrap();
            }
        }
    });
    serialport::new(&path, 115_200)
        .timeout(Duration::from_secs(1))
        .open()
        .expect("client opens the pty")
}

fn main() {
    let requests: usize = std::env::var("HILSIM_BENCH_REQUESTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2000);
    let scenario = Scenario::load_with_duration(SCENARIO.as_ref(), Some(600.0)).unwrap();
    let world = HilWorld::new(&scenario, 1).unwrap();
    let ports = HilPorts::open().unwrap();
    let (lidar_path, robot_path) = (
        ports.lidar_path().to_string(),
        ports.robot_path().to_string(),
    );
    let stop = Arc::new(AtomicBool::new(false));
    let config = HilConfig {
        watchdog: Duration::from_secs(600),
        flood: FloodLimits::NONE,
        ..HilConfig::new(Duration::from_secs(600))
    };
    let harness = {
        let stop = Arc::clone(&stop);
        thread::spawn(move || run(world, ports, None, &config, &stop).expect("the run"))
    };
    let lidar = thread::spawn(move || {
        let mut port = serialport::new(&lidar_path, 115_200)
            .timeout(Duration::from_millis(200))
            .open()
            .expect("lidar port");
        let mut buf = [0u8; 4096];
        while !matches!(port.read(&mut buf), Err(e) if e.kind() != ErrorKind::TimedOut) {}
    });
    let mut robot = serialport::new(&robot_path, 115_200)
        .timeout(Duration::from_secs(1))
        .open()
        .expect("robot port");
    let robot = robot.as_mut();
    let mut buf = vec![0u8; 1 << 16];
    round_trip(robot, b"TestMode On\n", &mut buf);
    let mut reply_len = 0;
    for _ in 0..100 {
        reply_len = round_trip(robot, b"GetMotors\n", &mut buf).1;
    }
    let mut bare = bare_pty(reply_len);
    let bare = bare.as_mut();
    let (mut back_to_back, mut baseline) = (Vec::new(), Vec::new());
    for _ in 0..requests {
        back_to_back.push(round_trip(robot, b"GetMotors\n", &mut buf).0);
        baseline.push(round_trip(bare, b"GetMotors\n", &mut buf).0);
    }
    let (mut paced, mut baseline_paced) = (Vec::new(), Vec::new());
    let start = Instant::now();
    for k in 0..requests / 2 {
        let due = start + Duration::from_millis(10) * k as u32;
        thread::sleep(due.saturating_duration_since(Instant::now()));
        paced.push(round_trip(robot, b"GetMotors\n", &mut buf).0);
        thread::sleep((due + Duration::from_millis(5)).saturating_duration_since(Instant::now()));
        baseline_paced.push(round_trip(bare, b"GetMotors\n", &mut buf).0);
    }
    stop.store(true, Ordering::Relaxed);
    let report = harness.join().unwrap();
    lidar.join().unwrap();

    println!(
        "GetMotors round trip through the robot command pty ({reply_len}-byte reply), {:.1} s of \
         real-time simulation with the lidar streaming:",
        report.simulated_s
    );
    let ratio = |hil: (Duration, Duration), bare: (Duration, Duration)| {
        println!(
            "  ratio hilsim / bare pty: median {:.2}, p99 {:.2}",
            hil.0.as_secs_f64() / bare.0.as_secs_f64(),
            hil.1.as_secs_f64() / bare.1.as_secs_f64()
        );
    };
    let hil = print("hilsim, back to back", &back_to_back);
    let bare = print("bare pty echo, interleaved", &baseline);
    ratio(hil, bare);
    let hil = print("hilsim, paced at 100 Hz", &paced);
    let bare = print("bare pty echo, paced, interleaved", &baseline_paced);
    ratio(hil, bare);
    let s = &report.stream;
    println!(
        "  meanwhile: {} requests answered, {} lidar revolutions sent, {} dropped; packet \
         lateness median {:.1} ms, p99 {:.1} ms; physics steps at most {:.1} ms late",
        report.commands.requests,
        s.revolutions_sent,
        s.revolutions_dropped,
        s.lateness_quantile(0.5).unwrap_or_default().as_secs_f64() * 1e3,
        s.lateness_quantile(0.99).unwrap_or_default().as_secs_f64() * 1e3,
        report.max_step_lateness.as_secs_f64() * 1e3
    );
}
