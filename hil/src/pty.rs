//! A pseudo-terminal pair: hilsim writes the master side, a client opens the slave's path as it
//! would a USB serial adapter.
//!
//! What a real client needs, learned the hard way:
//! - hilsim keeps its own handle on the client side open: otherwise, once the last reader
//!   leaves, writes fail (EIO) and the port's data is lost between clients;
//! - both descriptors are close-on-exec, or every child process (a firmware under test) would
//!   hold the port open forever;
//! - a pty buffers ~15 KB when nobody reads (measured here: 15,564 bytes before a non-blocking
//!   write would block, of which the slave reports at most 4,095 as readable), so a client that
//!   connects late would first read stale data. The streamer keeps the backlog under one
//!   revolution at each revolution's start by discarding it (through hilsim's own slave handle)
//!   whenever the reader falls behind: a late or returning client reads at most two revolutions
//!   of older data, then live data;
//! - a client that sets exclusive mode (serialport does by default) would lock the next client
//!   out while hilsim's handle keeps the port open, so exclusivity is cleared before each
//!   revolution.

use std::io::{self, Write};
use std::os::unix::io::AsRawFd;
use std::time::Duration;

use nix::fcntl::{fcntl, FcntlArg, FdFlag, OFlag};
use serialport::{ClearBuffer, SerialPort, TTYPort};

use crate::link::SerialLink;

/// A pty pair with hilsim's own handle on the client side.
pub struct PtyLink {
    master: TTYPort,
    client_side: TTYPort,
    client_path: String,
}

impl PtyLink {
    /// Opens a new pair.
    ///
    /// # Errors
    /// The system has no free pty, or the descriptors cannot be configured.
    pub fn open() -> io::Result<Self> {
        let (mut master, client_side) = TTYPort::pair().map_err(io::Error::from)?;
        let client_path = client_side
            .name()
            .ok_or_else(|| io::Error::other("the pty has no client path"))?;
        for fd in [master.as_raw_fd(), client_side.as_raw_fd()] {
            fcntl(fd, FcntlArg::F_SETFD(FdFlag::FD_CLOEXEC)).map_err(io::Error::from)?;
        }
        // Writes must never block the simulation: the master is non-blocking, and a full link
        // shows up as a short write or WouldBlock.
        let flags = fcntl(master.as_raw_fd(), FcntlArg::F_GETFL).map_err(io::Error::from)?;
        let flags = OFlag::from_bits_truncate(flags) | OFlag::O_NONBLOCK;
        fcntl(master.as_raw_fd(), FcntlArg::F_SETFL(flags)).map_err(io::Error::from)?;
        master
            .set_timeout(Duration::ZERO)
            .map_err(io::Error::from)?;
        Ok(Self {
            master,
            client_side,
            client_path,
        })
    }

    /// The path a client opens, e.g. `/dev/pts/3`.
    #[must_use]
    pub fn client_path(&self) -> &str {
        &self.client_path
    }

    /// Whether a process other than this one holds the client side open (Linux: `/proc/*/fd`;
    /// elsewhere `true`, as nothing can tell).
    #[must_use]
    pub fn client_connected(&self) -> bool {
        if !std::path::Path::new("/proc/self/fd").is_dir() {
            return true;
        }
        let client = std::path::Path::new(&self.client_path);
        crate::process::other_pids().into_iter().any(|pid| {
            std::fs::read_dir(format!("/proc/{pid}/fd")).is_ok_and(|fds| {
                fds.filter_map(Result::ok)
                    .any(|fd| std::fs::read_link(fd.path()).is_ok_and(|l| l == client))
            })
        })
    }

    /// Waits until a client has opened the port ([`PtyLink::client_connected`]), or `stop` is
    /// raised; whether a client came.
    pub fn wait_for_client(&self, stop: &std::sync::atomic::AtomicBool) -> bool {
        while !stop.load(std::sync::atomic::Ordering::Relaxed) {
            if self.client_connected() {
                return true;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        false
    }

    /// The master side, for reading what a client writes (the robot command port).
    pub fn master(&mut self) -> &mut TTYPort {
        &mut self.master
    }
}

impl Write for PtyLink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.master.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl SerialLink for PtyLink {
    fn read_host(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        crate::link::read_now(&mut self.master, buf)
    }

    fn backlog(&mut self) -> io::Result<usize> {
        let queued = self.client_side.bytes_to_read().map_err(io::Error::from)?;
        Ok(queued as usize)
    }

    fn discard_backlog(&mut self) -> io::Result<()> {
        self.client_side
            .clear(ClearBuffer::Input)
            .map_err(io::Error::from)
    }

    fn allow_reconnect(&mut self) -> io::Result<()> {
        // Only TIOCNXCL: serialport's `set_exclusive(false)` also takes a shared flock, which
        // fails while a client holds its exclusive flock (and must not disturb it).
        clear_exclusive(self.client_side.as_raw_fd()).map_err(io::Error::from)
    }
}

nix::ioctl_none_bad!(tiocnxcl, nix::libc::TIOCNXCL);

/// Clears a tty's exclusive mode (TIOCNXCL).
#[allow(unsafe_code)]
fn clear_exclusive(fd: std::os::unix::io::RawFd) -> nix::Result<()> {
    // SAFETY: TIOCNXCL takes no argument and only clears a flag of the tty behind `fd`, a
    // descriptor this link owns and keeps open.
    unsafe { tiocnxcl(fd) }.map(|_| ())
}
