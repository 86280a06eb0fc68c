//! Four consecutive readings into one packet, as the lidar takes them.

use hilsim_lidar_emulator::neato_packet::{rpm_to_fixed, Packet, Reading, READINGS_PER_PACKET};
use hilsim_lidar_emulator::wire::to_wire;
use hilsim_lidar_emulator::LidarReading;

/// Four consecutive readings into one packet, as the lidar takes them.
#[derive(Default)]
pub(super) struct PacketBuilder {
    rev: u64,
    readings: [Reading; READINGS_PER_PACKET],
    filled: usize,
}

impl PacketBuilder {
    pub(super) fn push(&mut self, reading: &LidarReading, rpm: f64) -> Option<Packet> {
        let slot = usize::from(reading.index) % READINGS_PER_PACKET;
        if slot == 0 || reading.rev != self.rev {
            self.rev = reading.rev;
            self.filled = 0;
        }
        self.readings[slot] = to_wire(reading);
        self.filled += 1;
        (slot == READINGS_PER_PACKET - 1 && self.filled == READINGS_PER_PACKET).then(|| Packet {
            index: u8::try_from(usize::from(reading.index) / READINGS_PER_PACKET).unwrap_or(0),
            rpm_fixed: rpm_to_fixed(rpm),
            readings: self.readings,
        })
    }
}
