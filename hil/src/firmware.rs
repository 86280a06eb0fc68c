//! The firmware under test as a child process: started from a command line split like a shell
//! would (no shell runs), in a process group of its own, with its stderr captured (the last
//! [`STDERR_TAIL_LINES`] lines are kept for the report) and its stdout passed through.
//!
//! Whatever way the run ends, the whole process group is killed: [`Firmware::shut_down`] asks
//! politely first (the ports close, then `SIGTERM`), and dropping a [`Firmware`] on any other
//! path (a harness error, a panic) kills the group with `SIGKILL` and reaps the child. The ptys
//! are close-on-exec, so the firmware holds only the ports it opens itself.

use std::collections::VecDeque;
use std::fmt;
use std::io::{self, BufRead, BufReader};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::process::{Child, ChildStderr, Command, ExitStatus, Stdio};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread;
use std::time::{Duration, Instant};

use nix::sys::signal::{self, killpg, sigprocmask, SigHandler, SigSet, SigmaskHow, Signal};

use crate::escaped::{kill_all, new_lineage, EscapedProcess, LINEAGE_VARIABLE};
use nix::unistd::Pid;

/// How many of the firmware's last stderr lines are kept.
pub const STDERR_TAIL_LINES: usize = 20;
/// Longest stderr line kept, characters (longer lines are cut).
const STDERR_LINE_CHARS: usize = 240;
/// How long a firmware has to leave after `SIGTERM` before it is killed.
pub const TERM_GRACE: Duration = Duration::from_secs(1);
/// How often a waiting harness looks at the child.
const POLL: Duration = Duration::from_millis(5);

/// A firmware command line that cannot be split into words.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum SplitError {
    /// Nothing to run.
    Empty,
    /// A quote (`'` or `"`) is never closed.
    UnterminatedQuote(char),
    /// The line ends with a lone backslash.
    TrailingBackslash,
}

impl fmt::Display for SplitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Empty => write!(f, "the firmware command line is empty"),
            Self::UnterminatedQuote(q) => {
                write!(f, "unterminated {q} quote in the firmware command line")
            }
            Self::TrailingBackslash => {
                write!(f, "the firmware command line ends with a lone backslash")
            }
        }
    }
}

impl std::error::Error for SplitError {}

/// Splits a command line into words the way a POSIX shell does, without expanding anything:
/// blanks separate words; `'…'` is literal; inside `"…"` a backslash escapes only `\`, `"`,
/// `$` and `` ` ``; elsewhere a backslash escapes the next character. `$VAR`, `~`, globs and
/// operators (`|`, `;`, `>`…) are ordinary characters: for those, run `sh -c '…'`.
///
/// ```
/// use hilsim_hil::firmware::split_command_line;
/// assert_eq!(
///     split_command_line(r#"fw --name 'my robot' "a \"b\"" c\ d ''"#).unwrap(),
///     ["fw", "--name", "my robot", "a \"b\"", "c d", ""]
/// );
/// assert!(split_command_line("fw 'oops").is_err());
/// ```
///
/// # Errors
/// An empty line, an unterminated quote or a trailing backslash.
pub fn split_command_line(line: &str) -> Result<Vec<String>, SplitError> {
    let mut words = Vec::new();
    let mut word: Option<String> = None;
    let mut chars = line.chars();
    while let Some(c) = chars.next() {
        match c {
            c if c.is_whitespace() => {
                if let Some(w) = word.take() {
                    words.push(w);
                }
            }
            '\'' => {
                let w = word.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(c) => w.push(c),
                        None => return Err(SplitError::UnterminatedQuote('\'')),
                    }
                }
            }
            '"' => {
                let w = word.get_or_insert_with(String::new);
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\\') => match chars.next() {
                            Some(e @ ('\\' | '"' | '$' | '`')) => w.push(e),
                            Some(other) => {
                                w.push('\\');
                                w.push(other);
                            }
                            None => return Err(SplitError::UnterminatedQuote('"')),
                        },
                        Some(c) => w.push(c),
                        None => return Err(SplitError::UnterminatedQuote('"')),
                    }
                }
            }
            '\\' => match chars.next() {
                Some(e) => word.get_or_insert_with(String::new).push(e),
                None => return Err(SplitError::TrailingBackslash),
            },
            c => word.get_or_insert_with(String::new).push(c),
        }
    }
    words.extend(word);
    if words.is_empty() {
        return Err(SplitError::Empty);
    }
    Ok(words)
}

