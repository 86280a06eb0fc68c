//! Writing whole revolutions to a serial link, paced as a real unit would send them, without
//! ever letting a slow, stalled or absent reader hold up the simulation.

use std::io::{self, ErrorKind};
use std::thread;
use std::time::{Duration, Instant};

use hilsim_lidar_emulator::neato_packet::{
    Packet, PACKETS_PER_REVOLUTION, PACKET_LEN, READINGS_PER_PACKET,
};
use hilsim_lidar_emulator::wire::RevolutionFrame;

use crate::faults::{FaultCounts, WireFaults};
use crate::link::SerialLink;

/// How the stream is paced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pacing {
    /// As a real XV-11: each packet leaves when its last reading has been taken, on the
    /// simulation clock mapped to the wall clock.
    Realtime,
    /// As fast as the reader takes it: a reader that reads loses nothing, however slowly it
    /// reads; one that takes nothing for [`FAST_STALL_GRACE`] counts as stalled and loses whole
    /// revolutions (counted) until it reads again. Before any reader has read, nothing waits.
    Fast,
    /// As fast as the reader takes it, never dropping: for hilsim's own reader
    /// (`hilsim run --via serial`). Fails after [`LOSSLESS_TIMEOUT`] without progress.
    Lossless,
}

/// Bytes a reader may leave unread before it counts as fallen behind: one revolution.
pub const BACKLOG_LIMIT: usize = PACKETS_PER_REVOLUTION * PACKET_LEN;
/// How long a reader of a fast stream may take nothing before it counts as stalled: a second,
/// far longer than a live reader's pause between reads (a Python driver decoding a revolution
/// takes milliseconds; a process descheduled on a busy machine, tens), and paid once per stall:
/// a stalled reader is not waited for again until it reads.
pub const FAST_STALL_GRACE: Duration = Duration::from_secs(1);
/// How long a reader may take nothing before it counts as stalled.
pub const STALL_DETECT: Duration = Duration::from_millis(5);
/// How long the reader's queue must stay empty before a draining stream takes it as read: a
/// pty hands written bytes over in the background, later on a busy machine.
const DRAIN_QUIET: Duration = Duration::from_millis(100);
/// How long a lossless stream waits for its reader before giving up.
pub const LOSSLESS_TIMEOUT: Duration = Duration::from_secs(10);
/// Packet lateness histogram resolution.
const LATENESS_BUCKET: Duration = Duration::from_micros(100);
/// Lateness histogram range (later packets land in the last bucket).
const LATENESS_BUCKETS: usize = 1000;

/// What the stream did.
#[derive(Debug, Clone, PartialEq)]
pub struct StreamStats {
    /// Revolutions written whole (less those later thrown away unread).
    pub revolutions_sent: u64,
    /// Revolutions thrown away because the reader was absent, stalled or too slow.
    pub revolutions_dropped: u64,
    /// Bytes written.
    pub bytes_written: u64,
    /// Bytes written but thrown away unread (a reader that fell behind, or none): what a reader
    /// took is `bytes_written - bytes_discarded - backlog`.
    pub bytes_discarded: u64,
    lateness: Vec<u64>,
}

impl Default for StreamStats {
    fn default() -> Self {
        Self {
            revolutions_sent: 0,
            revolutions_dropped: 0,
            bytes_written: 0,
            bytes_discarded: 0,
            lateness: vec![0; LATENESS_BUCKETS],
        }
    }
}

impl StreamStats {
    /// One line for a status line: what was sent by `t_s` seconds of simulated time.
    #[must_use]
    pub fn describe(&self, t_s: f64) -> String {
        format!(
            "{t_s:.1} s simulated, {} revolutions sent, {} dropped",
            self.revolutions_sent, self.revolutions_dropped
        )
    }

    /// Packets whose lateness was measured (realtime pacing only).
    #[must_use]
    pub fn paced_packets(&self) -> u64 {
        self.lateness.iter().sum()
    }

    /// `"packet lateness median 0.1 ms, p99 0.4 ms"`, when any packet was paced.
    #[must_use]
    pub fn lateness_summary(&self) -> Option<String> {
        let ms = |q| self.lateness_quantile(q).map(|d| d.as_secs_f64() * 1e3);
        Some(format!(
            "packet lateness median {:.1} ms, p99 {:.1} ms",
            ms(0.5)?,
            ms(0.99)?
        ))
    }

