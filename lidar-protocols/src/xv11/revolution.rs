//! Grouping decoded packets into revolutions of 360 readings.

use super::packet::{Packet, Reading, PACKETS_PER_REVOLUTION, READINGS_PER_PACKET};

/// One revolution as received: the packets that arrived, by index, and which are missing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Revolution {
    /// Counts revolutions from 0 at the start of the stream (a partial first one included).
    pub number: u64,
    /// `packets[i]` is the packet with index `i` (angles `4i..=4i+3`), `None` when it was lost.
    pub packets: [Option<Packet>; PACKETS_PER_REVOLUTION],
}

impl Revolution {
    /// A revolution with no packets yet.
    #[must_use]
    pub const fn empty(number: u64) -> Self {
        Self {
            number,
            packets: [None; PACKETS_PER_REVOLUTION],
        }
    }

    /// Whether all 90 packets arrived.
    #[must_use]
    pub fn is_complete(&self) -> bool {
        self.packets.iter().all(Option::is_some)
    }

    /// How many of the 90 packets arrived.
    #[must_use]
    pub fn packet_count(&self) -> usize {
        self.packets.iter().flatten().count()
    }

    /// The indices (0..=89) of the packets that did not arrive.
    pub fn missing_indices(&self) -> impl Iterator<Item = u8> + '_ {
        (0u8..)
            .zip(&self.packets)
            .filter_map(|(index, packet)| packet.is_none().then_some(index))
    }

    /// The reading at `angle_deg` (0..=359), `None` when its packet was lost or the angle is
    /// out of range.
    #[must_use]
    pub fn reading(&self, angle_deg: u16) -> Option<&Reading> {
        let angle = usize::from(angle_deg);
        let packet = self.packets.get(angle / READINGS_PER_PACKET)?.as_ref()?;
        packet.readings.get(angle % READINGS_PER_PACKET)
    }

    /// Every reading that arrived with its angle in degrees, in increasing angle.
    pub fn readings(&self) -> impl Iterator<Item = (u16, &Reading)> + '_ {
        self.packets
            .iter()
            .flatten()
            .flat_map(|packet| (packet.first_angle_deg()..).zip(&packet.readings))
    }

    /// The mean motor speed over the packets that arrived, `None` when none did.
    #[must_use]
    pub fn rpm_mean(&self) -> Option<f64> {
        let (sum, count) = self
            .packets
            .iter()
            .flatten()
            .fold((0.0, 0u32), |(sum, count), packet| {
                (sum + packet.rpm(), count + 1)
            });
        (count > 0).then(|| sum / f64::from(count))
    }
}

/// Groups consecutive packets into [`Revolution`]s.
///
/// A revolution ends when its last packet (index 89) arrives, or when a packet's index is not
/// above the previous one's (the stream wrapped past a lost index 89, or repeated itself); that
/// packet then opens the next revolution.
///
/// ```
/// use hilsim_lidar_protocols::xv11::{Packet, RevolutionAssembler};
///
/// let mut assembler = RevolutionAssembler::new();
/// let mut done = Vec::new();
/// for index in (80..90).chain(0..10).filter(|&i| i != 3) {
///     done.extend(assembler.push(Packet { index, ..Packet::default() }));
/// }
/// done.extend(assembler.finish());
/// assert_eq!(done.len(), 2);
/// assert_eq!(done[0].packet_count(), 10);
/// assert_eq!(done[1].missing_indices().take(2).collect::<Vec<_>>(), vec![3, 10]);
/// ```
#[derive(Debug, Clone, Default)]
pub struct RevolutionAssembler {
    current: Option<Revolution>,
    previous_index: Option<u8>,
    next_number: u64,
}

impl RevolutionAssembler {
    /// An assembler that has seen nothing.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            current: None,
            previous_index: None,
            next_number: 0,
        }
    }

    /// Adds the next packet of the stream; returns the revolution it completes, if any.
    /// Indices are taken modulo 90, as the encoder does.
    pub fn push(&mut self, packet: Packet) -> Option<Revolution> {
        const LAST_INDEX: u8 = PACKETS_PER_REVOLUTION as u8 - 1;
        let index = packet.index % PACKETS_PER_REVOLUTION as u8;
        let wrapped = self
            .previous_index
            .is_some_and(|previous| index <= previous);
        let mut finished = if wrapped { self.current.take() } else { None };
        if self.current.is_none() {
            self.current = Some(Revolution::empty(self.next_number));
            self.next_number += 1;
        }
        if let Some(current) = self.current.as_mut() {
            current.packets[usize::from(index)] = Some(Packet { index, ..packet });
        }
        self.previous_index = Some(index);
        if index == LAST_INDEX && finished.is_none() {
            finished = self.current.take();
            self.previous_index = None;
        }
        finished
    }

    /// Ends the stream: returns the revolution in progress, if it has any packet.
    pub fn finish(&mut self) -> Option<Revolution> {
        self.previous_index = None;
        self.current.take()
    }

    /// The number the revolution in progress has (or the next one will get).
    #[must_use]
    pub fn current_number(&self) -> u64 {
        self.current
            .as_ref()
            .map_or(self.next_number, |revolution| revolution.number)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn packet(index: u8) -> Packet {
        Packet {
            index,
            rpm_fixed: u16::from(index) * 64,
            readings: [Reading::distance(u16::from(index), 1); 4],
        }
    }

    fn assemble(indices: impl IntoIterator<Item = u8>) -> Vec<Revolution> {
        let mut assembler = RevolutionAssembler::new();
        let mut done: Vec<Revolution> = indices
            .into_iter()
            .filter_map(|index| assembler.push(packet(index)))
            .collect();
        done.extend(assembler.finish());
        done
    }

    #[test]
    fn complete_revolutions_are_emitted_on_their_last_packet() {
        let mut assembler = RevolutionAssembler::new();
        for index in 0..89 {
            assert_eq!(assembler.push(packet(index)), None);
        }
        let revolution = assembler.push(packet(89)).expect("index 89 completes it");
        assert!(revolution.is_complete());
        assert_eq!(revolution.number, 0);
        assert_eq!(revolution.reading(359), Some(&Reading::distance(89, 1)));
        assert_eq!(revolution.reading(360), None);
        let angles: Vec<u16> = revolution.readings().map(|(angle, _)| angle).collect();
        assert_eq!(angles, (0..360).collect::<Vec<_>>());
        assert_eq!(revolution.rpm_mean(), Some(44.5));
        assert_eq!(assembler.current_number(), 1);
        assert_eq!(assembler.finish(), None);
    }

    #[test]
    fn lost_last_packet_ends_the_revolution_at_the_wrap() {
        let revolutions = assemble((0..89).chain(0..5));
        assert_eq!(revolutions.len(), 2);
        assert_eq!(
            revolutions[0].missing_indices().collect::<Vec<_>>(),
            vec![89]
        );
        assert_eq!(revolutions[1].number, 1);
        assert_eq!(revolutions[1].packet_count(), 5);
        assert_eq!(revolutions[1].reading(100), None);
    }

    #[test]
    fn partial_first_revolution_and_repeats() {
        let revolutions = assemble([50, 51, 51, 89, 89]);
        let counts: Vec<usize> = revolutions.iter().map(Revolution::packet_count).collect();
        assert_eq!(counts, vec![2, 2, 1]);
        let numbers: Vec<u64> = revolutions.iter().map(|r| r.number).collect();
        assert_eq!(numbers, vec![0, 1, 2]);
        assert_eq!(Revolution::empty(0).rpm_mean(), None);
    }
}
