//! Reading a ROS 2 bag's MCAP files as a stream of records: never the whole file in memory
//! (mcap's sans-I/O linear reader, fed from the file in pieces; a chunk is decompressed as it
//! is read), so a bag of any size reads in bounded memory.

use std::collections::HashMap;
use std::fs::File;
use std::io::{Read, Seek};
use std::path::{Path, PathBuf};

use mcap::records::{op, Record};
use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::sans_io::summary_reader::{SummaryReadEvent, SummaryReader, SummaryReaderOptions};
use mcap::McapError;

use crate::Error;

/// The largest record read whole (a message, a schema): far above any scan (a 3,600-reading
/// LaserScan with intensities is 29 kB) and below what would exhaust memory on purpose.
const RECORD_LENGTH_LIMIT: usize = 64 << 20;

/// The most a chunk may hold uncompressed, checked against its header before it is
/// decompressed (and the header held to while decompressing): rosbag2 and the mcap writers write
/// chunks of 1 to 4 MiB, and a chunk must have room for the largest record. Reading a chunk
/// takes time in proportion to what it inflates to, whatever its size on disk.
pub const CHUNK_LIMIT: u64 = 2 * RECORD_LENGTH_LIMIT as u64;

/// How many times its file's size a whole-file zstd stream (rosbag2's `file` compression) may
/// inflate to: messages compress a few times over; a stream of zeros, thousands of times.
pub const FILE_INFLATION_LIMIT: u64 = 1000;

/// The longest topic, type or encoding name read: ROS 2 cannot create a topic of more than
/// 255 characters (DDS's limit), and type names are shorter. With channel and schema ids of
/// 16 bits, what is kept of a file's channels stays under a few tens of MiB however the file
/// was made.
pub const NAME_LIMIT: usize = 256;

/// The largest summary section read for a file's channels (a larger one is not read: the
/// data section is); a real bag's summary is a few kB per topic and chunk.
const SUMMARY_LIMIT: u64 = 16 << 20;

/// The most distinct channels a file may declare (channel ids have 16 bits).
const CHANNEL_LIMIT: usize = 1 << 16;

/// A topic of one MCAP file.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Channel {
    /// The channel's id in its file.
    pub id: u16,
    /// The topic, e.g. `/scan`.
    pub topic: String,
    /// The message type as the schema names it, e.g. `sensor_msgs/msg/LaserScan`.
    pub type_name: String,
    /// How messages are encoded (`cdr` for ROS 2).
    pub message_encoding: String,
}

/// A record of interest in a file's stream.
pub(crate) enum Item<'a> {
    /// A channel, before its first message.
    Channel(Channel),
    /// A message.
    Message {
        channel_id: u16,
        log_time: u64,
        data: &'a [u8],
    },
    /// A metadata record (name, key/value pairs).
    Metadata(mcap::records::Metadata),
}

/// The MCAP files of a bag: the file itself, or those a bag directory's `metadata.yaml` lists
/// (in order; split bags have several).
///
/// # Errors
/// Not a file or a bag directory, a directory without `metadata.yaml`, a bag whose storage is
/// not MCAP.
pub fn bag_files(bag: &Path) -> Result<Vec<PathBuf>, Error> {
    let meta = std::fs::metadata(bag).map_err(|err| Error::bag(bag, err.to_string()))?;
    if meta.is_file() {
        return Ok(vec![bag.to_path_buf()]);
    }
    if !meta.is_dir() {
        return Err(Error::bag(bag, "neither an MCAP file nor a bag directory"));
    }
    let yaml_path = bag.join("metadata.yaml");
    if !yaml_path.exists() && bag.join("meta.toml").is_file() {
        return Err(Error::bag(
            bag,
            "a hilsim recording (it has a meta.toml), not a ROS 2 bag: it needs no import",
        ));
    }
    let yaml = read_small(&yaml_path)?;
    if let Some(storage) = yaml_value(&yaml, "storage_identifier") {
        if storage != "mcap" && storage != "sqlite3" {
            return Err(Error::bag(
                &yaml_path,
                format!(
                    "storage `{storage}`, neither MCAP nor SQLite3: convert it first (`ros2 bag convert` to \
                     storage mcap)"
                ),
            ));
        }
    }
    let mut files = Vec::new();
    for name in listed_files(&yaml) {
        files.push(inside(bag, &yaml_path, &name)?);
    }
    if files.is_empty() {
        // No list: every .mcap file, split files in their index order (`name_2` before
        // `name_10`).
        let entries = std::fs::read_dir(bag).map_err(|err| Error::bag(bag, err.to_string()))?;
        for entry in entries {
            let path = entry
                .map_err(|err| Error::bag(bag, err.to_string()))?
                .path();
            if path.extension().is_some_and(|e| e == "mcap" || e == "db3") {
                files.push(path);
            }
        }
        files.sort_by_key(|p| {
            let stem = p
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .to_string();
            let digits = stem.len() - stem.trim_end_matches(|c: char| c.is_ascii_digit()).len();
            let index: u64 = stem[stem.len() - digits..].parse().unwrap_or(0);
            (stem[..stem.len() - digits].to_string(), index)
        });
    }
    if files.is_empty() {
        return Err(Error::bag(
            bag,
            "a bag directory without an .mcap or .db3 file",
        ));
    }
    Ok(files)
}

