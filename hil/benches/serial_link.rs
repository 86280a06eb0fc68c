//! Serial link benchmarks, printed as figures and ratios:
//!
//! - realtime pacing over `HILSIM_BENCH_SECONDS` (default 60) of a 300 rpm stream read by a
//!   client thread from the pty: revolutions per second against rpm/60, and the packet lateness
//!   (when each packet left, after its last reading's instant) median and 99th percentile;
//! - `--fast` throughput through the pty with whole-revolution writes, against one write per
//!   packet measured in the same run.
//!
//! `cargo bench -p hilsim-hil --bench serial_link` (set `HILSIM_BENCH_SECONDS=10` for a quick
//! look).

use std::io::{ErrorKind, Read};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::{Duration, Instant};

use hilsim_hil::{Pacing, PtyLink, Streamer};
use hilsim_lidar_emulator::neato_packet::{Decoder, Reading};
use hilsim_lidar_emulator::wire::RevolutionFrame;

const RPM: f64 = 300.0;

fn frame(rev: u64) -> RevolutionFrame {
    RevolutionFrame {
        rev,
        rpm: RPM,
        start_s: rev as f64 * 60.0 / RPM,
        readings: [Reading::distance(1234, 300); 360],
    }
}

/// A client that reads everything and counts packets and the time of the first and last; it
/// stops when raised, or once it has `until_bytes`.
fn client(
    path: String,
    stop: Arc<AtomicBool>,
    until_bytes: u64,
) -> thread::JoinHandle<(u64, u64, Duration)> {
    thread::spawn(move || {
        let mut port = serialport::new(&path, 115_200)
            .timeout(Duration::from_millis(20))
            .open()
            .expect("client opens the pty");
        let mut decoder = Decoder::new();
        let mut buf = vec![0u8; 1 << 16];
        let (mut bytes, mut packets) = (0u64, 0u64);
        let mut first: Option<Instant> = None;
        let mut last = Instant::now();
        while !stop.load(Ordering::Relaxed) && bytes < until_bytes {
            match port.read(&mut buf) {
                Ok(n) => {
                    let now = Instant::now();
                    first.get_or_insert(now);
                    last = now;
                    bytes += n as u64;
                    packets += decoder.feed(&buf[..n]).count() as u64;
                }
                Err(e) if e.kind() == ErrorKind::TimedOut => {}
                Err(e) => panic!("client: {e}"),
            }
        }
        (bytes, packets, last - first.unwrap_or(last))
    })
}

fn realtime(seconds: u64) {
    let link = PtyLink::open().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let reader = client(link.client_path().to_string(), Arc::clone(&stop), u64::MAX);
    thread::sleep(Duration::from_millis(200));
    let mut streamer = Streamer::new(link, Pacing::Realtime);
    let revolutions = seconds * RPM as u64 / 60;
    for rev in 0..revolutions {
        streamer.send(&frame(rev)).unwrap();
    }
    thread::sleep(Duration::from_millis(100));
    stop.store(true, Ordering::Relaxed);
    let (_, packets, span) = reader.join().unwrap();
    let stats = streamer.stats();
    let received_revs = packets as f64 / 90.0;
    // First to last packet spans (revs − 1/90) revolutions' worth of time.
    let rate = (received_revs - 1.0 / 90.0) / span.as_secs_f64();
    let ms = |d: Option<Duration>| d.map_or(f64::NAN, |d| d.as_secs_f64() * 1e3);
    println!(
        "realtime {seconds} s: {received_revs:.0} of {revolutions} revolutions received, \
         {rate:.4} rev/s vs {:.4} configured ({:+.3} %), dropped {}",
        RPM / 60.0,
        100.0 * (rate / (RPM / 60.0) - 1.0),
        stats.revolutions_dropped
    );
    println!(
        "realtime packet lateness: median {:.2} ms, p99 {:.2} ms, max bucket {:.2} ms",
        ms(stats.lateness_quantile(0.5)),
        ms(stats.lateness_quantile(0.99)),
        ms(stats.lateness_quantile(1.0)),
    );
}

/// Bytes per second through the pty to a reading client, writing whole revolutions (what
/// `--fast` does) or one packet per write.
fn fast(per_packet: bool, revolutions: u64) -> f64 {
    let mut link = PtyLink::open().unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let mut bytes = Vec::new();
    frame(0).encode(&mut bytes);
    let total = revolutions * bytes.len() as u64;
    let reader = client(link.client_path().to_string(), Arc::clone(&stop), total);
    thread::sleep(Duration::from_millis(200));
    let start = Instant::now();
    let mut written = 0u64;
    for _ in 0..revolutions {
        let chunks: Vec<&[u8]> = if per_packet {
            bytes.chunks(22).collect()
        } else {
            vec![&bytes[..]]
        };
        for mut chunk in chunks {
            while !chunk.is_empty() {
                match std::io::Write::write(&mut link, chunk) {
                    Ok(n) => {
                        chunk = &chunk[n..];
                        written += n as u64;
                    }
                    Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {
                        thread::yield_now();
                    }
                    Err(e) => panic!("{e}"),
                }
            }
        }
    }
    // Until the reader has it all.
    let (received, _, _) = reader.join().unwrap();
    let elapsed = start.elapsed();
    assert_eq!(received, written);
    written as f64 / elapsed.as_secs_f64()
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        println!("serial_link: benchmark");
        return;
    }
    let whole = fast(false, 20_000);
    let per_packet = fast(true, 2_000);
    println!(
        "fast: whole-revolution writes {:.1} MB/s, one write per packet {:.1} MB/s, ratio {:.1}",
        whole / 1e6,
        per_packet / 1e6,
        whole / per_packet
    );
    let seconds = std::env::var("HILSIM_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60);
    realtime(seconds);
}
