//! A ROS 1 bag (rosbag format 2.0, <http://wiki.ros.org/Bags/Format/2.0>) read as a stream of
//! records: the file's records one at a time, a chunk decompressed (none, bz2, lz4) and its
//! records read before the next, so memory is bounded by one chunk whatever the bag's size.
//!
//! A record is a `uint32` header length, the header's fields (each a `uint32` length and
//! `name=value`, the `op` field saying what the record is), a `uint32` data length and the
//! data. A bag that is damaged after its start (a recording cut short, a chunk that does not
//! decompress, a record that does not parse) is read as far as it goes, its damage counted in a
//! [`Damage`] for the import's notes; only a file that is not a bag at all is an error.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use hilsim_recording::printable;

use crate::Error;

/// The first line of a bag of format 2.0.
const MAGIC: &[u8] = b"#ROSBAG V2.0\n";

/// The largest record header read: a connection's or a chunk's is tens of bytes.
const HEADER_LIMIT: u32 = 1 << 20;

/// The largest record read whole outside a chunk (a chunk's compressed bytes, a message, a
/// connection with its message definition): as an MCAP bag's ([`crate::bag::CHUNK_LIMIT`]'s
/// half).
const RECORD_LIMIT: u32 = 64 << 20;

/// The most a chunk may hold uncompressed (its header's `size`, checked before it is
/// decompressed; a chunk that inflates to more is stopped there): `rosbag record` writes chunks
/// of 768 KiB (its `--chunksize` default), and a chunk must have room for the largest message.
/// An import holds a chunk's compressed and uncompressed bytes, so at most 192 MiB of chunk.
pub const CHUNK_LIMIT: u32 = 128 << 20;

/// The most distinct connections read (a bag's are its publishers, tens); with names of at most
/// [`crate::bag::NAME_LIMIT`] bytes, what is kept of them stays small.
const CONNECTION_LIMIT: usize = 1 << 16;

/// The record kinds (the header's `op`).
mod op {
    pub const MESSAGE_DATA: u8 = 0x02;
    pub const BAG_HEADER: u8 = 0x03;
    pub const INDEX_DATA: u8 = 0x04;
    pub const CHUNK: u8 = 0x05;
    pub const CHUNK_INFO: u8 = 0x06;
    pub const CONNECTION: u8 = 0x07;
}

/// A connection of a bag: a topic as one publisher wrote it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Connection {
    /// The connection's id in its bag.
    pub id: u32,
    /// The topic, e.g. `/scan`.
    pub topic: String,
    /// The message type, e.g. `sensor_msgs/LaserScan`.
    pub type_name: String,
}

/// A record of interest in a bag's stream.
pub(crate) enum Item<'a> {
    /// A connection (inside the chunk of its first message, and again in the index).
    Connection(Connection),
    /// A message.
    Message {
        conn: u32,
        /// Receive time, ns since the epoch.
        time_ns: i64,
        data: &'a [u8],
    },
}

/// What of a bag could not be read: counted, so the import goes on and says so.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Damage {
    /// Chunks skipped whole (they did not decompress, or declared more than the limit), and why
    /// the first was.
    pub chunks: u64,
    /// Why the first skipped chunk was.
    pub first_chunk: Option<String>,
    /// Chunks whose records stopped parsing part-way (the rest of the chunk skipped), and
    /// records outside chunks skipped.
    pub records: u64,
    /// Why the first such record did not parse.
    pub first_record: Option<String>,
    /// Where and why the file stopped being readable, when it did before its end (a recording
    /// cut short).
    pub stopped: Option<String>,
    /// Chunks of each compression not read (neither none, bz2 nor lz4).
    pub compressions: BTreeMap<String, u64>,
}