/// The file `name` (from `metadata.yaml`) of the bag directory `bag`, which it must not leave:
/// an absolute path, `..`, or a link that resolves outside would let a bag from anyone make
/// hilsim read any file the user can.
fn inside(bag: &Path, yaml_path: &Path, name: &str) -> Result<PathBuf, Error> {
    use std::path::Component;
    let relative = Path::new(name);
    let leaves = || {
        Error::bag(
            yaml_path,
            format!(
                "relative_file_paths lists {}, which leaves the bag's directory: refused",
                hilsim_recording::printable(name)
            ),
        )
    };
    if relative
        .components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err(leaves());
    }
    let path = bag.join(relative);
    // A link inside the directory may still point out of it.
    if let (Ok(dir), Ok(resolved)) = (bag.canonicalize(), path.canonicalize()) {
        if !resolved.starts_with(dir) {
            return Err(leaves());
        }
    }
    Ok(path)
}

fn read_small(path: &Path) -> Result<String, Error> {
    let file = File::open(path).map_err(|err| Error::bag(path, err.to_string()))?;
    let mut text = String::new();
    // metadata.yaml is a few kB; a larger one is not a bag's.
    file.take(1 << 20)
        .read_to_string(&mut text)
        .map_err(|err| Error::bag(path, format!("not a bag's metadata.yaml ({err})")))?;
    Ok(text)
}

/// The value of `key: value` at any depth of a YAML text (enough for rosbag2's scalars).
fn yaml_value<'a>(yaml: &'a str, key: &str) -> Option<&'a str> {
    yaml.lines().find_map(|line| {
        let (k, v) = line.trim().split_once(':')?;
        (k == key).then(|| v.trim().trim_matches(['"', '\'']))
    })
}

/// rosbag2's `relative_file_paths:` list.
fn listed_files(yaml: &str) -> Vec<String> {
    let mut lines = yaml.lines().map(str::trim);
    if !lines.any(|l| l == "relative_file_paths:") {
        return Vec::new();
    }
    lines
        .map_while(|l| l.strip_prefix("- "))
        .map(|name| name.trim().trim_matches(['"', '\'']).to_string())
        .collect()
}

/// Whether the file at `path` begins as MCAP's magic does (as far as it goes).
fn starts_like_mcap(path: &Path) -> bool {
    const MAGIC: &[u8] = b"\x89MCAP0\r\n";
    let mut head = Vec::with_capacity(MAGIC.len());
    let read = File::open(path)
        .and_then(|f| std::io::Read::take(f, MAGIC.len() as u64).read_to_end(&mut head));
    read.is_ok() && MAGIC.starts_with(&head)
}

/// What a file that is no bag is.
const NOT_A_BAG: &str =
    "not an MCAP file (a ROS 2 bag is MCAP or SQLite3; a ROS 1 bag starts `#ROSBAG V2.0`)";