/// How the firmware ended once the run was over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ended {
    /// It exited by itself (during the run, when its ports closed, or after a `SIGTERM` it had
    /// blocked or ignored: see [`FirmwareExit::shrugged_off_sigterm`]).
    ByItself,
    /// It left on `SIGTERM` (killed by it, or exiting from its handler).
    Terminated,
    /// It was still running [`TERM_GRACE`] after `SIGTERM` and was killed.
    Killed,
}

/// The firmware's exit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FirmwareExit {
    /// Its exit status.
    pub status: ExitStatus,
    /// How it came to exit.
    pub ended: Ended,
    /// `SIGTERM` was sent while the firmware had it blocked or ignored, so it could not act on it.
    pub shrugged_off_sigterm: bool,
    /// Processes it started that left its group and were still running once the group was
    /// gone; they were killed.
    pub escaped: Vec<EscapedProcess>,
}

/// An exit status in words: `exit status 3`, `signal 11 (SIGSEGV)`.
#[must_use]
pub fn describe_status(status: ExitStatus) -> String {
    match (status.code(), status.signal()) {
        (Some(code), _) => format!("exit status {code}"),
        (None, Some(sig)) => match Signal::try_from(sig) {
            Ok(signal) => format!("signal {sig} ({})", signal.as_str()),
            Err(_) => format!("signal {sig}"),
        },
        (None, None) => status.to_string(),
    }
}

/// The last lines of the firmware's stderr.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct StderrTail {
    /// The last [`STDERR_TAIL_LINES`] lines, oldest first.
    pub lines: Vec<String>,
    /// Lines written in all.
    pub total: u64,
}

#[derive(Debug, Default)]
struct TailState {
    lines: VecDeque<String>,
    total: u64,
    closed: bool,
}

#[derive(Debug, Default)]
struct Tail {
    state: Mutex<TailState>,
    closed: Condvar,
}

/// The process groups (and lineages) of the firmwares this process started that have not been
/// dropped yet, for [`kill_all_running`].
static RUNNING: Mutex<Vec<(Pid, String)>> = Mutex::new(Vec::new());

/// Kills, with `SIGKILL`, every firmware this process started and still holds, its process group
/// and what left the group: for a harness that must end at once (a second Ctrl-C) and has no
/// time to shut them down in order. Their [`Firmware`]s reap them when dropped.
pub fn kill_all_running() {
    let running = RUNNING.lock().unwrap_or_else(PoisonError::into_inner);
    for (pgid, lineage) in running.iter() {
        let _ = killpg(*pgid, Signal::SIGKILL);
        let _ = kill_all(lineage, Some(pgid.as_raw()));
    }
}

/// A running firmware.
#[derive(Debug)]
pub struct Firmware {
    child: Child,
    pgid: Pid,
    /// The value of [`LINEAGE_VARIABLE`] in its environment and its descendants'.
    lineage: String,
    status: Option<ExitStatus>,
    tail: Arc<Tail>,
}