    /// Counts one packet written `late` after its due time.
    pub(crate) fn record_lateness(&mut self, late: Duration) {
        let bucket = (late.as_micros() / LATENESS_BUCKET.as_micros()) as usize;
        self.lateness[bucket.min(LATENESS_BUCKETS - 1)] += 1;
    }

    /// The `q`-quantile (0..=1) of packet lateness: how long after its due time each packet was
    /// written, to 0.1 ms. `None` without paced packets.
    #[must_use]
    pub fn lateness_quantile(&self, q: f64) -> Option<Duration> {
        let total = self.paced_packets();
        if total == 0 {
            return None;
        }
        let rank = ((q.clamp(0.0, 1.0) * total as f64).ceil() as u64).max(1);
        let mut seen = 0;
        for (bucket, count) in self.lateness.iter().enumerate() {
            seen += count;
            if seen >= rank {
                return Some(LATENESS_BUCKET * (bucket as u32 + 1));
            }
        }
        Some(LATENESS_BUCKET * LATENESS_BUCKETS as u32)
    }
}

/// Streams revolutions over a link.
pub struct Streamer<L: SerialLink> {
    link: L,
    pacing: Pacing,
    origin: Option<Instant>,
    stats: StreamStats,
    bytes: Vec<u8>,
    /// For [`Streamer::send_packet`]: inside a revolution, whether all its packets so far went
    /// out (`None` before the first revolution start and after each revolution's end).
    packets_whole: Option<bool>,
    /// Whether a reader has taken data since the stream last found it stalled or absent: only
    /// then does a fast stream wait for it.
    reader_reading: bool,
    /// The scenario's wire faults, when it has any.
    faults: Option<WireFaults>,
    /// Where each of the revolution's packets lies in `bytes` (empty when the wire lost it).
    packet_spans: Vec<(usize, usize)>,
    /// A packet as the faults leave it (`send_packet`).
    packet_bytes: Vec<u8>,
}

impl<L: SerialLink> Streamer<L> {
    /// A streamer over `link`.
    pub fn new(link: L, pacing: Pacing) -> Self {
        Self {
            link,
            pacing,
            origin: None,
            stats: StreamStats::default(),
            bytes: Vec::with_capacity(BACKLOG_LIMIT),
            packets_whole: None,
            reader_reading: false,
            faults: None,
            packet_spans: Vec::with_capacity(PACKETS_PER_REVOLUTION),
            packet_bytes: Vec::with_capacity(PACKET_LEN),
        }
    }

