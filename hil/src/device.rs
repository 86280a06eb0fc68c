//! An existing serial device (a USB adapter, or a pty another program made), opened at the
//! XV-11's line settings: 115200 baud, 8N1, no flow control.

use std::io::{self, Write};
use std::os::unix::fs::FileTypeExt as _;
use std::os::unix::io::AsRawFd;
use std::time::Duration;

use nix::fcntl::{fcntl, FcntlArg, FdFlag};
use serialport::{ClearBuffer, DataBits, FlowControl, Parity, SerialPort, StopBits, TTYPort};

use crate::link::SerialLink;

/// The XV-11's baud rate (docs/formats/neato-xv11.md).
pub const XV11_BAUD: u32 = 115_200;

/// A device opened for writing the lidar stream.
pub struct DeviceLink {
    port: TTYPort,
}

impl DeviceLink {
    /// Opens `path` at the XV-11's 115200 8N1.
    ///
    /// # Errors
    /// `path` is not a terminal device (kind `InvalidInput`, saying what it is instead), or the
    /// device cannot be opened or configured.
    pub fn open(path: &str) -> io::Result<Self> {
        Self::open_at(path, XV11_BAUD)
    }

    /// As [`DeviceLink::open_at`], the error naming `path`: `PATH: why` when it is not a
    /// terminal device, else `PATH: cannot open: why`.
    ///
    /// # Errors
    /// As [`DeviceLink::open`].
    pub fn open_named(path: &std::path::Path, baud: u32) -> io::Result<Self> {
        Self::open_at(&path.to_string_lossy(), baud).map_err(|err| {
            let shown = path.display();
            match err.kind() {
                io::ErrorKind::InvalidInput => {
                    io::Error::new(err.kind(), format!("{shown}: {err}"))
                }
                kind => io::Error::new(kind, format!("{shown}: cannot open: {err}")),
            }
        })
    }

    /// Opens `path` at `baud`, 8N1 (the unit's speed: `UnitSpec::baud`).
    ///
    /// # Errors
    /// As [`DeviceLink::open`].
    pub fn open_at(path: &str, baud: u32) -> io::Result<Self> {
        let not_a_device = |what: &str| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("not a serial device or pseudo-terminal ({what})"),
            )
        };
        // Only a character device can be a terminal; anything else is named before it is opened
        // (opening a FIFO could wait for a reader).
        let kind = std::fs::metadata(path)?.file_type();
        if !kind.is_char_device() {
            return Err(not_a_device(describe_file_type(kind)));
        }
        let port = serialport::new(path, baud)
            .data_bits(DataBits::Eight)
            .parity(Parity::None)
            .stop_bits(StopBits::One)
            .flow_control(FlowControl::None)
            .timeout(Duration::ZERO)
            .open_native()
            .map_err(|err| {
                if is_terminal(path) == Some(false) {
                    not_a_device("a character device that is not a terminal")
                } else {
                    io::Error::from(err)
                }
            })?;
        fcntl(port.as_raw_fd(), FcntlArg::F_SETFD(FdFlag::FD_CLOEXEC)).map_err(io::Error::from)?;
        Ok(Self { port })
    }
}

/// Whether the device at `path` is a terminal; `None` when it cannot be opened to tell.
fn is_terminal(path: &str) -> Option<bool> {
    use std::io::IsTerminal as _;
    use std::os::unix::fs::OpenOptionsExt as _;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(nix::libc::O_NONBLOCK | nix::libc::O_NOCTTY)
        .open(path)
        .ok()
        .map(|file| file.is_terminal())
}

/// What a file that is not a character device is, in words.
fn describe_file_type(kind: std::fs::FileType) -> &'static str {
    if kind.is_file() {
        "a regular file"
    } else if kind.is_dir() {
        "a directory"
    } else if kind.is_fifo() {
        "a named pipe"
    } else if kind.is_socket() {
        "a socket"
    } else if kind.is_block_device() {
        "a block device"
    } else {
        "not a device"
    }
}

impl Write for DeviceLink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.port.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl SerialLink for DeviceLink {
    fn read_host(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        crate::link::read_now(&mut self.port, buf)
    }

    fn backlog(&mut self) -> io::Result<usize> {
        Ok(self.port.bytes_to_write().map_err(io::Error::from)? as usize)
    }

    fn discard_backlog(&mut self) -> io::Result<()> {
        self.port
            .clear(ClearBuffer::Output)
            .map_err(io::Error::from)
    }
}