impl Firmware {
    /// Starts `argv` (the program, then its arguments) with `env` added to the environment,
    /// stdin from `/dev/null`, stdout inherited and stderr captured, as the leader of a new
    /// process group, and [`LINEAGE_VARIABLE`] set so that what leaves the group is found. It
    /// starts with no signal blocked and every signal at its default disposition, whatever the
    /// calling thread's, and is killed if the thread that started it ends first (Linux ties the
    /// parent-death signal to that thread): start it from the thread that runs it.
    ///
    /// # Errors
    /// `argv` is empty, or the program cannot be started.
    pub fn spawn(argv: &[String], env: &[(&str, &str)]) -> io::Result<Self> {
        let (program, args) = argv
            .split_first()
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, SplitError::Empty))?;
        let lineage = new_lineage();
        let mut command = Command::new(program);
        command
            .args(args)
            .envs(env.iter().copied())
            .env(LINEAGE_VARIABLE, &lineage)
            .stdin(Stdio::null())
            .stderr(Stdio::piped())
            .process_group(0);
        let parent = nix::unistd::getpid();
        // The firmware starts with an empty signal mask and every signal at its default, as from
        // a shell: hilsim waits for SIGINT, SIGTERM and SIGHUP with them blocked in its threads,
        // and a child inherits the mask (and ignored dispositions, across `exec`), so a firmware
        // would never see the polite SIGTERM.
        //
        // SAFETY: the closure runs in the child between `fork` and `exec`, where only
        // async-signal-safe calls may be made: it makes only `sigprocmask`, `signal` with
        // `SIG_DFL` (installing no handler), `prctl` and `getppid`, all plain system calls, and
        // allocates nothing (an `Errno` becomes an `io::Error` without allocating).
        #[allow(unsafe_code)]
        unsafe {
            command.pre_exec(move || {
                sigprocmask(SigmaskHow::SIG_SETMASK, Some(&SigSet::empty()), None)?;
                for which in Signal::iterator() {
                    if !matches!(which, Signal::SIGKILL | Signal::SIGSTOP) {
                        signal::signal(which, SigHandler::SigDfl)?;
                    }
                }
                // The leader dies with the thread that started it even when hilsim is killed
                // outright and cannot shut it down; checked after, in case that already happened.
                if nix::libc::prctl(
                    nix::libc::PR_SET_PDEATHSIG,
                    nix::libc::SIGKILL as nix::libc::c_ulong,
                ) != 0
                {
                    return Err(io::Error::last_os_error());
                }
                if nix::unistd::getppid() != parent {
                    return Err(io::Error::from_raw_os_error(nix::libc::ESRCH));
                }
                Ok(())
            });
        }
        let mut child = command.spawn()?;
        let pgid = Pid::from_raw(i32::try_from(child.id()).unwrap_or(i32::MAX));
        let tail = Arc::new(Tail::default());
        if let Some(stderr) = child.stderr.take() {
            let tail = Arc::clone(&tail);
            // Detached: a grandchild that escaped the group could keep the pipe open forever.
            let spawned = thread::Builder::new()
                .name("firmware-stderr".into())
                .spawn(move || collect_stderr(stderr, &tail));
            if let Err(err) = spawned {
                let _ = killpg(pgid, Signal::SIGKILL);
                let _ = child.wait();
                return Err(err);
            }
        }
        RUNNING
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push((pgid, lineage.clone()));
        Ok(Self {
            child,
            pgid,
            lineage,
            status: None,
            tail,
        })
    }

    /// The firmware's process id (also its process group id).
    #[must_use]
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// The exit status, once the firmware has exited (it is then reaped).
    ///
    /// # Errors
    /// The child cannot be waited for.
    pub fn try_exit(&mut self) -> io::Result<Option<ExitStatus>> {
        if self.status.is_none() {
            self.status = self.child.try_wait()?;
        }
        Ok(self.status)
    }

    /// Ends the firmware after the run: waits up to `grace` for it to leave by itself (its ports
    /// have closed), then sends its group `SIGTERM`, then after [`TERM_GRACE`] `SIGKILL`. What
    /// is left of the group afterwards is killed too.
    ///
    /// # Errors
    /// The child cannot be waited for or signalled.
    pub fn shut_down(&mut self, grace: Duration) -> io::Result<FirmwareExit> {
        let exit = |status, ended, shrugged_off_sigterm| FirmwareExit {
            status,
            ended,
            shrugged_off_sigterm,
            escaped: Vec::new(),
        };
        let mut exit = if let Some(status) = self.wait_for(grace)? {
            exit(status, Ended::ByItself, false)
        } else {
            // What it does with the signal decides what its exit means.
            let shrugged_off = crate::process::shrugs_off(self.pid(), Signal::SIGTERM);
            signal_group(self.pgid, Signal::SIGTERM)?;
            if let Some(status) = self.wait_for(TERM_GRACE)? {
                let ended = if shrugged_off {
                    Ended::ByItself
                } else {
                    Ended::Terminated
                };
                exit(status, ended, shrugged_off)
            } else {
                signal_group(self.pgid, Signal::SIGKILL)?;
                let status = self.child.wait()?;
                self.status = Some(status);
                exit(status, Ended::Killed, shrugged_off)
            }
        };
        // Whatever the leader left running in its group goes too, and what left the group.
        signal_group(self.pgid, Signal::SIGKILL)?;
        exit.escaped = kill_all(&self.lineage, Some(self.pgid.as_raw()));
        self.wait_for_stderr(Duration::from_millis(500));
        Ok(exit)
    }

    /// The last lines of stderr so far.
    #[must_use]
    pub fn stderr_tail(&self) -> StderrTail {
        let state = self
            .tail
            .state
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        StderrTail {
            lines: state.lines.iter().cloned().collect(),
            total: state.total,
        }
    }

    /// Waits up to `limit` for the child to exit.
    fn wait_for(&mut self, limit: Duration) -> io::Result<Option<ExitStatus>> {
        let deadline = Instant::now() + limit;
        loop {
            if let Some(status) = self.try_exit()? {
                return Ok(Some(status));
            }
            if Instant::now() >= deadline {
                return Ok(None);
            }
            thread::sleep(POLL);
        }
    }

    /// Waits up to `limit` for every writer of the stderr pipe to close it.
    fn wait_for_stderr(&self, limit: Duration) {
        let state = self
            .tail
            .state
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        let _ = self
            .tail
            .closed
            .wait_timeout_while(state, limit, |s| !s.closed);
    }
}