    /// The stream with a scenario's wire faults applied to every packet it writes.
    #[must_use]
    pub fn with_faults(mut self, faults: Option<WireFaults>) -> Self {
        self.faults = faults;
        self
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

    /// What the stream did so far.
    #[must_use]
    pub fn stats(&self) -> &StreamStats {
        &self.stats
    }

    /// Sends one revolution (or drops it, counted, if the reader cannot take it).
    ///
    /// # Errors
    /// The link failed, or a lossless reader made no progress for [`LOSSLESS_TIMEOUT`].
    pub fn send(&mut self, frame: &RevolutionFrame) -> io::Result<()> {
        self.bytes.clear();
        frame.encode(&mut self.bytes);
        self.apply_faults(frame);
        self.link.allow_reconnect()?;
        if !self.make_room()? {
            self.stats.revolutions_dropped += 1;
            return Ok(());
        }
        let sent = match self.pacing {
            Pacing::Realtime => self.send_paced(frame)?,
            Pacing::Fast | Pacing::Lossless => {
                let bytes = std::mem::take(&mut self.bytes);
                let sent = self.write_all(&bytes)?;
                self.bytes = bytes;
                sent
            }
        };
        if sent {
            self.stats.revolutions_sent += 1;
        } else {
            self.stats.revolutions_dropped += 1;
        }
        Ok(())
    }

    /// Lays the revolution's packets out in `bytes` as the wire delivers them, noting each one's
    /// span (the spans of an unfaulted stream are the 22-byte packets).
    fn apply_faults(&mut self, frame: &RevolutionFrame) {
        self.packet_spans.clear();
        let Some(faults) = self.faults.as_mut() else {
            self.packet_spans.extend(
                (0..self.bytes.len() / PACKET_LEN).map(|k| (k * PACKET_LEN, (k + 1) * PACKET_LEN)),
            );
            return;
        };
        let clean = std::mem::take(&mut self.bytes);
        for (k, packet) in clean.chunks_exact(PACKET_LEN).enumerate() {
            let start = self.bytes.len();
            let done_s = frame.reading_time_s(((k + 1) * READINGS_PER_PACKET) as u16);
            faults.apply(packet, done_s, &mut self.bytes);
            self.packet_spans.push((start, self.bytes.len()));
        }
    }

    /// Counts `backlog` bytes written but never read as lost: their whole revolutions move from
    /// sent to dropped, so that every revolution is counted once.
    fn lost(&mut self, backlog: usize) {
        let revolutions = (backlog / BACKLOG_LIMIT) as u64;
        self.stats.bytes_discarded += backlog as u64;
        self.stats.revolutions_sent = self.stats.revolutions_sent.saturating_sub(revolutions);
        self.stats.revolutions_dropped += revolutions;
    }

    /// Tells the stream that a reader has connected (`--wait-for-client`): it is waited for as
    /// a reading one from the start, before its first read.
    pub fn reader_connected(&mut self) {
        self.reader_reading = true;
    }

    /// Lets a reader that is reading take what is still in the link before the stream ends (the
    /// link closing would throw it away): waits while the backlog shrinks, giving up after
    /// [`FAST_STALL_GRACE`] without progress. Nothing waits when no reader has been reading.
    ///
    /// # Errors
    /// The link failed.
    pub fn drain(&mut self) -> io::Result<()> {
        if !self.reader_reading {
            return Ok(());
        }
        let mut backlog = self.link.backlog()?;
        let mut progress_at = Instant::now();
        let mut empty_since: Option<Instant> = None;
        loop {
            // A pty moves written bytes into the reader's queue in the background: an empty
            // queue is only the end once it has stayed empty for a while.
            if backlog == 0 {
                let since = *empty_since.get_or_insert_with(Instant::now);
                if since.elapsed() >= DRAIN_QUIET {
                    break;
                }
            } else {
                empty_since = None;
                if progress_at.elapsed() >= FAST_STALL_GRACE {
                    // What the closing link will throw away.
                    self.lost(backlog);
                    self.reader_reading = false;
                    break;
                }
            }
            thread::sleep(Duration::from_millis(1));
            let now_backlog = self.link.backlog()?;
            if now_backlog < backlog {
                progress_at = Instant::now();
            }
            backlog = now_backlog;
        }
        Ok(())
    }

    /// Sends one packet of a realtime stream now, never waiting for its time: for a caller
    /// that paces the simulation itself and must not be held up (firmware in the loop), and
    /// hands over each packet once its last reading's instant has passed. `due` is that
    /// instant on the wall clock, for the lateness statistics, and `due_s` in simulated time,
    /// for the link's faults.
    ///
    /// Revolutions are still the unit: a packet with index 0 starts one and gets what
    /// [`Streamer::send`] gives a whole revolution (the reader may reconnect; a reader that fell
    /// behind has its backlog discarded at once, as in [`Pacing::Realtime`]). Packets before the
    /// first revolution start are not sent, and when the link cannot take a packet the rest of
    /// its revolution is dropped (counted once). A revolution counts as sent when its last
    /// packet (index 89) goes out.
    ///
    /// # Errors
    /// The link failed.
    pub fn send_packet(&mut self, packet: &Packet, due: Instant, due_s: f64) -> io::Result<()> {
        let index = usize::from(packet.index) % PACKETS_PER_REVOLUTION;
        if index == 0 {
            if self.packets_whole.take() == Some(true) {
                // The previous revolution never got its last packet.
                self.stats.revolutions_dropped += 1;
            }
            self.link.allow_reconnect()?;
            self.make_room()?;
            self.packets_whole = Some(true);
        }
        if self.packets_whole != Some(true) {
            return Ok(());
        }
        let mut bytes = std::mem::take(&mut self.packet_bytes);
        bytes.clear();
        match self.faults.as_mut() {
            Some(faults) => faults.apply(&packet.encode(), due_s, &mut bytes),
            None => bytes.extend_from_slice(&packet.encode()),
        }
        let written = self.write_all(&bytes)?;
        self.packet_bytes = bytes;
        if !written {
            self.packets_whole = Some(false);
            self.stats.revolutions_dropped += 1;
            return Ok(());
        }
        self.stats
            .record_lateness(Instant::now().saturating_duration_since(due));
        if index == PACKETS_PER_REVOLUTION - 1 {
            self.packets_whole = None;
            self.stats.revolutions_sent += 1;
        }
        Ok(())
    }

    /// Brings the backlog under [`BACKLOG_LIMIT`]: waits for a reader that is making progress
    /// (as the pacing allows), and discards what a stalled or absent one left. Returns `false`
    /// when this revolution must be dropped.
    fn make_room(&mut self) -> io::Result<bool> {
        let mut backlog = self.link.backlog()?;
        let mut progress_at = Instant::now();
        while backlog > BACKLOG_LIMIT {
            let now = Instant::now();
            // How long a reader may take nothing before its backlog is thrown away: none in
            // real time (live data first), the grace for a fast stream's reader that has been
            // reading, [`STALL_DETECT`] for one that never has (absent: do not hold the
            // simulation up), the timeout for hilsim's own lossless reader.
            let patience = match self.pacing {
                Pacing::Realtime => Duration::ZERO,
                Pacing::Fast if self.reader_reading => FAST_STALL_GRACE,
                Pacing::Fast => STALL_DETECT,
                Pacing::Lossless => LOSSLESS_TIMEOUT,
            };
            if now - progress_at >= patience {
                if self.pacing == Pacing::Lossless {
                    return Err(io::Error::new(
                        ErrorKind::TimedOut,
                        "the reader took nothing for 10 s",
                    ));
                }
                // The stale data would reach a late reader first: throw it away, counting the
                // whole revolutions it held.
                self.link.discard_backlog()?;
                self.lost(backlog);
                self.reader_reading = false;
                return Ok(true);
            }
            thread::sleep(Duration::from_millis(1));
            let now_backlog = self.link.backlog()?;
            if now_backlog < backlog {
                progress_at = Instant::now();
                self.reader_reading = true;
            }
            backlog = now_backlog;
        }
        Ok(true)
    }

    /// Writes all of `bytes`, waiting for the link as the pacing allows ([`write_waiting`]).
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<bool> {
        write_waiting(
            &mut self.link,
            bytes,
            self.pacing,
            &mut self.reader_reading,
            &mut self.stats,
        )
    }

    /// Writes the revolution packet by packet, each when its last reading has been taken.
    fn send_paced(&mut self, frame: &RevolutionFrame) -> io::Result<bool> {
        let origin = *self.origin.get_or_insert_with(|| {
            Instant::now() - Duration::from_secs_f64(frame.start_s.max(0.0))
        });
        let bytes = std::mem::take(&mut self.bytes);
        let spans = std::mem::take(&mut self.packet_spans);
        let mut all_sent = true;
        for (k, &(start, end)) in spans.iter().enumerate() {
            // The packet is complete once its fourth reading's instant has passed.
            let last_angle = ((k + 1) * READINGS_PER_PACKET) as u16;
            let due = origin + Duration::from_secs_f64(frame.reading_time_s(last_angle).max(0.0));
            sleep_until(due);
            if !self.write_all(&bytes[start..end])? {
                all_sent = false;
                break;
            }
            self.stats
                .record_lateness(Instant::now().saturating_duration_since(due));
        }
        self.packet_spans = spans;
        self.bytes = bytes;
        Ok(all_sent)
    }
}

/// Writes all of `bytes` to a link that never blocks, waiting while it is full for as long as
/// `pacing` lets a reader take nothing: 2 ms in real time (live data first), the grace for a
/// fast stream's reader that has been reading ([`FAST_STALL_GRACE`]), [`STALL_DETECT`] for one
/// that never has, [`LOSSLESS_TIMEOUT`] for hilsim's own reader (then an error). Every byte the
/// link takes restarts the wait. Returns `false` when the reader stalled: what it left (a
/// partial packet with it) is then thrown away, counted in `stats`, and the reader is no longer
/// waited for until it reads again.
///
/// # Errors
/// The link failed, or a lossless stream's reader took nothing for [`LOSSLESS_TIMEOUT`].
pub(crate) fn write_waiting<L: SerialLink + ?Sized>(
    link: &mut L,
    bytes: &[u8],
    pacing: Pacing,
    reader_reading: &mut bool,
    stats: &mut StreamStats,
) -> io::Result<bool> {
    let patience = match pacing {
        Pacing::Realtime => Duration::from_millis(2),
        Pacing::Fast if *reader_reading => FAST_STALL_GRACE,
        Pacing::Fast => STALL_DETECT,
        Pacing::Lossless => LOSSLESS_TIMEOUT,
    };
    let mut taken = 0;
    let mut deadline = Instant::now() + patience;
    while taken < bytes.len() {
        match link.write(&bytes[taken..]) {
            Ok(0) => {}
            Ok(n) => {
                taken += n;
                stats.bytes_written += n as u64;
                deadline = Instant::now() + patience;
                continue;
            }
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        }
        if Instant::now() >= deadline {
            if pacing == Pacing::Lossless {
                return Err(io::Error::new(
                    ErrorKind::TimedOut,
                    "the reader took nothing for 10 s",
                ));
            }
            stats.bytes_discarded += link.backlog()? as u64;
            link.discard_backlog()?;
            *reader_reading = false;
            return Ok(false);
        }
        thread::sleep(Duration::from_micros(200));
    }
    Ok(true)
}

/// The OS may wake a sleeper late by its timer slack (~50 µs) or more; sleep to just before
/// `due`, then spin until it. A busy spin, not `yield_now`: yielding to a busy machine's other
/// tasks costs a whole scheduler slice (milliseconds), far more than the 300 µs of spinning.
fn sleep_until(due: Instant) {
    const SPIN: Duration = Duration::from_micros(300);
    let now = Instant::now();
    if due > now + SPIN {
        thread::sleep(due - now - SPIN);
    }
    while Instant::now() < due {
        std::hint::spin_loop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MemoryLink;
    use hilsim_lidar_emulator::neato_packet::{Decoder, Reading};

    fn frame(rev: u64) -> RevolutionFrame {
        RevolutionFrame {
            rev,
            rpm: 300.0,
            start_s: rev as f64 * 0.2,
            readings: [Reading::distance(1000 + rev as u16, 100); 360],
        }
    }

    #[test]
    fn a_reader_that_keeps_up_gets_every_revolution_whole() {
        let mut s = Streamer::new(MemoryLink::with_capacity(4 * BACKLOG_LIMIT), Pacing::Fast);
        let mut decoder = Decoder::new();
        let mut packets = 0;
        for rev in 0..20 {
            s.send(&frame(rev)).unwrap();
            packets += decoder.feed(&s.link().take()).count();
        }
        assert_eq!(packets, 20 * 90);
        assert_eq!(s.stats().revolutions_sent, 20);
        assert_eq!(s.stats().revolutions_dropped, 0);
    }

    #[test]
    fn an_absent_reader_costs_revolutions_not_time_and_a_late_one_gets_fresh_data() {
        let mut s = Streamer::new(MemoryLink::with_capacity(8 * BACKLOG_LIMIT), Pacing::Fast);
        for rev in 0..50 {
            s.send(&frame(rev)).unwrap();
        }
        let stats = s.stats().clone();
        // Every revolution is counted once, sent or dropped (a revolution written and then
        // thrown away unread is dropped); the backlog never exceeds two revolutions, so of 50
        // at most 2 can still be waiting.
        assert_eq!(stats.revolutions_sent + stats.revolutions_dropped, 50);
        assert!(stats.revolutions_dropped >= 48 - 2, "{stats:?}");
        // What a reader connecting now finds is at most two revolutions, the newest ones.
        let backlog = s.link().take();
        assert!(backlog.len() <= 2 * BACKLOG_LIMIT, "{}", backlog.len());
        let first = Decoder::new().feed(&backlog).next().unwrap();
        assert!(first.readings[0].distance_mm >= 1048, "{first:?}");
        assert!(s.link().discarded() >= 46 * BACKLOG_LIMIT);
    }

    fn packet(rev: u64, index: u8) -> Packet {
        Packet {
            index,
            rpm_fixed: hilsim_lidar_emulator::neato_packet::rpm_to_fixed(300.0),
            readings: [Reading::distance(1000 + rev as u16, 100); 4],
        }
    }

    fn send_revolution(s: &mut Streamer<MemoryLink>, rev: u64) {
        for index in 0..90 {
            s.send_packet(&packet(rev, index), Instant::now(), 0.0)
                .unwrap();
        }
    }

    #[test]
    fn packets_sent_one_at_a_time_make_whole_revolutions_and_count_what_a_reader_took() {
        let mut s = Streamer::new(
            MemoryLink::with_capacity(8 * BACKLOG_LIMIT),
            Pacing::Realtime,
        );
        // The tail of a revolution before the first start is not sent.
        for index in 45..90 {
            s.send_packet(&packet(0, index), Instant::now(), 0.0)
                .unwrap();
        }
        assert_eq!(s.stats().bytes_written, 0);
        send_revolution(&mut s, 1);
        let taken = s.link().take();
        assert_eq!(Decoder::new().feed(&taken).count(), 90);
        // Nobody reads revolutions 2..=5: the backlog is discarded at a revolution start once it
        // holds more than one revolution, and what the reader took can be told from the counts.
        for rev in 2..=5 {
            send_revolution(&mut s, rev);
        }
        let stats = s.stats().clone();
        // Two written and then thrown away unread count as dropped, not sent.
        assert_eq!(stats.revolutions_sent, 3);
        assert_eq!(stats.revolutions_dropped, 2);
        assert_eq!(stats.bytes_written, 5 * BACKLOG_LIMIT as u64);
        assert_eq!(stats.bytes_discarded, 2 * BACKLOG_LIMIT as u64);
        let backlog = s.link().backlog().unwrap() as u64;
        assert_eq!(
            stats.bytes_written - stats.bytes_discarded - backlog,
            taken.len() as u64
        );
        assert_eq!(stats.paced_packets(), 5 * 90);
        let left = s.link().take();
        let first = Decoder::new().feed(&left).next().unwrap();
        assert_eq!(first.readings[0].distance_mm, 1004);
    }

    #[test]
    fn a_packet_the_link_cannot_take_drops_the_rest_of_its_revolution_once() {
        let mut s = Streamer::new(
            MemoryLink::with_capacity(BACKLOG_LIMIT + 100),
            Pacing::Realtime,
        );
        send_revolution(&mut s, 0);
        // The link fills up five packets into the next revolution.
        send_revolution(&mut s, 1);
        assert_eq!(s.stats().revolutions_sent, 1);
        assert_eq!(s.stats().revolutions_dropped, 1);
        assert!(
            s.link().take().is_empty(),
            "the partial revolution was discarded"
        );
        send_revolution(&mut s, 2);
        assert_eq!(s.stats().revolutions_sent, 2);
        assert_eq!(Decoder::new().feed(&s.link().take()).count(), 90);
    }

    #[test]
    fn realtime_sends_each_packet_no_earlier_than_its_last_reading() {
        let mut s = Streamer::new(
            MemoryLink::with_capacity(8 * BACKLOG_LIMIT),
            Pacing::Realtime,
        );
        let start = Instant::now();
        for rev in 0..3 {
            s.send(&frame(rev)).unwrap();
            s.link().take();
        }
        // Three revolutions at 300 rpm end 0.6 s after the first began: pacing may be late,
        // never early (a lower bound only: shared machines make upper bounds flaky).
        assert!(
            start.elapsed() >= Duration::from_millis(599),
            "{:?}",
            start.elapsed()
        );
        assert_eq!(s.stats().paced_packets(), 270);
        assert!(s.stats().lateness_quantile(0.99).is_some());
    }
}
