//! Opening a recording's files with bounds, so that no input — garbage, a device that never ends,
//! a line without end — can take more memory than the samples a valid file holds.
//!
//! The limits, and why:
//!
//! * A recording's files must be regular files (a symbolic link to one is fine). A character
//!   device (`/dev/zero`), a pipe or a socket can be endless, so it is refused before it is opened
//!   (opening a pipe would also wait for a writer). Every file `hilsim` writes is a regular file.
//! * A table's line may be at most [`MAX_LINE_BYTES`] (64 KiB). The longest row the writer
//!   produces (`lidar.csv`, with `true_range_m`) is under 200 bytes; 64 KiB leaves room for many
//!   added columns and bounds the one line held in memory at a time.
//! * A table may be at most [`MAX_TABLE_BYTES`] (16 GiB). A Neato lidar turning at 5 rev/s
//!   writes 5 × 360 rows of about 60 bytes a second: 9.3 GB for a day's recording. Anything
//!   larger is not a run this tool was made for, and its samples would not fit in memory.
//! * `meta.toml` may be at most [`MAX_META_BYTES`] (1 MiB); a real one is a few hundred bytes.
//!   It is read whole (TOML is parsed from text), so this bounds what it costs.

use std::fs::{self, File};
use std::io::Read;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;

use crate::Error;

/// The longest line a recording's table may have, in bytes (without its line break).
pub(crate) const MAX_LINE_BYTES: usize = 64 * 1024;

/// The largest table (`*.csv`) a recording may have, in bytes.
pub(crate) const MAX_TABLE_BYTES: u64 = 16 << 30;

/// The largest `meta.toml` a recording may have, in bytes.
pub const MAX_META_BYTES: u64 = 1 << 20;

/// Opens a file of a recording: a regular file (after following links) no larger than
/// `max_bytes`, described as `what` when it is larger.
pub(crate) fn open_regular(path: &Path, max_bytes: u64, what: &str) -> Result<File, Error> {
    let meta = fs::metadata(path).map_err(|err| Error::io(path, err))?;
    let kind = meta.file_type();
    let endless = if kind.is_char_device() {
        Some("a character device")
    } else if kind.is_block_device() {
        Some("a block device")
    } else if kind.is_fifo() {
        Some("a pipe")
    } else if kind.is_socket() {
        Some("a socket")
    } else {
        // A directory is opened and fails to read, with the system's own words, as it always did.
        None
    };
    if let Some(kind) = endless {
        return Err(Error::format(
            path,
            None,
            format!("not a regular file but {kind}"),
        ));
    }
    if kind.is_file() && meta.len() > max_bytes {
        return Err(too_large(path, max_bytes, what));
    }
    File::open(path).map_err(|err| Error::io(path, err))
}

/// The error for a file larger than `max_bytes`.
pub(crate) fn too_large(path: &Path, max_bytes: u64, what: &str) -> Error {
    Error::format(
        path,
        None,
        format!("larger than {}; not {what}", size(max_bytes)),
    )
}

/// `bytes` as people write it: 64 KiB, 1 MiB, 16 GiB.
pub(crate) fn size(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b % (1 << 30) == 0 => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b % (1 << 20) == 0 => format!("{} MiB", b >> 20),
        b if b >= 1 << 10 && b % (1 << 10) == 0 => format!("{} KiB", b >> 10),
        b => format!("{b} bytes"),
    }
}

/// Reads a small text file whole: at most `max_bytes`, UTF-8 (else an error at the line of the
/// first byte that is not).
pub fn read_small_text(path: &Path, max_bytes: u64, what: &str) -> Result<String, Error> {
    let file = open_regular(path, max_bytes, what)?;
    let mut bytes = Vec::new();
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|err| Error::io(path, err))?;
    if bytes.len() as u64 > max_bytes {
        // The file grew after it was measured.
        return Err(too_large(path, max_bytes, what));
    }
    String::from_utf8(bytes).map_err(|err| {
        let line = 1 + err.as_bytes()[..err.utf8_error().valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        Error::format(path, Some(line), "not UTF-8 text")
    })
}

/// Which directory `dir` is now (device and inode). A writer replaces a recording by renaming a
/// whole new directory over it, so a reader that opens its files one after another by path can
/// take some from the old recording and some from the new: a reader notes the identity before
/// its first open and checks it after its last ([`check_same_dir`]), which catches every mix.
pub(crate) fn dir_identity(dir: &Path) -> Result<(u64, u64), Error> {
    use std::os::unix::fs::MetadataExt;
    let meta = fs::metadata(dir).map_err(|err| Error::io(dir, err))?;
    Ok((meta.dev(), meta.ino()))
}

/// Refuses what was read from `dir` when `dir` is no longer the directory it was
/// (`identity`, from [`dir_identity`]) once every file was opened.
pub(crate) fn check_same_dir(dir: &Path, identity: (u64, u64)) -> Result<(), Error> {
    match dir_identity(dir) {
        Ok(now) if now == identity => Ok(()),
        _ => Err(Error::format(
            dir,
            None,
            "was replaced by another recording while it was being read; read it again",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(size(MAX_LINE_BYTES as u64), "64 KiB");
        assert_eq!(size(MAX_META_BYTES), "1 MiB");
        assert_eq!(size(MAX_TABLE_BYTES), "16 GiB");
        assert_eq!(size(1000), "1000 bytes");
    }
}
