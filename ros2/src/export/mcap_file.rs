//! The MCAP file being written: its channels (one a topic, with the `ros2msg` schema of its
//! type and rosbag2's QoS), each message CDR-encoded into a reused buffer, and the writer's
//! failures in the system's words. Kept apart from the messages, which know nothing of MCAP.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use mcap::records::MessageHeader;
use mcap::write::NoSeek;

use super::options::ExportReport;
use crate::cdr::encode;
use crate::definitions::schema_text;
use crate::Error;

/// rosbag2's QoS for a channel: `/tf_static` is latched (transient local), so a player sends it
/// to subscribers that join late; the rest reliable and volatile.
fn qos(latched: bool) -> String {
    let never = "    sec: 2147483647\n    nsec: 4294967295\n";
    format!(
        "- history: 3\n  depth: 0\n  reliability: 1\n  durability: {}\n  deadline:\n{never}  \
         lifespan:\n{never}  liveliness: 1\n  liveliness_lease_duration:\n{never}  \
         avoid_ros_namespace_conventions: false\n",
        if latched { 1 } else { 2 }
    )
}

/// An MCAP file being written: channels by topic and a reused message buffer.
pub(super) struct Bag<'p, W: Write> {
    pub(super) writer: mcap::Writer<NoSeek<W>>,
    pub(super) out: &'p Path,
    pub(super) channels: BTreeMap<&'static str, u16>,
    pub(super) sequence: u32,
    pub(super) buffer: Vec<u8>,
    pub(super) report: ExportReport,
}

impl<W: Write> Bag<'_, W> {
    pub(super) fn fail(&self, err: mcap::McapError) -> Error {
        mcap_failure(self.out, err)
    }

    fn channel(&mut self, topic: &'static str, type_name: &str) -> Result<u16, mcap::McapError> {
        if let Some(&id) = self.channels.get(topic) {
            return Ok(id);
        }
        let text = schema_text(type_name).unwrap_or_default();
        let schema = self
            .writer
            .add_schema(type_name, "ros2msg", text.as_bytes())?;
        let metadata = BTreeMap::from([(
            "offered_qos_profiles".to_string(),
            qos(topic == "/tf_static"),
        )]);
        let id = self.writer.add_channel(schema, topic, "cdr", &metadata)?;
        self.channels.insert(topic, id);
        Ok(id)
    }

    pub(super) fn write<T: serde::Serialize>(
        &mut self,
        topic: &'static str,
        type_name: &str,
        t_ns: i64,
        message: &T,
    ) -> Result<(), Error> {
        self.write_message(topic, type_name, t_ns, message)
            .map_err(|err| self.fail(err))
    }

    fn write_message<T: serde::Serialize>(
        &mut self,
        topic: &'static str,
        type_name: &str,
        t_ns: i64,
        message: &T,
    ) -> Result<(), mcap::McapError> {
        let channel_id = self.channel(topic, type_name)?;
        encode(message, &mut self.buffer);
        let time = u64::try_from(t_ns).unwrap_or(0);
        self.sequence = self.sequence.wrapping_add(1);
        self.writer.write_to_known_channel(
            &MessageHeader {
                channel_id,
                sequence: self.sequence,
                log_time: time,
                publish_time: time,
            },
            &self.buffer,
        )?;
        *self.report.messages.entry(topic.to_string()).or_insert(0) += 1;
        Ok(())
    }
}

/// Writing `out` failed: an I/O error in the system's words ("No space left on device", a pipe
/// whose reader left), as the recording crate reports one, not the mcap crate's wrapper's.
pub(super) fn mcap_failure(out: &Path, err: mcap::McapError) -> Error {
    match err {
        mcap::McapError::Io(io) => Error::Recording(hilsim_recording::Error {
            path: out.to_path_buf(),
            line: None,
            kind: hilsim_recording::ErrorKind::Io(io),
        }),
        other => Error::bag(out, other.to_string()),
    }
}