/// One line for an MCAP error.
fn mcap_error(path: &Path, err: McapError) -> Error {
    let message = match err {
        McapError::BadMagic => NOT_A_BAG.to_string(),
        McapError::UnsupportedCompression(name) => {
            format!(
                "a chunk compressed with `{name}`, which hilsim cannot read (zstd and lz4 only)"
            )
        }
        // A file shorter than MCAP's magic ends before it can be told apart: say which it is.
        McapError::UnexpectedEof | McapError::UnexpectedEoc if !starts_like_mcap(path) => {
            NOT_A_BAG.to_string()
        }
        McapError::UnexpectedEof | McapError::UnexpectedEoc => {
            "truncated: the file ends inside a record".to_string()
        }
        McapError::Io(err) => err.to_string(),
        McapError::RecordTooLarge { opcode, len } => format!(
            "a record (opcode 0x{opcode:02x}) of {len} bytes, beyond the {} MiB any record may \
             have",
            RECORD_LENGTH_LIMIT >> 20
        ),
        other => format!("not a readable MCAP file ({other})"),
    };
    Error::bag(path, message)
}

/// The channels of an MCAP file: from its summary section when it has one (a read of the end
/// of the file), else from a pass over the whole file.
///
/// # Errors
/// The file cannot be read, or is not MCAP.
pub fn channels(path: &Path) -> Result<Vec<Channel>, Error> {
    if is_sqlite(path) {
        return sqlite_channels(path);
    }
    if let Some(found) = summary_channels(path)? {
        if !found.is_empty() {
            return Ok(found);
        }
    }
    // Channel records repeat (one per chunk, in some writers): each distinct one is kept once,
    // in the order of their ids (as the summary's).
    let mut found = std::collections::BTreeSet::new();
    stream(path, |item| {
        if let Item::Channel(channel) = item {
            if found.len() == CHANNEL_LIMIT && !found.contains(&channel) {
                return Err(Error::bag(
                    path,
                    format!("more than {CHANNEL_LIMIT} different channels: not a bag's"),
                ));
            }
            found.insert(channel);
        }
        Ok(())
    })?;
    Ok(found.into_iter().collect())
}

/// The summary's channels; `None` when there is no summary or it cannot be read (the full pass
/// then decides whether the file is good).
pub(crate) fn summary_channels(path: &Path) -> Result<Option<Vec<Channel>>, Error> {
    if is_sqlite(path) {
        return Ok(None);
    }
    let mut file = File::open(path).map_err(|err| Error::bag(path, err.to_string()))?;
    let size = file
        .metadata()
        .map_err(|err| Error::bag(path, err.to_string()))?
        .len();
    // What the summary holds is kept whole: read it only when it is of a bag's size.
    match summary_start(&mut file, size) {
        Some(start) if size - start <= SUMMARY_LIMIT => {}
        _ => return Ok(None),
    }
    let mut reader = SummaryReader::new_with_options(
        SummaryReaderOptions::default()
            .with_file_size(size)
            .with_record_length_limit(RECORD_LENGTH_LIMIT),
    );
    while let Some(event) = reader.next_event() {
        let Ok(event) = event else { return Ok(None) };
        match event {
            SummaryReadEvent::ReadRequest(need) => {
                let Ok(read) = file.read(reader.insert(need)) else {
                    return Ok(None);
                };
                reader.notify_read(read);
            }
            SummaryReadEvent::SeekRequest(to) => {
                let Ok(at) = file.seek(to) else {
                    return Ok(None);
                };
                reader.notify_seeked(at);
            }
        }
    }
    let Some(summary) = reader.finish() else {
        return Ok(None);
    };
    let mut found = Vec::new();
    for c in summary.channels.values() {
        let type_name = c
            .schema
            .as_ref()
            .map(|s| s.name.clone())
            .unwrap_or_default();
        let schema_id = c.schema.as_ref().map_or(0, |s| s.id);
        found.push(Channel {
            id: c.id,
            topic: bounded_name(path, "channel", c.id, "topic", c.topic.clone())?,
            type_name: bounded_name(path, "schema", schema_id, "type name", type_name)?,
            message_encoding: bounded_name(
                path,
                "channel",
                c.id,
                "encoding",
                c.message_encoding.clone(),
            )?,
        });
    }
    found.sort_by_key(|c| c.id);
    Ok(Some(found))
}

/// Where the summary section starts, from the footer at the file's end; `None` when the file
/// has none (or no footer where one should be).
fn summary_start(file: &mut File, size: u64) -> Option<u64> {
    // The footer record (opcode, length, summary start, summary offset start, CRC), then the
    // magic.
    const TAIL: u64 = 1 + 8 + 8 + 8 + 4 + 8;
    let mut tail = [0; TAIL as usize];
    file.seek(std::io::SeekFrom::Start(size.checked_sub(TAIL)?))
        .ok()?;
    file.read_exact(&mut tail).ok()?;
    let start = u64::from_le_bytes(tail[9..17].try_into().ok()?);
    (tail[0] == op::FOOTER && start != 0 && start <= size).then_some(start)
}

