//! How a run goes: its length, the watchdog, the flood limits, the firmware's grace.

use std::time::Duration;

/// How long a firmware may go without a request before it counts as hung; also the time it has
/// to start reading the lidar.
pub const DEFAULT_WATCHDOG: Duration = Duration::from_secs(5);

/// How long the firmware has to exit by itself once its ports have closed.
pub const DEFAULT_FIRMWARE_GRACE: Duration = Duration::from_secs(1);

/// How much a firmware may send per second before it counts as flooding the port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FloodLimits {
    /// Bytes per second: by default 11,520, all that 115200 baud 8N1 carries: no real serial
    /// line would deliver more.
    pub bytes_per_s: u64,
    /// Requests per second: by default 200 (a real robot answers a `GetMotors` in about
    /// 60 ms at 115200 baud; a firmware polling faster than 200 Hz is broken).
    pub commands_per_s: u64,
}

impl Default for FloodLimits {
    fn default() -> Self {
        Self {
            bytes_per_s: 11_520,
            commands_per_s: 200,
        }
    }
}

impl FloodLimits {
    /// No limits (benchmarks that measure the port flat out).
    pub const NONE: Self = Self {
        bytes_per_s: u64::MAX,
        commands_per_s: u64::MAX,
    };
}

/// How a run goes.
#[derive(Debug, Clone)]
pub struct HilConfig {
    /// The run's length (simulated = wall time).
    pub duration: Duration,
    /// See [`DEFAULT_WATCHDOG`].
    pub watchdog: Duration,
    /// See [`FloodLimits`].
    pub flood: FloodLimits,
    /// See [`DEFAULT_FIRMWARE_GRACE`].
    pub firmware_grace: Duration,
}

impl HilConfig {
    /// A run of `duration` with the default watchdog, flood limits and grace.
    #[must_use]
    pub fn new(duration: Duration) -> Self {
        Self {
            duration,
            watchdog: DEFAULT_WATCHDOG,
            flood: FloodLimits::default(),
            firmware_grace: DEFAULT_FIRMWARE_GRACE,
        }
    }
}
