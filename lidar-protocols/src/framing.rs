//! The framing the LD06 and the LDS-01 share: fixed-length packets that open with a sync byte
//! and a second byte from a known set, found in a byte stream and resynchronised after damage.

use crate::DecodeStats;

/// Finds fixed-length packets of `N` bytes in a stream. When a whole candidate fails its
/// check, only its sync byte is dropped and the rest rescanned for the next sync byte followed
/// by a valid second byte (as `lds2d` does), so a packet that begins inside a damaged one is
/// still found. Holds at most `N` bytes.
#[derive(Debug, Clone)]
pub(crate) struct SyncFramer<const N: usize> {
    window: [u8; N],
    len: usize,
    sync: u8,
    second: fn(u8) -> bool,
    pub(crate) stats: DecodeStats,
}

impl<const N: usize> SyncFramer<N> {
    /// A framer for packets opening with `sync`, then a byte that `second` accepts.
    pub(crate) fn new(sync: u8, second: fn(u8) -> bool) -> Self {
        Self {
            window: [0; N],
            len: 0,
            sync,
            second,
            stats: DecodeStats::default(),
        }
    }

    /// Bytes held for a packet not complete yet, 0..N.
    pub(crate) fn pending_len(&self) -> usize {
        self.len
    }

    /// Takes one byte; when it completes a candidate that `check` accepts, returns what `check`
    /// made of it.
    pub(crate) fn push<T>(&mut self, byte: u8, check: impl Fn(&[u8; N]) -> Option<T>) -> Option<T> {
        self.stats.bytes += 1;
        match self.len {
            0 => self.start_or_skip(byte),
            1 if (self.second)(byte) => {
                self.window[1] = byte;
                self.len = 2;
            }
            1 => {
                self.stats.skipped_bytes += 1;
                self.len = 0;
                self.start_or_skip(byte);
            }
            _ => {
                self.window[self.len] = byte;
                self.len += 1;
                if self.len == N {
                    return self.check_window(check);
                }
            }
        }
        None
    }

    fn start_or_skip(&mut self, byte: u8) {
        if byte == self.sync {
            self.window[0] = byte;
            self.len = 1;
        } else {
            self.stats.skipped_bytes += 1;
        }
    }

    fn check_window<T>(&mut self, check: impl Fn(&[u8; N]) -> Option<T>) -> Option<T> {
        if let Some(packet) = check(&self.window) {
            self.len = 0;
            self.stats.packets += 1;
            return Some(packet);
        }
        self.stats.bad_checksum += 1;
        let next = (1..N)
            .find(|&at| {
                self.window[at] == self.sync
                    && self.window.get(at + 1).is_none_or(|&b| (self.second)(b))
            })
            .unwrap_or(N);
        self.stats.skipped_bytes += next as u64;
        self.window.copy_within(next.., 0);
        self.len = N - next;
        None
    }
}