/// The number of messages in an MCAP file, by reading it whole (every chunk decompressed and
/// its CRC checked, no message decoded).
///
/// # Errors
/// As [`channels`], and a truncated or corrupt file.
pub fn count_messages(path: &Path) -> Result<u64, Error> {
    let mut count = 0;
    stream(path, |item| {
        if let Item::Message { .. } = item {
            count += 1;
        }
        Ok(())
    })?;
    Ok(count)
}

/// A zstd frame's first bytes. A CDR message starts with its representation (0x00 0x00 or
/// 0x00 0x01), an MCAP file with 0x89: either starting so was compressed by rosbag2's
/// `message` or `file` compression mode.
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xb5, 0x2f, 0xfd];

/// An MCAP file's bytes: the file, or its decompression when rosbag2 compressed the whole file
/// (`compression_mode: file`, `name.mcap.zstd`), which may inflate to at most
/// [`FILE_INFLATION_LIMIT`] times the file (or [`CHUNK_LIMIT`], if more).
fn open(path: &Path) -> Result<Box<dyn Read>, Error> {
    let fail = |err: std::io::Error| Error::bag(path, err.to_string());
    let mut file = File::open(path).map_err(fail)?;
    let size = file.metadata().map_err(fail)?.len();
    if size == 0 {
        return Err(Error::bag(path, "an empty file (0 bytes), not a bag"));
    }
    let mut head = [0; 4];
    let starts_zstd = file.read_exact(&mut head).is_ok() && head == ZSTD_MAGIC;
    file.rewind().map_err(fail)?;
    if starts_zstd {
        let limit = size.saturating_mul(FILE_INFLATION_LIMIT).max(CHUNK_LIMIT);
        return Ok(Box::new(Inflation {
            inner: zstd::stream::read::Decoder::new(file).map_err(fail)?,
            left: limit,
            limit,
        }));
    }
    Ok(Box::new(file))
}

/// A decompressing reader that refuses to give more than `limit` bytes: what a stream inflates
/// to costs time in proportion, whatever its size on disk.
struct Inflation<R> {
    inner: R,
    left: u64,
    limit: u64,
}

impl<R: Read> Read for Inflation<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let read = self.inner.read(buf)?;
        self.left = self.left.checked_sub(read as u64).ok_or_else(|| {
            std::io::Error::other(format!(
                "a zstd-compressed file that inflates beyond {} bytes ({FILE_INFLATION_LIMIT} \
                 times its size): not a bag's",
                self.limit
            ))
        })?;
        Ok(read)
    }
}

/// A message that rosbag2 compressed on its own (`compression_mode: message`), into `out`; at
/// most [`RECORD_LENGTH_LIMIT`] bytes, as any record.
fn decompress_message(path: &Path, data: &[u8], out: &mut Vec<u8>) -> Result<(), Error> {
    out.clear();
    let decoder = zstd::stream::read::Decoder::new(data)
        .map_err(|err| Error::bag(path, format!("a zstd-compressed message: {err}")))?;
    let limit = RECORD_LENGTH_LIMIT as u64;
    decoder
        .take(limit + 1)
        .read_to_end(out)
        .map_err(|err| Error::bag(path, format!("a zstd-compressed message: {err}")))?;
    if out.len() as u64 > limit {
        return Err(Error::bag(
            path,
            format!("a zstd-compressed message of more than {limit} bytes"),
        ));
    }
    Ok(())
}

