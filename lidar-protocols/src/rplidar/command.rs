//! Requests: the host's `A5 cmd [size payload checksum]`, built and parsed.

use super::SYNC_BYTE;

/// The largest payload a request carries (its size field is one byte).
pub const MAX_PAYLOAD_LEN: usize = 255;

/// The bytes of a request: `A5 cmd`, and for a command with bit 7 set `size payload checksum`,
/// the checksum the XOR of every byte before it (protocol v2.1, "Request packets' format").
/// A payload longer than [`MAX_PAYLOAD_LEN`] is cut there.
#[must_use]
pub fn request(cmd: u8, payload: &[u8]) -> Vec<u8> {
    let mut bytes = vec![SYNC_BYTE, cmd];
    if cmd & 0x80 != 0 {
        let payload = &payload[..payload.len().min(MAX_PAYLOAD_LEN)];
        // Cut to at most 255 above, so the size fits its byte.
        bytes.push(payload.len() as u8);
        bytes.extend_from_slice(payload);
        let checksum = bytes.iter().fold(0, |acc, b| acc ^ b);
        bytes.push(checksum);
    }
    bytes
}

/// One request as the unit received it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// The command byte.
    pub cmd: u8,
    /// Its payload (empty for a command without bit 7).
    pub payload: Vec<u8>,
}

#[derive(Debug, Clone)]
enum State {
    Idle,
    Sync,
    Size { cmd: u8 },
    Payload { cmd: u8, size: usize },
    Checksum { cmd: u8 },
}

/// The unit's request parser: bytes in any pieces, requests out; bytes outside a request are
/// dropped, and a request whose checksum fails is dropped whole.
#[derive(Debug, Clone)]
pub(crate) struct RequestParser {
    state: State,
    payload: Vec<u8>,
    xor: u8,
}

impl RequestParser {
    pub(crate) fn new() -> Self {
        Self {
            state: State::Idle,
            payload: Vec::new(),
            xor: 0,
        }
    }

    /// Takes one byte; returns the request it completes.
    pub(crate) fn push(&mut self, byte: u8) -> Option<Request> {
        match self.state {
            State::Idle => {
                if byte == SYNC_BYTE {
                    self.state = State::Sync;
                }
                None
            }
            // A repeated sync byte is taken as the start of the request (no command is 0xA5).
            State::Sync if byte == SYNC_BYTE => None,
            State::Sync if byte & 0x80 == 0 => {
                self.state = State::Idle;
                Some(Request {
                    cmd: byte,
                    payload: Vec::new(),
                })
            }
            State::Sync => {
                self.state = State::Size { cmd: byte };
                self.xor = SYNC_BYTE ^ byte;
                self.payload.clear();
                None
            }
            State::Size { cmd } => {
                self.xor ^= byte;
                self.state = if byte == 0 {
                    State::Checksum { cmd }
                } else {
                    State::Payload {
                        cmd,
                        size: usize::from(byte),
                    }
                };
                None
            }
            State::Payload { cmd, size } => {
                self.xor ^= byte;
                self.payload.push(byte);
                if self.payload.len() == size {
                    self.state = State::Checksum { cmd };
                }
                None
            }
            State::Checksum { cmd } => {
                self.state = State::Idle;
                (byte == self.xor).then(|| Request {
                    cmd,
                    payload: std::mem::take(&mut self.payload),
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(bytes: &[u8]) -> Vec<Request> {
        let mut parser = RequestParser::new();
        bytes.iter().filter_map(|&b| parser.push(b)).collect()
    }

    #[test]
    fn request_bytes_match_the_drivers() {
        // rplidar-roboticia's `_set_pwm(660)`: A5 F0 02 94 02 checksum.
        assert_eq!(
            request(0xF0, &660u16.to_le_bytes()),
            [
                0xA5,
                0xF0,
                0x02,
                0x94,
                0x02,
                0xA5 ^ 0xF0 ^ 0x02 ^ 0x94 ^ 0x02
            ]
        );
        assert_eq!(request(0x20, &[1, 2]), [0xA5, 0x20]);
        // rplidar-roboticia's express start: five zero bytes, checksum 0x22.
        assert_eq!(
            request(0x82, &[0; 5]),
            [0xA5, 0x82, 0x05, 0, 0, 0, 0, 0, 0x22]
        );
    }

    #[test]
    fn parser_finds_requests_among_garbage_and_drops_bad_checksums() {
        let mut wire = vec![0x00, 0x5A, 0xA5, 0xA5, 0x50, 0x13];
        let mut bad = request(0xF0, &[1, 2]);
        *bad.last_mut().unwrap() ^= 1;
        wire.extend_from_slice(&bad);
        wire.extend_from_slice(&request(0x82, &[0; 5]));
        wire.extend_from_slice(&[0xA5, 0x25]);
        let got = parse(&wire);
        let cmds: Vec<u8> = got.iter().map(|r| r.cmd).collect();
        assert_eq!(cmds, [0x50, 0x82, 0x25]);
        assert_eq!(got[1].payload, [0; 5]);
    }
}
