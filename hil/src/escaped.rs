//! Processes a firmware started that left its process group (a daemon's `setsid`, a double
//! fork into a new group): the group signals never reach them, and they would outlive the run,
//! holding ports, files or the CPU of the next test. Every process the firmware starts inherits
//! its environment, so the firmware is started with a variable unique to the run
//! ([`LINEAGE_VARIABLE`]) and, once its group is gone, any process still carrying it is
//! reported and killed. A descendant that clears its environment cannot be found this way; none
//! of the common ways of daemonising (`setsid`, `daemon(3)`, `nohup`, `disown`) clears it.
//! Linux (`/proc`); elsewhere none is found.

use std::collections::hash_map::RandomState;
use std::fmt;
use std::fs;
use std::hash::BuildHasher;

use nix::sys::signal::{kill, Signal};
use nix::unistd::Pid;

/// The environment variable every process of one firmware run carries.
pub const LINEAGE_VARIABLE: &str = "HILSIM_FIRMWARE_RUN";

/// A process that outlived its firmware's group.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EscapedProcess {
    /// Its process id.
    pub pid: u32,
    /// Its command name (`/proc/PID/comm`).
    pub command: String,
}

impl fmt::Display for EscapedProcess {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.pid, self.command)
    }
}

/// A value of [`LINEAGE_VARIABLE`] no other run shares: this process's id and a random key.
#[must_use]
pub fn new_lineage() -> String {
    let key = RandomState::new().hash_one(std::process::id());
    format!("{}-{key:016x}", std::process::id())
}

/// Every live process whose environment holds `LINEAGE_VARIABLE=lineage`, zombies and the
/// members of process group `group` left out: a member has been sent the group's `SIGKILL`
/// and is on its way out (on a loaded machine it may not have gone yet), not escaped.
#[must_use]
pub fn find(lineage: &str, group: Option<i32>) -> Vec<EscapedProcess> {
    let wanted = format!("{LINEAGE_VARIABLE}={lineage}");
    let mut found: Vec<EscapedProcess> = crate::process::other_pids()
        .into_iter()
        .filter(|&pid| carries(pid, &wanted) && !crate::process::is_zombie(pid))
        .filter(|&pid| group.is_none() || process_group(pid) != group)
        .map(|pid| EscapedProcess {
            pid,
            command: fs::read_to_string(format!("/proc/{pid}/comm"))
                .map(|c| c.trim_end().to_string())
                .unwrap_or_default(),
        })
        .collect();
    found.sort_by_key(|p| p.pid);
    found
}

/// Process `pid`'s group (`/proc/PID/stat`: the third field after the command name, which is
/// in parentheses and may hold any byte); `None` once it has gone.
fn process_group(pid: u32) -> Option<i32> {
    let stat = fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    stat.rsplit(')')
        .next()?
        .split_whitespace()
        .nth(2)?
        .parse()
        .ok()
}

/// Whether process `pid`'s environment holds the entry `wanted` (a process of another user, or
/// one that has just gone, is not read and does not).
fn carries(pid: u32, wanted: &str) -> bool {
    fs::read(format!("/proc/{pid}/environ"))
        .is_ok_and(|env| env.split(|&b| b == 0).any(|e| e == wanted.as_bytes()))
}

/// Finds the processes of `lineage` that are still running outside process group `group` and
/// kills them: what they were.
#[must_use]
pub fn kill_all(lineage: &str, group: Option<i32>) -> Vec<EscapedProcess> {
    let found = find(lineage, group);
    for p in &found {
        if let Ok(pid) = i32::try_from(p.pid) {
            let _ = kill(Pid::from_raw(pid), Signal::SIGKILL);
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::{Command, Stdio};
    use std::time::Duration;

    #[test]
    fn lineages_differ() {
        assert_ne!(new_lineage(), new_lineage());
    }

    /// A process that left its group with `setsid` is found by its environment, and killed.
    #[test]
    fn a_process_that_left_its_group_is_found_and_killed() {
        let lineage = new_lineage();
        let mut child = Command::new("sh")
            .args(["-c", "setsid sleep 30 </dev/null >/dev/null 2>&1 & echo $!"])
            .env(LINEAGE_VARIABLE, &lineage)
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let mut out = String::new();
        std::io::Read::read_to_string(child.stdout.as_mut().unwrap(), &mut out).unwrap();
        child.wait().unwrap();
        let escaped: u32 = out.trim().parse().unwrap();
        // Until the forked shell has become `sleep` and the new image's stack is laid out, its
        // environment may read empty: the kernel names the process (`comm`) before it places
        // the environment, so `comm` alone was seen as `sleep` with nothing to read (failed
        // once in `.ci/run`). Wait for both, as a firmware's daemon would have long done by
        // the time its run ends.
        for _ in 0..500 {
            let comm = std::fs::read_to_string(format!("/proc/{escaped}/comm"));
            let environ = std::fs::read(format!("/proc/{escaped}/environ"));
            if comm.is_ok_and(|c| c.trim_end() == "sleep") && environ.is_ok_and(|e| !e.is_empty()) {
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let found = kill_all(&lineage, None);
        assert!(found.iter().any(|p| p.pid == escaped), "{found:?}");
        assert!(crate::process::has_exited(escaped, Duration::from_secs(2)));
        assert!(find(&lineage, None).is_empty());
        // Another run's lineage finds nothing of this one.
        assert!(find(&new_lineage(), None).is_empty());
    }
}