/// Reads an MCAP file from start to end, handing each channel, message and metadata record to
/// `visit` in file order; `visit`'s error ends the read.
///
/// # Errors
/// The file cannot be read, is not MCAP, is truncated or corrupt (chunk CRCs are checked), or a
/// chunk uses a compression this build lacks; or `visit`'s error.
pub(crate) fn stream(
    path: &Path,
    mut visit: impl FnMut(Item<'_>) -> Result<(), Error>,
) -> Result<(), Error> {
    stream_while(path, |item| visit(item).map(|()| true))
}

/// As [`stream`], until `visit` returns `false`.
///
/// # Errors
/// As [`stream`].
pub(crate) fn stream_while(
    path: &Path,
    visit: impl FnMut(Item<'_>) -> Result<bool, Error>,
) -> Result<(), Error> {
    if is_sqlite(path) {
        return sqlite_stream_while(path, visit);
    }
    let mut file = open(path)?;
    // Chunks come whole (compressed) so that each header is checked before anything is
    // decompressed; their records are then streamed out of them.
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_emit_chunks(true)
            .with_validate_chunk_crcs(true)
            .with_record_length_limit(RECORD_LENGTH_LIMIT),
    );
    let mut records = Records {
        path,
        visit,
        schemas: HashMap::new(),
        message: Vec::new(),
        past_data: false,
    };
    while let Some(event) = reader.next_event() {
        match event.map_err(|err| mcap_error(path, err))? {
            LinearReadEvent::ReadRequest(need) => {
                // Large reads: the reader asks for what the next record needs, often a few
                // bytes; 1 MiB at a time keeps system calls rare and memory flat.
                let read = file
                    .read(reader.insert(need.max(1 << 20)))
                    .map_err(|err| Error::bag(path, err.to_string()))?;
                reader.notify_read(read);
            }
            LinearReadEvent::Record { opcode, data } => {
                let go_on = if opcode == op::CHUNK {
                    chunk(data, &mut records)?
                } else {
                    records.record(opcode, data)?
                };
                if !go_on {
                    return Ok(());
                }
            }
        }
    }
    Ok(())
}

/// A file's records handed on: schemas kept (by name) for the channels that follow.
struct Records<'p, V> {
    path: &'p Path,
    visit: V,
    schemas: HashMap<u16, String>,
    /// A message decompressed on its own.
    message: Vec<u8>,
    /// Past the data section's end: the summary only repeats (or contradicts) it.
    past_data: bool,
}

