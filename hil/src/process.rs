//! Whether a process still runs: what the tests of every exit path (and anyone checking for
//! orphans a firmware left) ask of the system.

use std::thread;
use std::time::{Duration, Instant};

/// Whether process `pid` is gone, or a zombie waiting for its parent to reap it, within `within`
/// (polled every 10 ms from `/proc`; Linux).
#[must_use]
pub fn has_exited(pid: u32, within: Duration) -> bool {
    let deadline = Instant::now() + within;
    loop {
        match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
            Err(_) => return true,
            Ok(stat) if stat_is_zombie(&stat) => return true,
            Ok(_) if Instant::now() > deadline => return false,
            Ok(_) => thread::sleep(Duration::from_millis(10)),
        }
    }
}

/// Whether process `pid` is a zombie (ended, not yet reaped); `false` when it is gone.
#[must_use]
pub fn is_zombie(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| stat_is_zombie(&stat))
}

/// The state follows the command name, which is in parentheses and may hold any byte.
fn stat_is_zombie(stat: &str) -> bool {
    stat.rsplit(')')
        .next()
        .is_some_and(|s| s.trim_start().starts_with('Z'))
}

/// The ids of every other process this one can see (`/proc`; Linux; empty elsewhere).
#[must_use]
pub fn other_pids() -> Vec<u32> {
    let ours = std::process::id();
    std::fs::read_dir("/proc").map_or_else(
        |_| Vec::new(),
        |entries| {
            entries
                .filter_map(Result::ok)
                .filter_map(|e| e.file_name().to_str()?.parse::<u32>().ok())
                .filter(|&pid| pid != ours)
                .collect()
        },
    )
}

/// Whether process `pid` has `signal` blocked (in its main thread) or ignored, so that sending
/// it does nothing (`/proc/PID/status`; Linux; `false` when that cannot be read).
#[must_use]
pub fn shrugs_off(pid: u32, signal: nix::sys::signal::Signal) -> bool {
    let Ok(status) = std::fs::read_to_string(format!("/proc/{pid}/status")) else {
        return false;
    };
    let bit = 1u64 << (signal as i32 - 1);
    status.lines().any(|line| {
        ["SigBlk:", "SigIgn:"].iter().any(|key| {
            line.strip_prefix(key)
                .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
                .is_some_and(|mask| mask & bit != 0)
        })
    })
}
