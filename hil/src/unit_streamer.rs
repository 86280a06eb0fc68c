//! Streaming a unit other than the XV-11: its packets sent as the unit sends them, its host's
//! commands read and answered as they come (start, stop, info, health), and a slow, stalled or
//! absent reader never holding up the simulation.
//!
//! The XV-11's own [`crate::Streamer`] works in whole revolutions of fixed packets; a unit here
//! speaks through a [`Unit`], a pure state machine, and this streamer only moves its bytes and
//! keeps time.

use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::{Duration, Instant};

use hilsim_lidar_protocols::{Output, PacketSpan, Unit, UnitReading};

use crate::faults::{FaultCounts, WireFaults};
use crate::link::SerialLink;
use crate::streamer::{write_waiting, Pacing, StreamStats, FAST_STALL_GRACE, STALL_DETECT};

/// How long the streamer sleeps between looks at the host's commands while it waits: a
/// command is answered within about this (a real unit answers within a few milliseconds).
const HOST_POLL: Duration = Duration::from_millis(1);
/// The backlog a reader may leave before it counts as fallen behind, until a whole
/// revolution's bytes are known (a revolution of the units here is 1.5–2.5 KB).
const FIRST_BACKLOG_LIMIT: usize = 4096;

/// Streams one unit's packets over a link and answers its host.
pub struct UnitStreamer<L: SerialLink> {
    link: L,
    unit: Box<dyn Unit>,
    pacing: Pacing,
    /// The wall-clock instant of simulated t = 0 (real-time pacing, once started).
    origin: Option<Instant>,
    stats: StreamStats,
    faults: Option<WireFaults>,
    out: Output,
    wire: Vec<u8>,
    /// Bytes written since the last revolution's start, and a whole revolution's.
    revolution_bytes: usize,
    backlog_limit: usize,
    /// Whether a reader has taken data since the stream last found it stalled or absent.
    reader_reading: bool,
    /// The simulated time of the latest reading taken.
    now_s: f64,
    /// Packets queued for their time ([`UnitStreamer::queue`]), and how many of them went.
    queued: Output,
    queued_sent: usize,
}

impl<L: SerialLink> UnitStreamer<L> {
    /// A streamer of `unit` over `link`.
    pub fn new(link: L, unit: Box<dyn Unit>, pacing: Pacing) -> Self {
        Self {
            link,
            unit,
            pacing,
            origin: None,
            stats: StreamStats::default(),
            faults: None,
            out: Output::new(),
            wire: Vec::new(),
            revolution_bytes: 0,
            backlog_limit: FIRST_BACKLOG_LIMIT,
            reader_reading: false,
            now_s: 0.0,
            queued: Output::new(),
            queued_sent: 0,
        }
    }

    /// The stream with a scenario's wire faults applied to every packet and reply.
    #[must_use]
    pub fn with_faults(mut self, faults: Option<WireFaults>) -> Self {
        self.faults = faults;
        self
    }

    /// Tells the stream that a reader has connected: it is waited for from the start.
    pub fn reader_connected(&mut self) {
        self.reader_reading = true;
    }

    /// What the stream did so far.
    #[must_use]
    pub fn stats(&self) -> &StreamStats {
        &self.stats
    }

    /// What the wire's faults did so far (`None` without faults).
    #[must_use]
    pub fn fault_counts(&self) -> Option<FaultCounts> {
        self.faults.as_ref().map(WireFaults::counts)
    }

    /// The link.
    pub fn link(&mut self) -> &mut L {
        &mut self.link
    }

    /// Whether the unit is sending its readings.
    #[must_use]
    pub fn scanning(&self) -> bool {
        self.unit.scanning()
    }

    /// Hands the unit its next reading at the reading's instant, and sends what it completes.
    /// In real time it waits for that instant, answering the host meanwhile; otherwise a unit
    /// that is not scanning holds the simulation until its host starts it (or `stop` is
    /// raised), and one that is scanning runs as fast as its reader takes it.
    ///
    /// # Errors
    /// The link failed.
    pub fn take(&mut self, reading: &UnitReading, stop: &AtomicBool) -> io::Result<()> {
        self.pace(reading.t_s, stop)?;
        self.now_s = reading.t_s;
        let mut out = std::mem::take(&mut self.out);
        out.clear();
        self.unit.push(reading, &mut out);
        let sent = self.send(&out);
        self.out = out;
        sent
    }

    /// Starts the stream's real-time clock: simulated t = 0 at `origin`. For a caller that paces
    /// the simulation itself (firmware in the loop) and hands readings over with
    /// [`UnitStreamer::queue`].
    pub fn start_clock(&mut self, origin: Instant) {
        self.origin = Some(origin);
    }

