//! The Neato XV-11 lidar serial packet codec (firmware 2.4 / 2.6), as described in
//! `docs/formats/neato-xv11.md`.
//!
//! A pure state machine: nothing here opens a port, reads a clock or prints. The serial link
//! only moves bytes; this module turns readings into bytes ([`Packet::encode`],
//! [`encode_revolution`]) and bytes back into packets ([`Decoder::push`]), then into whole
//! revolutions ([`RevolutionAssembler`]) and the counts `hilsim decode` reports
//! ([`PacketSummary`], [`DecoderStats`]).
//!
//! ```
//! use hilsim_lidar_protocols::xv11::{encode_revolution, Decoder, Reading};
//!
//! let mut readings = [Reading::distance(1000, 200); 360];
//! readings[90] = Reading::error(0x35);
//! let mut wire = Vec::new();
//! encode_revolution(&readings, 300.0, &mut wire);
//! assert_eq!(wire.len(), 1980);
//!
//! let mut decoder = Decoder::new();
//! let packets: Vec<_> = decoder.feed(&wire).collect();
//! assert_eq!(packets.len(), 90);
//! assert_eq!(packets[22].readings[2].error_code(), Some(0x35)); // angle 90 = 4 * 22 + 2
//! assert_eq!(packets[0].rpm(), 300.0);
//! assert_eq!(decoder.stats().bad_checksum, 0);
//! ```

mod decoder;
mod packet;
mod revolution;
mod summary;

pub use decoder::{Decoder, DecoderStats};
pub use packet::{
    checksum, encode_revolution, rpm_to_fixed, Packet, PacketError, Reading, INDEX_BASE,
    MAX_DISTANCE_MM, PACKETS_PER_REVOLUTION, PACKET_LEN, READINGS_PER_PACKET,
    READINGS_PER_REVOLUTION, REVOLUTION_LEN, START_BYTE,
};
pub use revolution::{Revolution, RevolutionAssembler};
pub use summary::PacketSummary;