impl Damage {
    /// Sentences for people.
    #[must_use]
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        if self.chunks > 0 {
            notes.push(format!(
                "{} chunks of the bag skipped, damaged (the first: {})",
                self.chunks,
                self.first_chunk.as_deref().unwrap_or("")
            ));
        }
        for (name, count) in &self.compressions {
            notes.push(format!(
                "{count} chunks compressed with `{}` skipped: hilsim reads none, bz2 and lz4",
                printable(name)
            ));
        }
        if self.records > 0 {
            notes.push(format!(
                "{} chunks read only up to a damaged record, or records skipped (the first: {})",
                self.records,
                self.first_record.as_deref().unwrap_or("")
            ));
        }
        if let Some(stopped) = &self.stopped {
            notes.push(format!("the bag was read up to {stopped}"));
        }
        notes
    }
}

/// Whether the file at `path` begins as a ROS 1 bag does (any version).
#[must_use]
pub fn is_ros1_bag(path: &Path) -> bool {
    let mut head = Vec::with_capacity(9);
    let read = File::open(path).and_then(|f| f.take(9).read_to_end(&mut head));
    read.is_ok() && head == b"#ROSBAG V"
}

/// A header field: its name and value.
type Field<'a> = (&'a [u8], &'a [u8]);

/// The fields of a record header (or of a connection's data): `name=value` each after its
/// `uint32` length.
fn fields(mut bytes: &[u8]) -> Result<Vec<Field<'_>>, String> {
    let mut out = Vec::new();
    while !bytes.is_empty() {
        let Some((len, rest)) = bytes.split_first_chunk::<4>() else {
            return Err("a header field's length cut short".into());
        };
        let len = usize::try_from(u32::from_le_bytes(*len)).unwrap_or(usize::MAX);
        if len > rest.len() {
            return Err(format!(
                "a header field of {len} bytes in the {} left",
                rest.len()
            ));
        }
        let (field, rest) = rest.split_at(len);
        let Some(eq) = field.iter().position(|&b| b == b'=') else {
            return Err("a header field without `=`".into());
        };
        out.push((&field[..eq], &field[eq + 1..]));
        bytes = rest;
    }
    Ok(out)
}

fn field<'a>(fields: &[Field<'a>], name: &str) -> Option<&'a [u8]> {
    fields
        .iter()
        .find(|(n, _)| *n == name.as_bytes())
        .map(|(_, v)| *v)
}