    /// Hands the unit its next reading without waiting; the packets it completes wait in a
    /// queue for their time ([`UnitStreamer::send_due`]).
    pub fn queue(&mut self, reading: &UnitReading) {
        self.now_s = reading.t_s;
        if self.queued_sent == self.queued.packets.len() {
            self.queued.clear();
            self.queued_sent = 0;
        }
        self.unit.push(reading, &mut self.queued);
    }

    /// When the next queued packet is due, simulated seconds.
    #[must_use]
    pub fn next_due_s(&self) -> Option<f64> {
        self.queued.packets.get(self.queued_sent).map(|p| p.due_s)
    }

    /// Sends every queued packet due by simulated time `now_s`.
    ///
    /// # Errors
    /// The link failed.
    pub fn send_due(&mut self, now_s: f64) -> io::Result<()> {
        let queued = std::mem::take(&mut self.queued);
        let mut result = Ok(());
        while let Some(span) = queued.packets.get(self.queued_sent) {
            if span.due_s > now_s {
                break;
            }
            self.queued_sent += 1;
            result = self.send_packet(&queued.bytes[span.range.clone()], span);
            if result.is_err() {
                break;
            }
        }
        self.queued = queued;
        result
    }

    /// Reads and answers the host's commands until the link has no more.
    ///
    /// # Errors
    /// The link failed.
    pub fn answer_host(&mut self) -> io::Result<()> {
        let mut buf = [0_u8; 512];
        let now_s = self.sim_now_s();
        loop {
            let n = self.link.read_host(&mut buf)?;
            if n == 0 {
                return Ok(());
            }
            let mut out = std::mem::take(&mut self.out);
            out.clear();
            self.unit.host_wrote(&buf[..n], now_s, &mut out);
            let sent = self.send(&out);
            self.out = out;
            sent?;
        }
    }

    /// Lets a reader that is reading take what is still in the link before the stream ends:
    /// waits while the backlog shrinks, giving up after [`FAST_STALL_GRACE`] without progress.
    ///
    /// # Errors
    /// The link failed.
    pub fn drain(&mut self) -> io::Result<()> {
        if !self.reader_reading {
            return Ok(());
        }
        let mut backlog = self.link.backlog()?;
        let mut progress_at = Instant::now();
        while backlog > 0 && progress_at.elapsed() < FAST_STALL_GRACE {
            self.answer_host()?;
            thread::sleep(HOST_POLL);
            let now = self.link.backlog()?;
            if now < backlog {
                progress_at = Instant::now();
            }
            backlog = now;
        }
        Ok(())
    }

    /// The simulated time now: on the wall clock in real time, else the latest reading's.
    fn sim_now_s(&self) -> f64 {
        match (self.pacing, self.origin) {
            (Pacing::Realtime, Some(origin)) => origin.elapsed().as_secs_f64(),
            _ => self.now_s,
        }
    }

    fn pace(&mut self, t_s: f64, stop: &AtomicBool) -> io::Result<()> {
        match self.pacing {
            Pacing::Realtime => {
                let origin = *self.origin.get_or_insert_with(|| {
                    Instant::now()
                        .checked_sub(Duration::from_secs_f64(t_s.max(0.0)))
                        .unwrap_or_else(Instant::now)
                });
                let due = origin + Duration::from_secs_f64(t_s.max(0.0));
                loop {
                    self.answer_host()?;
                    let now = Instant::now();
                    // Within a poll of its instant is on time: sleeping is coarser than that.
                    if now + HOST_POLL >= due || stop.load(Ordering::Relaxed) {
                        return Ok(());
                    }
                    thread::sleep((due - now - HOST_POLL).min(HOST_POLL));
                }
            }
            Pacing::Fast | Pacing::Lossless => {
                self.answer_host()?;
                while !self.unit.scanning() && !stop.load(Ordering::Relaxed) {
                    thread::sleep(HOST_POLL);
                    self.answer_host()?;
                }
                Ok(())
            }
        }
    }

    /// Sends `out`'s packets through the faults.
    fn send(&mut self, out: &Output) -> io::Result<()> {
        for (packet, span) in out.iter() {
            self.send_packet(packet, span)?;
        }
        Ok(())
    }