impl Drop for Firmware {
    fn drop(&mut self) {
        // Every path out of the harness comes through here: nothing of the firmware survives.
        let _ = killpg(self.pgid, Signal::SIGKILL);
        let _ = kill_all(&self.lineage, Some(self.pgid.as_raw()));
        if self.status.is_none() {
            let _ = self.child.wait();
        }
        RUNNING
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .retain(|(pgid, _)| *pgid != self.pgid);
    }
}

/// Signals the group; a group that is already gone is not an error.
fn signal_group(pgid: Pid, signal: Signal) -> io::Result<()> {
    match killpg(pgid, signal) {
        Ok(()) | Err(nix::errno::Errno::ESRCH) => Ok(()),
        Err(err) => Err(io::Error::from(err)),
    }
}

/// Reads stderr to its end, keeping the last lines.
fn collect_stderr(stderr: ChildStderr, tail: &Tail) {
    let mut reader = BufReader::new(stderr);
    let mut line = Vec::new();
    loop {
        line.clear();
        match reader.read_until(b'\n', &mut line) {
            Ok(0) | Err(_) => break,
            Ok(_) => {
                let text = String::from_utf8_lossy(&line);
                let text = text.trim_end_matches(['\n', '\r']);
                let kept: String = text.chars().take(STDERR_LINE_CHARS).collect();
                let mut state = tail.state.lock().unwrap_or_else(PoisonError::into_inner);
                state.total += 1;
                if state.lines.len() == STDERR_TAIL_LINES {
                    state.lines.pop_front();
                }
                state.lines.push_back(kept);
            }
        }
    }
    // The pipe is closed before anyone is told it is.
    drop(reader);
    tail.state
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .closed = true;
    tail.closed.notify_all();
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(line: &str) -> Vec<String> {
        split_command_line(line).unwrap()
    }

    #[test]
    fn splits_like_a_shell_without_expanding() {
        assert_eq!(words("  fw   a\tb \n c "), ["fw", "a", "b", "c"]);
        assert_eq!(
            words("sh -c 'echo $HOME; exit 3'"),
            ["sh", "-c", "echo $HOME; exit 3"]
        );
        assert_eq!(
            words(r#""x\$y\\z\n" it's"#.replace("it's", "'it'\\''s'").as_str()),
            [r"x$y\z\n", "it's"]
        );
        assert_eq!(words(r"a\ b\'c"), ["a b'c"]);
        assert_eq!(words(r#"pre"mid"'post'"#), ["premidpost"]);
        assert_eq!(words(r#"'' """#), ["", ""]);
        assert_eq!(words("fw >out | x"), ["fw", ">out", "|", "x"]);
    }

    #[test]
    fn refuses_what_a_shell_would_refuse() {
        assert_eq!(split_command_line(""), Err(SplitError::Empty));
        assert_eq!(split_command_line("   "), Err(SplitError::Empty));
        assert_eq!(
            split_command_line("fw 'a"),
            Err(SplitError::UnterminatedQuote('\''))
        );
        assert_eq!(
            split_command_line("fw \"a"),
            Err(SplitError::UnterminatedQuote('"'))
        );
        assert_eq!(
            split_command_line("fw \"a\\"),
            Err(SplitError::UnterminatedQuote('"'))
        );
        assert_eq!(
            split_command_line("fw a\\"),
            Err(SplitError::TrailingBackslash)
        );
    }

    fn sh(script: &str) -> Firmware {
        Firmware::spawn(
            &["sh".into(), "-c".into(), script.into()],
            &[("HILSIM_TEST", "42")],
        )
        .unwrap()
    }

    #[test]
    fn keeps_the_last_stderr_lines_and_reports_the_exit() {
        let mut fw = sh("i=0; while [ $i -lt 30 ]; do echo \"line $i $HILSIM_TEST\" >&2; i=$((i+1)); done; exit 3");
        let exit = fw.shut_down(Duration::from_secs(5)).unwrap();
        assert_eq!(exit.ended, Ended::ByItself);
        assert_eq!(exit.status.code(), Some(3));
        assert_eq!(describe_status(exit.status), "exit status 3");
        let tail = fw.stderr_tail();
        assert_eq!(tail.total, 30);
        assert_eq!(tail.lines.len(), STDERR_TAIL_LINES);
        assert_eq!(tail.lines[0], "line 10 42");
        assert_eq!(tail.lines[19], "line 29 42");
    }

    #[test]
    fn a_firmware_that_ignores_its_ports_is_terminated_and_its_group_goes_with_it() {
        let mut fw = sh("sleep 30 & echo $! >&2; wait");
        let pid = fw.pid();
        // The background sleep's pid arrives on stderr.
        let deadline = Instant::now() + Duration::from_secs(5);
        while fw.stderr_tail().lines.is_empty() {
            assert!(Instant::now() < deadline);
            thread::sleep(POLL);
        }
        let grandchild: i32 = fw.stderr_tail().lines[0].parse().unwrap();
        let exit = fw.shut_down(Duration::from_millis(50)).unwrap();
        assert_eq!(exit.ended, Ended::Terminated);
        assert_eq!(describe_status(exit.status), "signal 15 (SIGTERM)");
        assert!(gone(pid as i32) && gone(grandchild), "{pid} {grandchild}");
    }

    #[test]
    fn dropping_a_firmware_kills_its_whole_group() {
        let fw = sh("sleep 30 & echo $! >&2; trap '' TERM; wait");
        let pid = fw.pid() as i32;
        let deadline = Instant::now() + Duration::from_secs(5);
        while fw.stderr_tail().lines.is_empty() {
            assert!(Instant::now() < deadline);
            thread::sleep(POLL);
        }
        let grandchild: i32 = fw.stderr_tail().lines[0].parse().unwrap();
        drop(fw);
        assert!(gone(pid) && gone(grandchild), "{pid} {grandchild}");
    }

    /// A daemon that left the firmware's group (`setsid`) is reported and killed.
    #[test]
    fn a_process_that_left_the_group_is_reported_and_killed() {
        // The pid is told only once the daemon has left (its own session, `sleep` exec'd):
        // on a loaded machine the firmware could otherwise exit first and its group be shut
        // down with the daemon still in it, which kills it as a member, not as an escapee.
        let mut fw = sh("setsid sleep 30 </dev/null >/dev/null 2>&1 & p=$!; \
             until [ \"$(cut -d' ' -f2,6 /proc/$p/stat)\" = \"(sleep) $p\" ]; do sleep 0.01; done; \
             echo $p >&2; exit 0");
        let deadline = Instant::now() + Duration::from_secs(5);
        while fw.stderr_tail().lines.is_empty() {
            assert!(Instant::now() < deadline);
            thread::sleep(POLL);
        }
        let escaped: u32 = fw.stderr_tail().lines[0].parse().unwrap();
        let exit = fw.shut_down(Duration::from_secs(5)).unwrap();
        assert_eq!(exit.ended, Ended::ByItself);
        assert_eq!(
            exit.escaped,
            [EscapedProcess {
                pid: escaped,
                command: "sleep".into()
            }]
        );
        assert!(gone(escaped as i32), "{escaped}");
    }

    /// A firmware in Python: no shell between hilsim and it, since a shell resets what it
    /// inherits and would hide a blocked or ignored signal.
    fn python(script: &str) -> Firmware {
        Firmware::spawn(&["python3".into(), "-c".into(), script.into()], &[]).unwrap()
    }

    /// Waits for the firmware's first stderr line.
    fn first_line(fw: &Firmware) -> String {
        let deadline = Instant::now() + Duration::from_secs(10);
        while fw.stderr_tail().lines.is_empty() {
            assert!(Instant::now() < deadline, "no line from the firmware");
            thread::sleep(POLL);
        }
        fw.stderr_tail().lines[0].clone()
    }

    #[test]
    fn a_firmware_started_where_signals_are_blocked_and_ignored_starts_with_neither() {
        // A harness that waits for these blocks them in its threads; this test thread does too.
        let mut blocked = SigSet::empty();
        for which in [Signal::SIGINT, Signal::SIGTERM, Signal::SIGHUP] {
            blocked.add(which);
        }
        blocked.thread_block().unwrap();
        let mut fw = python(
            "import signal, sys, time\n\
             blocked = sorted(int(s) for s in signal.pthread_sigmask(signal.SIG_BLOCK, []))\n\
             sys.stderr.write(f'{blocked} {signal.getsignal(signal.SIGTERM) == signal.SIG_DFL}\\n')\n\
             sys.stderr.flush()\n\
             time.sleep(30)",
        );
        blocked.thread_unblock().unwrap();
        assert_eq!(first_line(&fw), "[] True");
        // So the polite SIGTERM works.
        let exit = fw.shut_down(Duration::from_millis(50)).unwrap();
        assert_eq!(exit.ended, Ended::Terminated);
        assert!(!exit.shrugged_off_sigterm);
        assert_eq!(describe_status(exit.status), "signal 15 (SIGTERM)");
    }

    #[test]
    fn a_firmware_that_blocks_sigterm_and_exits_later_is_not_said_to_have_left_on_it() {
        let mut fw = python(
            "import signal, sys, time\n\
             signal.pthread_sigmask(signal.SIG_BLOCK, [signal.SIGTERM])\n\
             sys.stderr.write('blocked\\n')\n\
             sys.stderr.flush()\n\
             time.sleep(0.5)",
        );
        assert_eq!(first_line(&fw), "blocked");
        let exit = fw.shut_down(Duration::from_millis(50)).unwrap();
        assert_eq!(exit.ended, Ended::ByItself);
        assert!(exit.shrugged_off_sigterm);
        assert_eq!(exit.status.code(), Some(0));
    }

    #[test]
    fn a_firmware_that_ignores_sigterm_is_killed_and_said_to_have_ignored_it() {
        let mut fw = python(
            "import signal, sys, time\n\
             signal.signal(signal.SIGTERM, signal.SIG_IGN)\n\
             sys.stderr.write('ignoring\\n')\n\
             sys.stderr.flush()\n\
             time.sleep(30)",
        );
        assert_eq!(first_line(&fw), "ignoring");
        let exit = fw.shut_down(Duration::from_millis(50)).unwrap();
        assert_eq!(exit.ended, Ended::Killed);
        assert!(exit.shrugged_off_sigterm);
        assert_eq!(describe_status(exit.status), "signal 9 (SIGKILL)");
    }

    #[test]
    fn a_program_that_does_not_exist_is_an_error() {
        let err = Firmware::spawn(&["/nonexistent/firmware".into()], &[]).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::NotFound);
        assert!(Firmware::spawn(&[], &[]).is_err());
    }

    /// The process no longer runs (gone, or a zombie waiting for init to reap it).
    fn gone(pid: i32) -> bool {
        crate::process::has_exited(pid.unsigned_abs(), Duration::from_secs(2))
    }
}
