//! The one trait every serial link implements: bytes out without ever blocking, and a view of
//! the backlog a slow or absent reader leaves behind.

use std::io::{self, Read, Write};

/// A byte link to a serial client (a pty, a device, or memory in tests).
///
/// `write` never blocks: when the link cannot take more it returns what it took, or an error of
/// kind `WouldBlock` (or `TimedOut`).
pub trait SerialLink: Write + Send {
    /// Bytes written but not yet taken by the reader, as far as the link can tell.
    ///
    /// # Errors
    /// The link failed.
    fn backlog(&mut self) -> io::Result<usize>;

    /// Throws the backlog away, so a reader that comes back gets fresh data.
    ///
    /// # Errors
    /// The link failed.
    fn discard_backlog(&mut self) -> io::Result<()>;

    /// Undoes anything the last client did that would stop the next one from opening the
    /// port (a pty's exclusive mode). The default does nothing.
    ///
    /// # Errors
    /// The link failed.
    fn allow_reconnect(&mut self) -> io::Result<()> {
        Ok(())
    }

    /// Reads what the client wrote (a command-driven unit's commands) into `buf`, without
    /// waiting: `Ok(0)` when nothing is there. The default has no way back and reads nothing.
    ///
    /// # Errors
    /// The link failed.
    fn read_host(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let _ = buf;
        Ok(0)
    }
}

/// Reads what is there now from a non-blocking port: nothing (`Ok(0)`) rather than an error when
/// the read would wait, and nothing once no client holds the other side (`EIO` on a pty).
pub(crate) fn read_now(port: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    match port.read(buf) {
        Ok(n) => Ok(n),
        Err(err)
            if matches!(
                err.kind(),
                io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut | io::ErrorKind::Interrupted
            ) =>
        {
            Ok(0)
        }
        // EIO: a pty whose client side nobody holds open.
        Err(err) if err.raw_os_error() == Some(5) => Ok(0),
        Err(err) => Err(err),
    }
}

/// An in-memory link: a bounded buffer that a test drains by hand.
///
/// ```
/// use std::io::Write;
/// use hilsim_hil::{MemoryLink, SerialLink};
/// let mut link = MemoryLink::with_capacity(4);
/// assert_eq!(link.write(b"abcdef").unwrap(), 4);
/// assert_eq!(link.backlog().unwrap(), 4);
/// assert_eq!(link.take(), b"abcd");
/// ```
#[derive(Debug, Clone, Default)]
pub struct MemoryLink {
    buffer: Vec<u8>,
    capacity: usize,
    discarded: usize,
    /// What the test's client wrote, not yet read by the unit.
    from_client: std::collections::VecDeque<u8>,
}

impl MemoryLink {
    /// A link that holds at most `capacity` unread bytes.
    #[must_use]
    pub fn with_capacity(capacity: usize) -> Self {
        Self {
            buffer: Vec::new(),
            capacity,
            discarded: 0,
            from_client: std::collections::VecDeque::new(),
        }
    }

    /// The client writes `bytes` (a command to the unit).
    pub fn client_writes(&mut self, bytes: &[u8]) {
        self.from_client.extend(bytes);
    }

    /// What a reader would read now; empties the buffer.
    pub fn take(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.buffer)
    }

    /// Bytes thrown away by [`SerialLink::discard_backlog`].
    #[must_use]
    pub fn discarded(&self) -> usize {
        self.discarded
    }
}

impl Write for MemoryLink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let room = self.capacity.saturating_sub(self.buffer.len());
        if room == 0 && !buf.is_empty() {
            return Err(io::ErrorKind::WouldBlock.into());
        }
        let n = room.min(buf.len());
        self.buffer.extend_from_slice(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl SerialLink for MemoryLink {
    fn backlog(&mut self) -> io::Result<usize> {
        Ok(self.buffer.len())
    }

    fn discard_backlog(&mut self) -> io::Result<()> {
        self.discarded += self.buffer.len();
        self.buffer.clear();
        Ok(())
    }

    fn read_host(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = buf.len().min(self.from_client.len());
        for (slot, byte) in buf.iter_mut().zip(self.from_client.drain(..n)) {
            *slot = byte;
        }
        Ok(n)
    }
}
