//! An existing serial device (a USB adapter, or a pty another program made), opened at the
//! XV-11's line settings: 115200 baud, 8N1, no flow control.

use std::io::{self, Write};
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
    /// Opens `path` at 115200 8N1.
    ///
    /// # Errors
    /// The device cannot be opened or configured.
    pub fn open(path: &str) -> io::Result<Self> {
        let port = serialport::new(path, XV11_BAUD)
            .data_bits(DataBits::Eight)
            .parity(Parity::None)
            .stop_bits(StopBits::One)
            .flow_control(FlowControl::None)
            .timeout(Duration::ZERO)
            .open_native()
            .map_err(io::Error::from)?;
        fcntl(port.as_raw_fd(), FcntlArg::F_SETFD(FdFlag::FD_CLOEXEC)).map_err(io::Error::from)?;
        Ok(Self { port })
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
    fn backlog(&mut self) -> io::Result<usize> {
        Ok(self.port.bytes_to_write().map_err(io::Error::from)? as usize)
    }

    fn discard_backlog(&mut self) -> io::Result<()> {
        self.port
            .clear(ClearBuffer::Output)
            .map_err(io::Error::from)
    }
}