fn field_u32(fields: &[Field<'_>], name: &str) -> Result<u32, String> {
    field(fields, name)
        .and_then(|v| v.try_into().ok())
        .map(u32::from_le_bytes)
        .ok_or_else(|| format!("no 4-byte `{name}` field"))
}

fn field_u64(fields: &[Field<'_>], name: &str) -> Result<u64, String> {
    field(fields, name)
        .and_then(|v| v.try_into().ok())
        .map(u64::from_le_bytes)
        .ok_or_else(|| format!("no 8-byte `{name}` field"))
}

fn name(bytes: &[u8], what: &str) -> Result<String, String> {
    if bytes.len() > crate::bag::NAME_LIMIT {
        return Err(format!(
            "a {what} of {} bytes, beyond the {} a name may have",
            bytes.len(),
            crate::bag::NAME_LIMIT
        ));
    }
    Ok(String::from_utf8_lossy(bytes).into_owned())
}

/// A record's op, from its header fields.
fn op_of(fields: &[Field<'_>]) -> Result<u8, String> {
    match field(fields, "op") {
        Some([op]) => Ok(*op),
        _ => Err("a record without its one-byte `op`".into()),
    }
}

/// A connection record: the topic from its header, the type from its data (the publisher's
/// connection header).
fn connection(header: &[Field<'_>], data: &[u8]) -> Result<Connection, String> {
    let id = field_u32(header, "conn")?;
    let topic = field(header, "topic").ok_or("a connection without its topic")?;
    let data = fields(data)?;
    let type_name = field(&data, "type").ok_or("a connection without its type")?;
    Ok(Connection {
        id,
        topic: name(topic, "topic")?,
        type_name: name(type_name, "type name")?,
    })
}

/// A message record's connection and time.
fn message_of(header: &[Field<'_>]) -> Result<(u32, i64), String> {
    let conn = field_u32(header, "conn")?;
    let time = field_u64(header, "time")?;
    // `time`: uint32 seconds, then uint32 nanoseconds.
    let (sec, nsec) = (time & 0xffff_ffff, time >> 32);
    Ok((conn, (sec * 1_000_000_000 + nsec) as i64))
}

/// The records of a decompressed chunk, in order; the first that does not parse ends it.
fn chunk_records(
    mut bytes: &[u8],
    visit: &mut impl FnMut(Item<'_>) -> Result<bool, Error>,
) -> Result<Result<bool, String>, Error> {
    while !bytes.is_empty() {
        let record = (|| {
            let (header, rest) = split_length(bytes, "record header")?;
            let (data, rest) = split_length(rest, "record data")?;
            let header = fields(header)?;
            Ok::<_, String>((header, data, rest))
        })();
        let (header, data, rest) = match record {
            Ok(r) => r,
            Err(why) => return Ok(Err(why)),
        };
        bytes = rest;
        let go_on = match op_of(&header) {
            Ok(op::CONNECTION) => match connection(&header, data) {
                Ok(c) => visit(Item::Connection(c))?,
                Err(why) => return Ok(Err(why)),
            },
            Ok(op::MESSAGE_DATA) => match message_of(&header) {
                Ok((conn, time_ns)) => visit(Item::Message {
                    conn,
                    time_ns,
                    data,
                })?,
                Err(why) => return Ok(Err(why)),
            },
            Ok(_) => true,
            Err(why) => return Ok(Err(why)),
        };
        if !go_on {
            return Ok(Ok(false));
        }
    }
    Ok(Ok(true))
}

/// A `uint32` length and that many bytes, from the front of `bytes`.
fn split_length<'a>(bytes: &'a [u8], what: &str) -> Result<(&'a [u8], &'a [u8]), String> {
    let Some((len, rest)) = bytes.split_first_chunk::<4>() else {
        return Err(format!("the {what}'s length cut short"));
    };
    let len = usize::try_from(u32::from_le_bytes(*len)).unwrap_or(usize::MAX);
    if len > rest.len() {
        return Err(format!(
            "a {what} of {len} bytes in the {} left of the chunk",
            rest.len()
        ));
    }
    Ok(rest.split_at(len))
}

/// Decompresses a chunk's `data` into `out` (cleared first): exactly `size` bytes.
fn decompress(compression: &str, data: &[u8], size: u32, out: &mut Vec<u8>) -> Result<(), String> {
    out.clear();
    // The declared size, within the chunk limit, at once: no doubling past it while reading.
    out.reserve_exact(size as usize + 1);
    let limit = u64::from(size) + 1;
    let read = match compression {
        "bz2" => bzip2::read::BzDecoder::new(data)
            .take(limit)
            .read_to_end(out),
        "lz4" => lz4::Decoder::new(data).and_then(|d| d.take(limit).read_to_end(out)),
        other => return Err(format!("compression `{}`", printable(other))),
    };
    match read {
        Err(err) => Err(format!(
            "{compression} data that does not decompress ({err})"
        )),
        Ok(n) if n as u64 != u64::from(size) => Err(format!(
            "{compression} data of {}{n} bytes where its header says {size}",
            if n as u64 == limit { "more than " } else { "" }
        )),
        Ok(_) => Ok(()),
    }
}

/// A bag's file, read record by record.
struct Records {
    file: BufReader<File>,
    size: u64,
    at: u64,
}

/// A top-level record: its header fields' bytes and where its data starts.
struct Head {
    header: Vec<u8>,
    data_len: u32,
}

impl Records {
    fn open(path: &Path) -> Result<Self, Error> {
        let file = File::open(path).map_err(|err| Error::bag(path, err.to_string()))?;
        let size = file
            .metadata()
            .map_err(|err| Error::bag(path, err.to_string()))?
            .len();
        let mut file = BufReader::with_capacity(1 << 16, file);
        let mut magic = Vec::with_capacity(MAGIC.len());
        (&mut file)
            .take(MAGIC.len() as u64)
            .read_to_end(&mut magic)
            .map_err(|err| Error::bag(path, err.to_string()))?;
        if magic != MAGIC {
            let message = if magic.starts_with(b"#ROSBAG V") {
                let version = String::from_utf8_lossy(&magic[9..]).trim().to_string();
                format!(
                    "a ROS 1 bag of format {}, not 2.0 (`rosbag fix` rewrites it as 2.0)",
                    printable(&version)
                )
            } else if magic.is_empty() {
                "empty: not a bag".to_string()
            } else {
                "not a bag (a ROS 1 bag starts `#ROSBAG V2.0`; a ROS 2 bag is MCAP or SQLite3)"
                    .to_string()
            };
            return Err(Error::bag(path, message));
        }
        Ok(Self {
            file,
            size,
            at: MAGIC.len() as u64,
        })
    }

    fn seek(&mut self, to: u64) -> std::io::Result<()> {
        self.file.seek(SeekFrom::Start(to))?;
        self.at = to;
        Ok(())
    }

    fn u32(&mut self) -> Result<u32, String> {
        let mut bytes = [0; 4];
        self.file
            .read_exact(&mut bytes)
            .map_err(|_| "a record cut short".to_string())?;
        self.at += 4;
        Ok(u32::from_le_bytes(bytes))
    }

    /// The next record's header; `None` at the end of the file.
    fn head(&mut self) -> Result<Option<Head>, String> {
        if self.at >= self.size {
            return Ok(None);
        }
        let header_len = self.u32()?;
        if header_len > HEADER_LIMIT {
            return Err(format!(
                "a record header of {header_len} bytes, beyond the {} KiB any has",
                HEADER_LIMIT >> 10
            ));
        }
        let mut header = Vec::new();
        self.bytes(header_len, &mut header)?;
        let data_len = self.u32()?;
        Ok(Some(Head { header, data_len }))
    }

    /// `len` bytes into `out` (cleared first); a length beyond the file's end is a record cut
    /// short, before anything is allocated for it.
    fn bytes(&mut self, len: u32, out: &mut Vec<u8>) -> Result<(), String> {
        out.clear();
        if self.at + u64::from(len) > self.size {
            return Err("a record cut short".to_string());
        }
        out.reserve_exact(len as usize);
        let n = (&mut self.file)
            .take(u64::from(len))
            .read_to_end(out)
            .map_err(|err| err.to_string())?;
        self.at += n as u64;
        if n as u64 != u64::from(len) {
            return Err("a record cut short".to_string());
        }
        Ok(())
    }

    fn skip(&mut self, len: u32) -> Result<(), String> {
        let to = self.at + u64::from(len);
        if to > self.size {
            return Err("a record cut short".to_string());
        }
        self.file
            .seek_relative(i64::from(len))
            .map_err(|err| err.to_string())?;
        self.at = to;
        Ok(())
    }
}

/// What the first record, the bag header, says: where the index (connections and chunk infos)
/// starts; `None` for a bag not closed (`index_pos` 0) or without a readable header.
fn index_pos(records: &mut Records) -> Option<u64> {
    let head = records.head().ok()??;
    let fields = fields(&head.header).ok()?;
    if op_of(&fields).ok()? != op::BAG_HEADER {
        return None;
    }
    let pos = field_u64(&fields, "index_pos").ok()?;
    (pos > MAGIC.len() as u64 && pos < records.size).then_some(pos)
}

/// The connections of a bag: from its index at the end when it has one (a read of the end of
/// the file), else from a pass over the whole file. Each connection once, in order of id.
///
/// # Errors
/// Not a bag of format 2.0, or more connections than any bag has.
pub fn connections(path: &Path) -> Result<Vec<Connection>, Error> {
    let mut found: BTreeMap<u32, Connection> = BTreeMap::new();
    let mut keep = |c: Connection| {
        if found.len() == CONNECTION_LIMIT && !found.contains_key(&c.id) {
            return Err(Error::bag(
                path,
                format!("more than {CONNECTION_LIMIT} connections: not a bag's"),
            ));
        }
        found.entry(c.id).or_insert(c);
        Ok(())
    };
    let mut records = Records::open(path)?;
    if let Some(pos) = index_pos(&mut records) {
        if records.seek(pos).is_ok() {
            let mut data = Vec::new();
            let mut indexed = Vec::new();
            let whole = loop {
                let Ok(head) = records.head() else {
                    break false;
                };
                let Some(head) = head else { break true };
                let Ok(fields) = fields(&head.header) else {
                    break false;
                };
                if op_of(&fields) == Ok(op::CONNECTION) && head.data_len <= RECORD_LIMIT {
                    if records.bytes(head.data_len, &mut data).is_err() {
                        break false;
                    }
                    match connection(&fields, &data) {
                        Ok(c) => indexed.push(c),
                        Err(_) => break false,
                    }
                } else if records.skip(head.data_len).is_err() {
                    break false;
                }
            };
            if whole && !indexed.is_empty() {
                for c in indexed {
                    keep(c)?;
                }
                return Ok(found.into_values().collect());
            }
        }
    }
    stream_while(path, |item| {
        if let Item::Connection(c) = item {
            keep(c)?;
        }
        Ok(true)
    })?;
    Ok(found.into_values().collect())
}

/// Streams a bag's connections and messages through `visit` in file order, chunk by chunk,
/// until `visit` returns `false` or the file ends; what could not be read is returned.
///
/// # Errors
/// Not a bag of format 2.0, or `visit` fails.
pub(crate) fn stream_while(
    path: &Path,
    mut visit: impl FnMut(Item<'_>) -> Result<bool, Error>,
) -> Result<Damage, Error> {
    let mut records = Records::open(path)?;
    let mut damage = Damage::default();
    let (mut raw, mut chunk) = (Vec::new(), Vec::new());
    loop {
        let start = records.at;
        let stop = |damage: &mut Damage, why: String| {
            damage.stopped = Some(format!("byte {start}, where {why}"));
        };
        let head = match records.head() {
            Ok(Some(head)) => head,
            Ok(None) => break,
            Err(why) => {
                stop(&mut damage, why);
                break;
            }
        };
        let fields = match fields(&head.header).and_then(|f| Ok((op_of(&f)?, f))) {
            Ok(f) => f,
            Err(why) => {
                stop(&mut damage, why);
                break;
            }
        };
        let (op, fields) = fields;
        match op {
            op::CHUNK => {
                let compression = field(&fields, "compression").unwrap_or(b"none");
                let compression = String::from_utf8_lossy(compression).into_owned();
                let size = field_u32(&fields, "size");
                let size = match size {
                    Ok(size) if size <= CHUNK_LIMIT => size,
                    Ok(size) => {
                        skip_chunk(&mut damage, format!(
                            "a chunk of {size} bytes uncompressed, beyond the {} MiB a chunk may hold",
                            CHUNK_LIMIT >> 20
                        ));
                        if let Err(why) = records.skip(head.data_len) {
                            stop(&mut damage, why);
                            break;
                        }
                        continue;
                    }
                    Err(why) => {
                        stop(&mut damage, why);
                        break;
                    }
                };
                if !matches!(compression.as_str(), "none" | "bz2" | "lz4") {
                    *damage.compressions.entry(compression).or_insert(0) += 1;
                    if let Err(why) = records.skip(head.data_len) {
                        stop(&mut damage, why);
                        break;
                    }
                    continue;
                }
                if compression == "none" && head.data_len != size {
                    stop(
                        &mut damage,
                        format!(
                            "an uncompressed chunk of {} bytes says it holds {size}",
                            head.data_len
                        ),
                    );
                    break;
                }
                if head.data_len > CHUNK_LIMIT {
                    stop(
                        &mut damage,
                        format!(
                            "a chunk of {} bytes, beyond the {} MiB a chunk may hold",
                            head.data_len,
                            CHUNK_LIMIT >> 20
                        ),
                    );
                    break;
                }
                if let Err(why) = records.bytes(head.data_len, &mut raw) {
                    stop(&mut damage, why);
                    break;
                }
                let bytes = if compression == "none" {
                    &raw
                } else {
                    match decompress(&compression, &raw, size, &mut chunk) {
                        Ok(()) => &chunk,
                        Err(why) => {
                            skip_chunk(&mut damage, why);
                            continue;
                        }
                    }
                };
                match chunk_records(bytes, &mut visit)? {
                    Ok(true) => {}
                    Ok(false) => return Ok(damage),
                    Err(why) => {
                        damage.records += 1;
                        damage.first_record.get_or_insert(why);
                    }
                }
            }
            op::CONNECTION | op::MESSAGE_DATA if head.data_len <= RECORD_LIMIT => {
                if let Err(why) = records.bytes(head.data_len, &mut raw) {
                    stop(&mut damage, why);
                    break;
                }
                let item = if op == op::CONNECTION {
                    connection(&fields, &raw).map(Item::Connection)
                } else {
                    message_of(&fields).map(|(conn, time_ns)| Item::Message {
                        conn,
                        time_ns,
                        data: &raw,
                    })
                };
                match item {
                    Ok(item) => {
                        if !visit(item)? {
                            return Ok(damage);
                        }
                    }
                    Err(why) => {
                        damage.records += 1;
                        damage.first_record.get_or_insert(why);
                    }
                }
            }
            op::BAG_HEADER
            | op::INDEX_DATA
            | op::CHUNK_INFO
            | op::CONNECTION
            | op::MESSAGE_DATA => {
                if matches!(op, op::CONNECTION | op::MESSAGE_DATA) {
                    damage.records += 1;
                    damage.first_record.get_or_insert(format!(
                        "a record of {} bytes, beyond the {} MiB one may have",
                        head.data_len,
                        RECORD_LIMIT >> 20
                    ));
                }
                if let Err(why) = records.skip(head.data_len) {
                    stop(&mut damage, why);
                    break;
                }
            }
            other => {
                stop(
                    &mut damage,
                    format!("a record of op 0x{other:02x}, which rosbag 2.0 has not"),
                );
                break;
            }
        }
    }
    Ok(damage)
}

fn skip_chunk(damage: &mut Damage, why: String) {
    damage.chunks += 1;
    damage.first_chunk.get_or_insert(why);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_fields_split_at_the_first_equals_sign() {
        let mut bytes = Vec::new();
        for f in [&b"op=\x07"[..], b"topic=/a=b", b"x="] {
            bytes.extend((f.len() as u32).to_le_bytes());
            bytes.extend_from_slice(f);
        }
        let f = fields(&bytes).unwrap();
        assert_eq!(f[0], (&b"op"[..], &b"\x07"[..]));
        assert_eq!(f[1], (&b"topic"[..], &b"/a=b"[..]));
        assert_eq!(f[2], (&b"x"[..], &b""[..]));
        assert_eq!(op_of(&f), Ok(op::CONNECTION));
        bytes.extend(100u32.to_le_bytes());
        assert!(fields(&bytes).unwrap_err().contains("100 bytes"));
        assert!(fields(&[1, 0, 0, 0, b'x'])
            .unwrap_err()
            .contains("without `=`"));
    }

    #[test]
    fn a_message_time_is_seconds_then_nanoseconds() {
        let time = (5u64 << 32) | 3;
        let header = [
            (&b"conn"[..], &7u32.to_le_bytes()[..]),
            (b"time", &time.to_le_bytes()[..]),
        ];
        assert_eq!(message_of(&header), Ok((7, 3_000_000_005)));
    }

    #[test]
    fn a_chunk_must_inflate_to_its_declared_size() {
        let mut out = Vec::new();
        assert!(decompress("bz2", b"not bz2", 10, &mut out)
            .unwrap_err()
            .contains("does not decompress"));
        assert!(decompress("zstd", b"", 0, &mut out)
            .unwrap_err()
            .contains("`zstd`"));
    }
}