impl<V: FnMut(Item<'_>) -> Result<bool, Error>> Records<'_, V> {
    /// One record; `false` when `visit` says to stop.
    fn record(&mut self, opcode: u8, data: &[u8]) -> Result<bool, Error> {
        let path = self.path;
        if opcode == 0 {
            return Err(Error::bag(
                path,
                "a record of opcode 0x00, which MCAP does not have: zero bytes or garbage where \
                 a record should start (a damaged file)",
            ));
        }
        if self.past_data {
            return Ok(true);
        }
        // A name's length is read before the record is parsed, which would copy the name.
        let first_name = match opcode {
            op::SCHEMA => Some(("schema", "type name", 2)),
            op::CHANNEL => Some(("channel", "topic", 4)),
            _ => None,
        };
        if let Some((record, what, at)) = first_name {
            let id = data
                .get(..2)
                .map_or(0, |b| u16::from_le_bytes([b[0], b[1]]));
            let len = data
                .get(at..at + 4)
                .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            if len as usize > NAME_LIMIT && data.len() >= at + 4 + len as usize {
                return Err(name_too_long(path, record, id, what, len as usize));
            }
        }
        Ok(
            match mcap::parse_record(opcode, data).map_err(|err| mcap_error(path, err))? {
                Record::DataEnd(_) => {
                    self.past_data = true;
                    true
                }
                Record::Schema { header, .. } => {
                    let name = bounded_name(path, "schema", header.id, "type name", header.name)?;
                    self.schemas.insert(header.id, name);
                    true
                }
                Record::Channel(c) => {
                    let topic = bounded_name(path, "channel", c.id, "topic", c.topic)?;
                    let message_encoding =
                        bounded_name(path, "channel", c.id, "encoding", c.message_encoding)?;
                    (self.visit)(Item::Channel(Channel {
                        id: c.id,
                        topic,
                        type_name: self.schemas.get(&c.schema_id).cloned().unwrap_or_default(),
                        message_encoding,
                    }))?
                }
                Record::Message { header, data } => {
                    let data = if data.starts_with(&ZSTD_MAGIC) {
                        decompress_message(path, &data, &mut self.message)?;
                        &self.message[..]
                    } else {
                        &data[..]
                    };
                    (self.visit)(Item::Message {
                        channel_id: header.channel_id,
                        log_time: header.log_time,
                        data,
                    })?
                }
                Record::Metadata(m) => (self.visit)(Item::Metadata(m))?,
                _ => true,
            },
        )
    }
}

/// `name` when it is no longer than a ROS name can be ([`NAME_LIMIT`]); a longer one is
/// refused rather than kept (a file can declare thousands).
fn bounded_name(
    path: &Path,
    record: &str,
    id: u16,
    what: &str,
    name: String,
) -> Result<String, Error> {
    if name.len() > NAME_LIMIT {
        return Err(name_too_long(path, record, id, what, name.len()));
    }
    Ok(name)
}

fn name_too_long(path: &Path, record: &str, id: u16, what: &str, len: usize) -> Error {
    Error::bag(
        path,
        format!(
            "{record} {id}: a {what} of {len} bytes, longer than any ROS 2 name (at most \
             {NAME_LIMIT}): not a ROS 2 bag's"
        ),
    )
}

/// One chunk record's records, streamed through `records` after its header is checked: its
/// uncompressed size at most [`CHUNK_LIMIT`] (and no more than the header says comes out of it,
/// which the reader holds it to).
fn chunk<V>(body: &[u8], records: &mut Records<'_, V>) -> Result<bool, Error>
where
    V: FnMut(Item<'_>) -> Result<bool, Error>,
{
    let path = records.path;
    let Record::Chunk { header, .. } =
        mcap::parse_record(op::CHUNK, body).map_err(|err| mcap_error(path, err))?
    else {
        return Err(Error::bag(path, "a chunk record that is not a chunk"));
    };
    if header.uncompressed_size > CHUNK_LIMIT {
        return Err(Error::bag(
            path,
            format!(
                "a chunk of {} bytes uncompressed (as its header says), beyond the {} MiB a \
                 chunk may hold: not a bag's (rosbag2 writes chunks of a few MiB)",
                header.uncompressed_size,
                CHUNK_LIMIT >> 20
            ),
        ));
    }
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_validate_chunk_crcs(true)
            .with_record_length_limit(RECORD_LENGTH_LIMIT),
    );
    let mut head = vec![op::CHUNK];
    head.extend_from_slice(&(body.len() as u64).to_le_bytes());
    let mut source = head.as_slice().chain(body);
    while let Some(event) = reader.next_event() {
        match event.map_err(|err| chunk_error(path, err))? {
            LinearReadEvent::ReadRequest(need) => {
                let read = source
                    .read(reader.insert(need.max(1 << 20)))
                    .map_err(|err| Error::bag(path, err.to_string()))?;
                reader.notify_read(read);
            }
            LinearReadEvent::Record { opcode, data } => {
                if !records.record(opcode, data)? {
                    return Ok(false);
                }
            }
        }
    }
    Ok(true)
}

/// One line for an error inside a chunk, which was read whole: it cannot be truncated.
fn chunk_error(path: &Path, err: McapError) -> Error {
    match err {
        McapError::UnexpectedEof | McapError::UnexpectedEoc => Error::bag(
            path,
            "a chunk whose records run past its end (a damaged or altered chunk)",
        ),
        McapError::DecompressionError(why) => Error::bag(
            path,
            format!("a chunk that does not decompress as its header says ({why})"),
        ),
        other => mcap_error(path, other),
    }
}

/// Whether the file is an SQLite database (rosbag2's `sqlite3` storage, `.db3`).
fn is_sqlite(path: &Path) -> bool {
    let mut head = [0; 16];
    File::open(path).is_ok_and(|mut f| f.read_exact(&mut head).is_ok())
        && &head == b"SQLite format 3\0"
}

/// One line for an SQLite error (a database that is not a rosbag2 bag, or a damaged one).
fn sqlite_error(path: &Path, err: &rusqlite::Error) -> Error {
    Error::bag(path, format!("not a readable SQLite3 bag ({err})"))
}

/// One line for a row whose column is not of rosbag2's type: the table (and row), the column,
/// and what it holds instead.
fn sqlite_row_error(path: &Path, table: &str, err: &rusqlite::Error) -> Error {
    match err {
        rusqlite::Error::InvalidColumnType(_, name, found) => {
            let wanted = match name.as_str() {
                "name" | "type" | "serialization_format" => "text",
                _ => "an integer",
            };
            Error::bag(
                path,
                format!(
                    "table {table}: column {name} holds {}, expected {wanted}",
                    sqlite_type(*found)
                ),
            )
        }
        other => sqlite_error(path, other),
    }
}

/// An SQLite value's type, as a phrase.
fn sqlite_type(found: rusqlite::types::Type) -> &'static str {
    use rusqlite::types::Type;
    match found {
        Type::Integer => "an integer",
        Type::Real => "a real number",
        Type::Text => "text",
        Type::Blob => "a blob",
        Type::Null => "null",
    }
}

fn open_sqlite(path: &Path) -> Result<rusqlite::Connection, Error> {
    use rusqlite::OpenFlags;
    let flags = OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX;
    rusqlite::Connection::open_with_flags(path, flags).map_err(|err| sqlite_error(path, &err))
}

/// An SQLite3 bag's topics, from its `topics` table (rosbag2's schema; ids as channel ids).
fn sqlite_channels(path: &Path) -> Result<Vec<Channel>, Error> {
    let db = open_sqlite(path)?;
    let fail = |err: rusqlite::Error| sqlite_error(path, &err);
    let mut query = db
        .prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")
        .map_err(fail)?;
    let rows = query
        .query_map([], |row| {
            Ok((row.get::<_, i64>(0)?, row.get(1)?, row.get(2)?, row.get(3)?))
        })
        .map_err(fail)?;
    let mut found = Vec::new();
    for row in rows {
        let (id, topic, type_name, message_encoding): (i64, String, String, String) =
            row.map_err(|err| sqlite_row_error(path, "topics", &err))?;
        let id = u16::try_from(id).map_err(|_| {
            Error::bag(
                path,
                format!(
                    "table topics: topic {}: id {id}, not a channel id (0 to 65535)",
                    hilsim_recording::printable(&topic)
                ),
            )
        })?;
        if found.len() == CHANNEL_LIMIT {
            return Err(Error::bag(
                path,
                format!("table topics: more than {CHANNEL_LIMIT} topics: not a bag's"),
            ));
        }
        found.push(Channel {
            id,
            topic: bounded_name(path, "topic", id, "name", topic)?,
            type_name: bounded_name(path, "topic", id, "type name", type_name)?,
            message_encoding: bounded_name(path, "topic", id, "encoding", message_encoding)?,
        });
    }
    Ok(found)
}

/// As [`stream_while`] for an SQLite3 bag: its topics, then its messages in time order, one
/// row at a time (SQLite walks rosbag2's timestamp index; memory stays flat).
fn sqlite_stream_while(
    path: &Path,
    mut visit: impl FnMut(Item<'_>) -> Result<bool, Error>,
) -> Result<(), Error> {
    for channel in sqlite_channels(path)? {
        if !visit(Item::Channel(channel))? {
            return Ok(());
        }
    }
    let db = open_sqlite(path)?;
    let fail = |err: rusqlite::Error| sqlite_error(path, &err);
    // A blob's length is known without reading it: one beyond the record limit is never
    // loaded.
    let mut query = db
        .prepare(
            "SELECT topic_id, timestamp, \
             CASE WHEN typeof(data) = 'blob' AND length(data) <= ?1 THEN data END, id, \
             length(data) FROM messages ORDER BY timestamp, id",
        )
        .map_err(fail)?;
    let mut rows = query.query([RECORD_LENGTH_LIMIT as i64]).map_err(fail)?;
    let mut message = Vec::new();
    while let Some(row) = rows.next().map_err(fail)? {
        let id = row.get_ref(3).ok().and_then(|v| v.as_i64().ok());
        let table = id.map_or("messages".to_string(), |id| format!("messages, id {id}"));
        let in_row = |err: rusqlite::Error| sqlite_row_error(path, &table, &err);
        let topic_id: i64 = row.get(0).map_err(in_row)?;
        let timestamp: i64 = row.get(1).map_err(in_row)?;
        let data = match row.get_ref(2).map_err(in_row)? {
            rusqlite::types::ValueRef::Blob(data) => data,
            _ => {
                let length: Option<i64> = row.get(4).map_err(in_row)?;
                // Not a blob, or one too large to have been read.
                let found: String = db
                    .query_row(
                        "SELECT typeof(data) FROM messages WHERE id = ?1",
                        [id],
                        |r| r.get(0),
                    )
                    .unwrap_or_default();
                let what = if found == "blob" {
                    format!(
                        "a message of {} bytes, beyond the {} MiB any record may have",
                        length.unwrap_or(0),
                        RECORD_LENGTH_LIMIT >> 20
                    )
                } else {
                    let found = match found.as_str() {
                        "integer" => "an integer",
                        "real" => "a real number",
                        other => other,
                    };
                    format!("column data holds {found}, expected a blob (the message's bytes)")
                };
                return Err(Error::bag(path, format!("table {table}: {what}")));
            }
        };
        let data = if data.starts_with(&ZSTD_MAGIC) {
            decompress_message(path, data, &mut message)?;
            &message[..]
        } else {
            data
        };
        let go_on = visit(Item::Message {
            // A topic id beyond u16 was refused with the topics.
            channel_id: u16::try_from(topic_id).unwrap_or(u16::MAX),
            log_time: u64::try_from(timestamp).unwrap_or(0),
            data,
        })?;
        if !go_on {
            break;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rosbag2_metadata_lists_its_files() {
        let yaml = "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  \
                    relative_file_paths:\n    - run_0.mcap\n    - 'run_1.mcap'\n  \
                    starting_time:\n    nanoseconds_since_epoch: 1\n";
        assert_eq!(yaml_value(yaml, "storage_identifier"), Some("mcap"));
        assert_eq!(listed_files(yaml), vec!["run_0.mcap", "run_1.mcap"]);
    }

    #[test]
    fn a_foreign_storage_and_a_missing_bag_are_one_line_errors() {
        let dir = tempfile::tempdir().unwrap();
        let err = bag_files(dir.path()).unwrap_err().to_string();
        assert!(err.contains("metadata.yaml"), "{err}");
        std::fs::write(
            dir.path().join("metadata.yaml"),
            "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n",
        )
        .unwrap();
        // SQLite3 storage is read; this directory has no file of it.
        let err = bag_files(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("a bag directory without an .mcap or .db3 file"),
            "{err}"
        );
        std::fs::write(
            dir.path().join("metadata.yaml"),
            "rosbag2_bagfile_information:\n  storage_identifier: rosbag_v2\n",
        )
        .unwrap();
        let err = bag_files(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("storage `rosbag_v2`, neither MCAP nor SQLite3"),
            "{err}"
        );
        std::fs::write(dir.path().join("metadata.yaml"), "x: 1\n").unwrap();
        for name in ["b_10.mcap", "b_2.mcap", "b_0.mcap"] {
            std::fs::write(dir.path().join(name), b"").unwrap();
        }
        let names: Vec<_> = bag_files(dir.path())
            .unwrap()
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().to_string())
            .collect();
        assert_eq!(names, ["b_0.mcap", "b_2.mcap", "b_10.mcap"]);
    }

    /// A whole-file stream that inflates beyond its limit is stopped there, with a line saying
    /// so, whatever is left of it.
    #[test]
    fn a_stream_inflating_beyond_its_limit_is_stopped() {
        let zeros = zstd::encode_all(&[0u8; 1 << 16][..], 3).unwrap();
        let decoder = zstd::stream::read::Decoder::new(&zeros[..]).unwrap();
        let mut limited = Inflation {
            inner: decoder,
            left: 1000,
            limit: 1000,
        };
        let err = std::io::copy(&mut limited, &mut std::io::sink()).unwrap_err();
        assert!(
            err.to_string().contains("inflates beyond 1000 bytes"),
            "{err}"
        );
        let decoder = zstd::stream::read::Decoder::new(&zeros[..]).unwrap();
        let mut limited = Inflation {
            inner: decoder,
            left: 1 << 16,
            limit: 1 << 16,
        };
        assert_eq!(
            std::io::copy(&mut limited, &mut std::io::sink()).unwrap(),
            1 << 16
        );
    }

    #[test]
    fn not_mcap_and_truncated_files_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.mcap");
        std::fs::write(&path, b"hello").unwrap();
        let err = stream(&path, |_| Ok(())).unwrap_err().to_string();
        assert!(
            err.contains("x.mcap: not an MCAP file"),
            "shorter than the magic: {err}"
        );
        std::fs::write(&path, b"hello, this is not an MCAP file at all").unwrap();
        let err = stream(&path, |_| Ok(())).unwrap_err().to_string();
        assert!(err.contains("x.mcap: not an MCAP file"), "{err}");
        // The magic and half a header record.
        std::fs::write(
            &path,
            b"\x89MCAP0\r\n\x01\x40\x00\x00\x00\x00\x00\x00\x00ros2",
        )
        .unwrap();
        let err = stream(&path, |_| Ok(())).unwrap_err().to_string();
        assert!(err.starts_with(&format!("{}: ", path.display())), "{err}");
        assert!(err.contains("truncated"), "{err}");
    }
}