    /// Sends one packet through the faults, making room at a revolution's start.
    fn send_packet(&mut self, packet: &[u8], span: &PacketSpan) -> io::Result<()> {
        if span.starts_revolution {
            if self.revolution_bytes > 0 {
                self.backlog_limit = self.revolution_bytes.max(256);
            }
            self.revolution_bytes = 0;
            self.link.allow_reconnect()?;
            self.make_room()?;
        }
        let mut wire = std::mem::take(&mut self.wire);
        wire.clear();
        match self.faults.as_mut() {
            Some(faults) => faults.apply_unit_packet(packet, span.sync_len, span.due_s, &mut wire),
            None => wire.extend_from_slice(packet),
        }
        let written = self.write_all(&wire);
        self.wire = wire;
        if !written? {
            if span.starts_revolution {
                self.stats.revolutions_dropped += 1;
            }
            return Ok(());
        }
        self.revolution_bytes += packet.len();
        if span.starts_revolution {
            self.stats.revolutions_sent += 1;
        }
        if let (Pacing::Realtime, Some(origin)) = (self.pacing, self.origin) {
            let due = origin + Duration::from_secs_f64(span.due_s.max(0.0));
            self.stats
                .record_lateness(Instant::now().saturating_duration_since(due));
        }
        Ok(())
    }

    /// Writes `bytes`, waiting for the link as the pacing allows ([`write_waiting`]).
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<bool> {
        write_waiting(
            &mut self.link,
            bytes,
            self.pacing,
            &mut self.reader_reading,
            &mut self.stats,
        )
    }

