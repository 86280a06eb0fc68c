//! The two sides of every protocol: the unit's ([`Unit`]) and the host's ([`HostDecoder`]).

use std::ops::Range;

/// One reading as the emulated head hands it to a unit's wire, in the unit's own terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitReading {
    /// When it was taken, simulation seconds.
    pub t_s: f64,
    /// Its revolution's number.
    pub rev: u64,
    /// Its place in its revolution (0: the first reading after the unit's 0°; for a grid unit,
    /// its step less the first step read).
    pub index: u32,
    /// Its angle in the unit's own convention, degrees in [0, 360): from the unit's 0°
    /// (forward), growing in the unit's [`crate::Direction`].
    pub angle_deg: f64,
    /// The distance, millimetres; 0 when there is no return (too near, too far, too weak).
    pub distance_mm: u32,
    /// The return's strength, 0–255 (the unit's own scale is the codec's business).
    pub intensity: u8,
    /// The revolution rate the unit reports for this reading's revolution, Hz.
    pub rev_hz: f64,
    /// Whether this reading starts a new revolution (the first of its revolution).
    pub starts_revolution: bool,
}

/// Where one packet lies in an [`Output`]'s bytes, and when it may leave.
#[derive(Debug, Clone, PartialEq)]
pub struct PacketSpan {
    /// Its bytes in [`Output::bytes`].
    pub range: Range<usize>,
    /// When it is complete, simulation seconds: its last reading's instant, or for a reply the
    /// instant of the command it answers.
    pub due_s: f64,
    /// Leading bytes a corruption fault leaves alone (the sync bytes: a packet corrupted there
    /// is no packet at all, which the dropped-packet fault already covers).
    pub sync_len: usize,
    /// Whether the packet carries the first reading of a revolution.
    pub starts_revolution: bool,
}

/// Bytes a unit sends, cut into packets.
#[derive(Debug, Clone, Default)]
pub struct Output {
    /// The bytes, packets back to back.
    pub bytes: Vec<u8>,
    /// The packets, in order.
    pub packets: Vec<PacketSpan>,
}

impl Output {
    /// An empty output.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends one packet that `write` appends to the bytes.
    pub fn packet(
        &mut self,
        due_s: f64,
        sync_len: usize,
        starts_revolution: bool,
        write: impl FnOnce(&mut Vec<u8>),
    ) {
        let start = self.bytes.len();
        write(&mut self.bytes);
        self.packets.push(PacketSpan {
            range: start..self.bytes.len(),
            due_s,
            sync_len,
            starts_revolution,
        });
    }

    /// Each packet's bytes with its span.
    pub fn iter(&self) -> impl Iterator<Item = (&[u8], &PacketSpan)> {
        self.packets
            .iter()
            .map(|span| (&self.bytes[span.range.clone()], span))
    }

    /// Empties it, keeping its allocations.
    pub fn clear(&mut self) {
        self.bytes.clear();
        self.packets.clear();
    }

    /// Whether it holds no packet.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.packets.is_empty()
    }
}

/// The unit's side of a protocol: readings into packets, and for a command-driven unit the
/// host's commands into replies. A pure state machine.
pub trait Unit: Send {
    /// The host wrote `bytes` at simulation time `now_s`: the unit parses its commands (a
    /// command may arrive in pieces) and appends its replies to `out`, each a packet due at
    /// `now_s`. Bytes that are no command are ignored, as a real unit ignores them.
    fn host_wrote(&mut self, bytes: &[u8], now_s: f64, out: &mut Output);

    /// Whether the unit sends its readings now: always for a self-driven unit; for a
    /// command-driven one, from its start command to its stop command.
    fn scanning(&self) -> bool;

    /// The next reading the head takes, in order; the packets it completes are appended to
    /// `out`. A unit that is not scanning takes it and sends nothing (unless a pending one-shot
    /// request, such as SCIP's `GD`, wants it).
    fn push(&mut self, reading: &UnitReading, out: &mut Output);
}

/// One reading as a host decodes it from a unit's bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Its angle in the unit's own convention, degrees in [0, 360).
    pub angle_deg: f64,
    /// The distance, millimetres; 0 when the unit reported no return.
    pub distance_mm: u32,
    /// The strength the unit reported (0 when it reports none).
    pub intensity: u16,
    /// Whether the unit marked it as the first of a revolution (or, for a unit that marks
    /// none, whether its angle wrapped past 0°).
    pub starts_revolution: bool,
    /// The revolution rate the unit reported with it, Hz (`None`: the packet carries none).
    pub rev_hz: Option<f64>,
}

/// What a host's decoder has seen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DecodeStats {
    /// Bytes fed.
    pub bytes: u64,
    /// Packets (or replies) accepted.
    pub packets: u64,
    /// Packets refused for their checksum (or check bits).
    pub bad_checksum: u64,
    /// Bytes skipped while looking for a packet's start.
    pub skipped_bytes: u64,
}

/// The host's side of a protocol: the bytes a unit sends back into its readings, in chunks of
/// any size, resynchronising after damage. A pure state machine with bounded memory.
pub trait HostDecoder: Send {
    /// Decodes `bytes`, appending the readings of every packet they complete to `out`.
    fn feed(&mut self, bytes: &[u8], out: &mut Vec<Point>);

    /// What it has seen so far.
    fn stats(&self) -> DecodeStats;
}
