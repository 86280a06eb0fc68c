//! The flood meter: requests and bytes in the last second.

use std::time::Duration;

/// Resolution of the flood meter: a one-second window in ten slices.
const FLOOD_SLICE: Duration = Duration::from_millis(100);
const FLOOD_SLICES: usize = 10;

/// Requests and bytes in the last second.
#[derive(Default)]
pub(super) struct FloodMeter {
    slices: [(u64, u64); FLOOD_SLICES],
    current: u64,
}

impl FloodMeter {
    /// Adds to the slice of `elapsed` and returns the totals of the last second.
    pub(super) fn add(&mut self, elapsed: Duration, bytes: u64, commands: u64) -> (u64, u64) {
        let slice = (elapsed.as_millis() / FLOOD_SLICE.as_millis()) as u64;
        let stale = slice.saturating_sub(self.current).min(FLOOD_SLICES as u64);
        for k in 1..=stale {
            self.slices[((self.current + k) % FLOOD_SLICES as u64) as usize] = (0, 0);
        }
        self.current = self.current.max(slice);
        let entry = &mut self.slices[(self.current % FLOOD_SLICES as u64) as usize];
        entry.0 += bytes;
        entry.1 += commands;
        self.slices
            .iter()
            .fold((0, 0), |(b, c), (sb, sc)| (b + sb, c + sc))
    }
}
