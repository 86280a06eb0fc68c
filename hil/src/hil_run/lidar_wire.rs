//! The lidar port of a firmware-in-the-loop run: the XV-11's packets built four readings at a
//! time and sent one by one as each falls due, or another unit's protocol through its
//! [`UnitStreamer`], which also answers the firmware's commands to the unit.

use std::collections::VecDeque;
use std::io;
use std::os::unix::io::{AsRawFd, RawFd};
use std::time::{Duration, Instant};

use hilsim_lidar_emulator::lidar::reading_period_s;
use hilsim_lidar_emulator::neato_packet::Packet;
use hilsim_lidar_emulator::wire::to_unit_reading;
use hilsim_lidar_emulator::LidarReading;
use hilsim_lidar_protocols::{LidarModel, UnitSpec};

use super::packets::PacketBuilder;
use crate::faults::{FaultCounts, WireFaults};
use crate::link::SerialLink;
use crate::pty::PtyLink;
use crate::streamer::{Pacing, StreamStats, Streamer};
use crate::unit_streamer::UnitStreamer;

/// The lidar port's stream.
pub(super) enum LidarWire {
    /// The Neato XV-11's packets, each due when its last reading's period has passed.
    Xv11 {
        streamer: Streamer<PtyLink>,
        packets: PacketBuilder,
        due: VecDeque<(f64, Packet)>,
    },
    /// Another unit, which may wait for the firmware's start command.
    Unit {
        streamer: UnitStreamer<PtyLink>,
        spec: &'static UnitSpec,
    },
}

impl LidarWire {
    /// The stream of `model` over `link`, its wire faults applied.
    pub(super) fn new(link: PtyLink, model: LidarModel, faults: Option<WireFaults>) -> Self {
        match hilsim_lidar_protocols::unit_for(model) {
            None => LidarWire::Xv11 {
                streamer: Streamer::new(link, Pacing::Realtime).with_faults(faults),
                packets: PacketBuilder::default(),
                due: VecDeque::new(),
            },
            Some(unit) => LidarWire::Unit {
                streamer: UnitStreamer::new(link, unit, Pacing::Realtime).with_faults(faults),
                spec: model.spec(),
            },
        }
    }

    /// Starts the clock: simulated t = 0 at `origin`.
    pub(super) fn start(&mut self, origin: Instant) {
        if let LidarWire::Unit { streamer, .. } = self {
            streamer.start_clock(origin);
        }
    }

    /// Takes the next reading, turning at `rpm`.
    pub(super) fn take(&mut self, reading: &LidarReading, rpm: f64) {
        match self {
            LidarWire::Xv11 { packets, due, .. } => {
                // A packet leaves when its last reading's period has passed (as
                // `Streamer::send` paces them).
                if let Some(packet) = packets.push(reading, rpm) {
                    due.push_back((reading.t_s + reading_period_s(rpm), packet));
                }
            }
            LidarWire::Unit { streamer, spec } => streamer.queue(&to_unit_reading(reading, spec)),
        }
    }

    /// Answers the firmware's commands to the unit, and writes every packet due by `now`
    /// (the wall-clock instant of simulated `now_s`).
    pub(super) fn send_due(&mut self, origin: Instant, now: Instant) -> io::Result<()> {
        match self {
            LidarWire::Xv11 { streamer, due, .. } => {
                while let Some(&(due_s, packet)) = due.front() {
                    let at = origin + Duration::from_secs_f64(due_s.max(0.0));
                    if at > now {
                        break;
                    }
                    due.pop_front();
                    streamer.send_packet(&packet, at, due_s)?;
                }
                Ok(())
            }
            LidarWire::Unit { streamer, .. } => {
                streamer.answer_host()?;
                streamer.send_due(now.duration_since(origin).as_secs_f64())
            }
        }
    }

    /// When the next packet is due, simulated seconds.
    pub(super) fn next_due_s(&self) -> Option<f64> {
        match self {
            LidarWire::Xv11 { due, .. } => due.front().map(|&(due_s, _)| due_s),
            LidarWire::Unit { streamer, .. } => streamer.next_due_s(),
        }
    }

    /// The descriptor to wait on for the firmware's commands to the unit (an XV-11 takes none).
    pub(super) fn command_fd(&mut self) -> Option<RawFd> {
        match self {
            LidarWire::Xv11 { .. } => None,
            LidarWire::Unit { streamer, .. } => Some(streamer.link().master().as_raw_fd()),
        }
    }

    /// Whether the unit waits for a command before it sends readings, and has had none.
    pub(super) fn waiting_for_start(&self) -> bool {
        match self {
            LidarWire::Xv11 { .. } => false,
            LidarWire::Unit { streamer, .. } => {
                !streamer.scanning() && streamer.stats().bytes_written == 0
            }
        }
    }

    /// What the stream did so far.
    pub(super) fn stats(&self) -> &StreamStats {
        match self {
            LidarWire::Xv11 { streamer, .. } => streamer.stats(),
            LidarWire::Unit { streamer, .. } => streamer.stats(),
        }
    }

    /// What the wire's faults did so far.
    pub(super) fn fault_counts(&self) -> Option<FaultCounts> {
        match self {
            LidarWire::Xv11 { streamer, .. } => streamer.fault_counts(),
            LidarWire::Unit { streamer, .. } => streamer.fault_counts(),
        }
    }

    /// Bytes written but not yet read by the firmware.
    pub(super) fn backlog(&mut self) -> io::Result<usize> {
        match self {
            LidarWire::Xv11 { streamer, .. } => streamer.link().backlog(),
            LidarWire::Unit { streamer, .. } => streamer.link().backlog(),
        }
    }

    /// Whether this is the XV-11's stream (whose revolutions the robot port's `GetLDSScan`
    /// reports).
    pub(super) fn is_xv11(&self) -> bool {
        matches!(self, LidarWire::Xv11 { .. })
    }
}