    /// Brings the backlog under one revolution at a revolution's start: waits for a reader
    /// that is making progress (fast pacing), and throws away what a stalled or absent one left
    /// (at once in real time: live data first).
    fn make_room(&mut self) -> io::Result<()> {
        let mut backlog = self.link.backlog()?;
        let mut progress_at = Instant::now();
        while backlog > self.backlog_limit {
            let patience = match self.pacing {
                Pacing::Realtime => Duration::ZERO,
                _ if self.reader_reading => FAST_STALL_GRACE,
                _ => STALL_DETECT,
            };
            if progress_at.elapsed() >= patience {
                self.link.discard_backlog()?;
                self.stats.bytes_discarded += backlog as u64;
                let revolutions = (backlog / self.backlog_limit.max(1)) as u64;
                self.stats.revolutions_sent =
                    self.stats.revolutions_sent.saturating_sub(revolutions);
                self.stats.revolutions_dropped += revolutions;
                self.reader_reading = false;
                return Ok(());
            }
            self.answer_host()?;
            thread::sleep(Duration::from_micros(200));
            let now = self.link.backlog()?;
            if now < backlog {
                progress_at = Instant::now();
                self.reader_reading = true;
            }
            backlog = now;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MemoryLink;
    use std::io::ErrorKind;

    /// A toy command-driven unit: `S` starts it, `T` stops it, `I` asks for its info; each
    /// reading is a 3-byte packet.
    #[derive(Default)]
    struct ToyUnit {
        scanning: bool,
    }

    impl Unit for ToyUnit {
        fn host_wrote(&mut self, bytes: &[u8], now_s: f64, out: &mut Output) {
            for &b in bytes {
                match b {
                    b'S' => self.scanning = true,
                    b'T' => self.scanning = false,
                    b'I' => out.packet(now_s, 0, false, |o| o.extend_from_slice(b"INFO")),
                    _ => {}
                }
            }
        }

        fn scanning(&self) -> bool {
            self.scanning
        }

        fn push(&mut self, reading: &UnitReading, out: &mut Output) {
            if self.scanning {
                out.packet(reading.t_s, 1, reading.starts_revolution, |o| {
                    o.extend_from_slice(&[0xAB, reading.index as u8, reading.distance_mm as u8]);
                });
            }
        }
    }

    fn reading(k: u32) -> UnitReading {
        UnitReading {
            t_s: f64::from(k) * 1e-3,
            rev: u64::from(k / 10),
            index: k % 10,
            angle_deg: f64::from(k % 10) * 36.0,
            distance_mm: 100 + k,
            intensity: 50,
            rev_hz: 100.0,
            starts_revolution: k % 10 == 0,
        }
    }

    #[test]
    fn a_command_driven_unit_answers_its_host_and_streams_only_between_start_and_stop() {
        let stop = AtomicBool::new(false);
        let link = MemoryLink::with_capacity(1 << 16);
        let mut s = UnitStreamer::new(link, Box::new(ToyUnit::default()), Pacing::Fast);
        s.link().client_writes(b"I");
        s.answer_host().unwrap();
        assert_eq!(s.link().take(), b"INFO");
        // Started: every reading goes out, and a question is answered between readings.
        s.link().client_writes(b"S");
        for k in 0..20 {
            if k == 5 {
                s.link().client_writes(b"I");
            }
            s.take(&reading(k), &stop).unwrap();
        }
        let bytes = s.link().take();
        assert_eq!(bytes.len(), 20 * 3 + 4);
        assert_eq!(&bytes[..3], &[0xAB, 0, 100]);
        assert_eq!(&bytes[15..19], b"INFO");
        assert_eq!(s.stats().revolutions_sent, 2);
        // Stopped: nothing more, though the head turns on (a stop flag lets the fast stream
        // through: it would otherwise wait for the next start).
        s.link().client_writes(b"T");
        stop.store(true, Ordering::Relaxed);
        for k in 20..30 {
            s.take(&reading(k), &stop).unwrap();
        }
        assert!(s.link().take().is_empty());
    }

    #[test]
    fn faults_reach_the_unit_packets_and_silence_swallows_replies() {
        let stop = AtomicBool::new(false);
        let faults = hilsim_sim::scenario::LinkFaults {
            silent: Some((0.0, 1.0)),
            ..hilsim_sim::scenario::LinkFaults::default()
        };
        let link = MemoryLink::with_capacity(1 << 16);
        let mut s = UnitStreamer::new(link, Box::new(ToyUnit::default()), Pacing::Fast)
            .with_faults(WireFaults::new(&faults, 1));
        s.link().client_writes(b"IS");
        s.take(&reading(0), &stop).unwrap();
        // Inside the silent second: neither the reply nor the packet comes.
        assert!(s.link().take().is_empty());
        assert_eq!(s.fault_counts().unwrap().silenced_packets, 2);
    }

    /// A link whose reader takes `per_wait` bytes each time the writer finds it full: a reader
    /// slower than the stream, but reading.
    struct SlowReaderLink {
        queue: Vec<u8>,
        capacity: usize,
        per_wait: usize,
        received: Vec<u8>,
    }

    impl std::io::Write for SlowReaderLink {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            let room = self.capacity - self.queue.len();
            if room == 0 {
                let n = self.per_wait.min(self.queue.len());
                self.received.extend(self.queue.drain(..n));
                return Err(ErrorKind::WouldBlock.into());
            }
            let n = room.min(buf.len());
            self.queue.extend_from_slice(&buf[..n]);
            Ok(n)
        }

        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl SerialLink for SlowReaderLink {
        fn backlog(&mut self) -> io::Result<usize> {
            // Time passes while the stream looks: the reader takes its share.
            let n = self.per_wait.min(self.queue.len());
            self.received.extend(self.queue.drain(..n));
            Ok(self.queue.len())
        }

        fn discard_backlog(&mut self) -> io::Result<()> {
            self.queue.clear();
            Ok(())
        }
    }

    #[test]
    fn a_fast_streams_reader_that_reads_slowly_loses_nothing() {
        let stop = AtomicBool::new(false);
        // A link that holds less than a packet's worth beyond a revolution: every revolution
        // meets a full link, as a pty does behind a descheduled reader.
        let link = SlowReaderLink {
            queue: Vec::new(),
            capacity: 40,
            per_wait: 7,
            received: Vec::new(),
        };
        let mut s = UnitStreamer::new(link, Box::new(ToyUnit { scanning: true }), Pacing::Fast);
        s.reader_connected();
        for k in 0..2_000 {
            s.take(&reading(k), &stop).unwrap();
        }
        let link = s.link();
        let mut received = std::mem::take(&mut link.received);
        received.append(&mut link.queue);
        let expected: Vec<u8> = (0..2_000)
            .flat_map(|k| [0xAB, (k % 10) as u8, (100 + k) as u8])
            .collect();
        assert_eq!(received.len(), expected.len());
        assert!(received == expected, "the stream lost or reordered bytes");
        assert_eq!(s.stats().revolutions_dropped, 0);
        assert_eq!(s.stats().bytes_discarded, 0);
    }

    #[test]
    fn an_absent_reader_costs_data_not_time() {
        let stop = AtomicBool::new(false);
        let link = MemoryLink::with_capacity(1 << 20);
        let mut s = UnitStreamer::new(link, Box::new(ToyUnit { scanning: true }), Pacing::Fast);
        for k in 0..10_000 {
            s.take(&reading(k), &stop).unwrap();
        }
        // Nobody reads: the backlog is thrown away at revolution starts, never above about
        // two revolutions' bytes (a revolution here is 30 bytes; the floor is 256).
        assert!(
            s.link().backlog().unwrap() <= 2 * 256,
            "{}",
            s.link().backlog().unwrap()
        );
        assert!(s.stats().bytes_discarded > 0);
    }
}
