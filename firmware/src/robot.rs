//! The robot's command port: a text line out, a reply of `\r\n`-separated lines back, ending
//! with Ctrl-Z (0x1A); the first line echoes the request.

use std::io::{self, ErrorKind, Read, Write};
use std::time::{Duration, Instant};

use serialport::SerialPort;

/// How long a reply may take.
const REPLY_TIMEOUT: Duration = Duration::from_secs(2);

pub struct RobotPort {
    port: Box<dyn SerialPort>,
}

impl RobotPort {
    pub fn open(path: &str) -> io::Result<Self> {
        let port = serialport::new(path, 115_200)
            .timeout(Duration::from_millis(100))
            .open()
            .map_err(io::Error::from)?;
        Ok(Self { port })
    }

    /// Sends one request and returns the reply's lines after the echo. A reply that says
    /// `Error:` or `Unknown Cmd` is an error.
    pub fn request(&mut self, line: &str) -> io::Result<Vec<String>> {
        self.port.write_all(format!("{line}\n").as_bytes())?;
        let mut reply = Vec::new();
        let deadline = Instant::now() + REPLY_TIMEOUT;
        let mut buf = [0u8; 1024];
        while !reply.ends_with(&[0x1A]) {
            if Instant::now() > deadline {
                return Err(io::Error::new(
                    ErrorKind::TimedOut,
                    format!("no reply to `{line}`"),
                ));
            }
            match self.port.read(&mut buf) {
                Ok(0) => {
                    return Err(io::Error::new(
                        ErrorKind::UnexpectedEof,
                        "robot port closed",
                    ))
                }
                Ok(n) => reply.extend_from_slice(&buf[..n]),
                Err(e) if e.kind() == ErrorKind::TimedOut || e.kind() == ErrorKind::Interrupted => {
                }
                Err(e) => return Err(e),
            }
        }
        reply.pop();
        let text = String::from_utf8_lossy(&reply);
        let lines: Vec<String> = text
            .split("\r\n")
            .skip(1)
            .filter(|l| !l.is_empty())
            .map(str::to_string)
            .collect();
        if let Some(error) = lines
            .iter()
            .find(|l| l.starts_with("Error:") || l.starts_with("Unknown Cmd"))
        {
            return Err(io::Error::other(error.clone()));
        }
        Ok(lines)
    }

    /// The wheel encoders' travel, mm (`GetMotors`).
    pub fn wheel_positions_mm(&mut self) -> io::Result<[i64; 2]> {
        let lines = self.request("GetMotors LeftWheel RightWheel")?;
        let value = |name: &str| {
            lines
                .iter()
                .find_map(|l| l.strip_prefix(name)?.strip_prefix(',')?.trim().parse().ok())
                .ok_or_else(|| io::Error::other(format!("GetMotors without {name}")))
        };
        Ok([
            value("LeftWheel_PositionInMM")?,
            value("RightWheel_PositionInMM")?,
        ])
    }
}
