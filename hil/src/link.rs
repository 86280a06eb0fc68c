//! The one trait every serial link implements: bytes out without ever blocking, and a view of
//! the backlog a slow or absent reader leaves behind.

use std::io::{self, Write};

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
}

impl MemoryLink {
    /// A link that holds at most `capacity` unread bytes.
    #[must_use]
    pub fn with_capacity(capacity: usize) -> Self {
        Self {
            buffer: Vec::new(),
            capacity,
            discarded: 0,
        }
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
}
