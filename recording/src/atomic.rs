//! Writes that never leave a half-written file where a good one stood.
//!
//! Not `tempfile`: its files are created `0600` with random names, while these keep the
//! umask's permissions and the `.NAME.tmp.PID` / `.NAME.old.PID` names that `hilsim-dataset`
//! recognises as leftovers of an interrupted write and removes.

use std::fs;
use std::io::{self, Write};
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Path, PathBuf};

use crate::{Error, FORMAT};

/// Where an output file goes, decided before anything is written: a user's path is never
/// replaced by something of another kind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputTarget {
    /// A regular file (or nothing yet) at this path, symbolic links followed: written to a
    /// temporary sibling and renamed over it.
    Replace(PathBuf),
    /// A character device or a FIFO (`/dev/null`, `/dev/stdout`, a pipe): written through, as a
    /// shell's `>` would, never replaced.
    WriteThrough(PathBuf),
}

impl OutputTarget {
    /// What writing to `path` means.
    ///
    /// # Errors
    /// `path` is a directory, a socket, a block device, or a symbolic link that leads nowhere.
    pub fn of(path: &Path) -> Result<Self, Error> {
        let refuse = |what: &str| {
            Error::io(
                path,
                io::Error::other(format!("{what}; refusing to write over it")),
            )
        };
        let is_link = match fs::symlink_metadata(path) {
            Err(err) if err.kind() == io::ErrorKind::NotFound => {
                return Ok(Self::Replace(path.to_path_buf()))
            }
            Err(err) => return Err(Error::io(path, err)),
            Ok(meta) => meta.file_type().is_symlink(),
        };
        // Follow a link: the file the user names is the one they mean. (Otherwise keep the path
        // as given, so that messages name it as the user wrote it.)
        let target = if is_link {
            fs::canonicalize(path).map_err(|_| refuse("is a symbolic link that leads nowhere"))?
        } else {
            path.to_path_buf()
        };
        let kind = fs::metadata(&target)
            .map_err(|err| Error::io(path, err))?
            .file_type();
        if kind.is_file() {
            Ok(Self::Replace(target))
        } else if kind.is_char_device() || kind.is_fifo() {
            Ok(Self::WriteThrough(target))
        } else if kind.is_dir() {
            Err(refuse("is a directory"))
        } else {
            Err(refuse("is not a regular file"))
        }
    }
}

/// Whether `a` and `b` are the same file (same device and inode); false when either is absent.
#[must_use]
pub fn is_same_file(a: &Path, b: &Path) -> bool {
    match (fs::metadata(a), fs::metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Writes `contents` to `path` through a temporary file in the same directory, then renames it
/// over `path`, so a reader sees either the old file or the whole new one. A symbolic link is
/// followed; a device or FIFO is written through (see [`OutputTarget`]).
///
/// # Errors
/// Any I/O error, naming `path`; a directory or other non-file at `path` is refused.
pub fn write_file_atomically(path: &Path, contents: &[u8]) -> Result<(), Error> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(contents)
        .map_err(|err| Error::io(file.path(), err))?;
    file.commit()
}

/// A file written as [`write_file_atomically`] writes one, for contents that arrive in pieces
/// (buffered): through a temporary sibling (`.NAME.tmp.PID`) that [`AtomicFile::commit`] syncs
/// and renames over the target, or straight to a device or FIFO. Dropped uncommitted, it removes
/// the sibling and leaves the target as it was.
pub struct AtomicFile {
    /// The file the user named (links followed).
    target: PathBuf,
    /// The temporary sibling, until committed; `None` for a device written through.
    tmp: Option<PathBuf>,
    out: io::BufWriter<fs::File>,
}

impl AtomicFile {
    /// Starts writing `path` (see [`OutputTarget`]).
    ///
    /// # Errors
    /// `path` is refused, or the file cannot be created.
    pub fn create(path: &Path) -> Result<Self, Error> {
        let (target, tmp) = match OutputTarget::of(path)? {
            OutputTarget::Replace(target) => {
                let tmp = sibling(&target, "tmp");
                (target, Some(tmp))
            }
            OutputTarget::WriteThrough(device) => (device, None),
        };
        let file = match &tmp {
            Some(tmp) => fs::File::create(tmp),
            None => fs::OpenOptions::new().write(true).open(&target),
        }
        .map_err(|err| Error::io(path, err))?;
        Ok(Self {
            target,
            tmp,
            out: io::BufWriter::with_capacity(1 << 16, file),
        })
    }

    /// The file being written (links followed).
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Flushes, syncs and renames the temporary sibling over the target.
    ///
    /// # Errors
    /// An I/O error naming the target; the target is then as it was.
    pub fn commit(mut self) -> Result<(), Error> {
        let fail = |err: io::Error| Error::io(&self.target, err);
        self.out.flush().map_err(fail)?;
        if let Some(tmp) = &self.tmp {
            self.out.get_ref().sync_all().map_err(fail)?;
            fs::rename(tmp, &self.target).map_err(fail)?;
        }
        // In place: nothing for `drop` to remove.
        self.tmp = None;
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.out.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.out.write_all(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if let Some(tmp) = &self.tmp {
            let _ = fs::remove_file(tmp);
        }
    }
}

/// Builds a directory with `fill` in a temporary sibling, then puts it in place of `dir`.
///
/// An existing `dir` is moved aside first and deleted only once the new one is in place; if
/// `fill` fails, `dir` is left untouched and the temporary directory removed.
///
/// # Errors
/// Whatever `fill` returns, or an I/O error naming `dir`.
pub fn replace_dir_atomically<E>(
    dir: &Path,
    fill: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E>
where
    E: From<Error>,
{
    let tmp = new_sibling_dir(dir)?;
    if let Err(err) = fill(&tmp) {
        let _ = fs::remove_dir_all(&tmp);
        return Err(err);
    }
    put_in_place(&tmp, dir).map_err(E::from)
}

/// A fresh, empty temporary sibling of `dir` (`.NAME.tmp.PID`), its parent created if needed.
pub(crate) fn new_sibling_dir(dir: &Path) -> Result<PathBuf, Error> {
    if let Some(parent) = dir.parent().filter(|p| !p.as_os_str().is_empty()) {
        fs::create_dir_all(parent).map_err(|err| Error::io(parent, err))?;
    }
    let tmp = sibling(dir, "tmp");
    let _ = fs::remove_dir_all(&tmp);
    fs::create_dir(&tmp).map_err(|err| Error::io(&tmp, err))?;
    Ok(tmp)
}

/// Renames the complete `tmp` into place as `dir`: an existing `dir` is moved aside first and
/// deleted only once the new one is in place; on failure `dir` is put back and `tmp` removed.
pub(crate) fn put_in_place(tmp: &Path, dir: &Path) -> Result<(), Error> {
    let old = sibling(dir, "old");
    let had_old = dir.exists();
    if had_old {
        let _ = fs::remove_dir_all(&old);
        fs::rename(dir, &old).map_err(|err| Error::io(dir, err))?;
    }
    if let Err(err) = fs::rename(tmp, dir) {
        if had_old {
            let _ = fs::rename(&old, dir);
        }
        let _ = fs::remove_dir_all(tmp);
        return Err(Error::io(dir, err));
    }
    if had_old {
        let _ = fs::remove_dir_all(&old);
    }
    Ok(())
}

/// Whether `dir` may be replaced by a recording: it is absent, an empty directory, or a hilsim
/// recording (a directory whose `meta.toml` names the format). Anything else is the user's.
///
/// # Errors
/// `dir` is something else (a file, a link, a directory of other things), with what it is.
pub fn check_replaceable_recording(dir: &Path) -> Result<(), Error> {
    let refuse = |what: &str| {
        Error::io(
            dir,
            io::Error::other(format!(
                "{what}; refusing to replace it (choose another directory, or empty this one)"
            )),
        )
    };
    let meta = match fs::symlink_metadata(dir) {
        Err(err) if err.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(err) => return Err(Error::io(dir, err)),
        Ok(meta) => meta,
    };
    if !meta.is_dir() {
        return Err(refuse("exists and is not a directory"));
    }
    let mut entries = fs::read_dir(dir).map_err(|err| Error::io(dir, err))?;
    if entries.next().is_none() {
        return Ok(());
    }
    if names_the_format(&dir.join("meta.toml")) {
        Ok(())
    } else {
        Err(refuse(
            "exists and holds something other than a hilsim recording",
        ))
    }
}

/// Whether `path` is a small regular file whose `format` key is the recording format's.
fn names_the_format(path: &Path) -> bool {
    // A real meta.toml is a few hundred bytes; anything large is not one.
    const MAX_META_BYTES: u64 = 1 << 20;
    let Ok(meta) = fs::symlink_metadata(path) else {
        return false;
    };
    if !meta.is_file() || meta.len() > MAX_META_BYTES {
        return false;
    }
    fs::read_to_string(path)
        .ok()
        .and_then(|text| text.parse::<toml::Table>().ok())
        .is_some_and(|table| table.get("format").and_then(|f| f.as_str()) == Some(FORMAT))
}

/// [`replace_dir_atomically`] for a recording's directory: refused unless `dir` may be replaced
/// ([`check_replaceable_recording`]).
///
/// # Errors
/// As [`check_replaceable_recording`] and [`replace_dir_atomically`].
pub fn replace_recording_dir<E>(
    dir: &Path,
    fill: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), E>
where
    E: From<Error>,
{
    tidy_after_killed_writers(dir)?;
    check_replaceable_recording(dir)?;
    replace_dir_atomically(dir, fill)
}

/// Tidies what writers of `dir` that were killed left beside it: an unfinished new recording
/// (`.NAME.tmp.PID`) is removed; a previous one moved aside (`.NAME.old.PID`) is put back when
/// `dir` is missing (the writer died between its two renames: that was the only copy), else
/// removed. Only leftovers of processes no longer running are touched.
///
/// It lists `dir`'s parent: call it once per output a command writes, not once per run of a
/// directory that holds many (a dataset tidies its own).
///
/// # Errors
/// A leftover that cannot be removed or put back.
pub fn tidy_after_killed_writers(dir: &Path) -> Result<(), Error> {
    let (Some(parent), Some(name)) = (dir.parent(), dir.file_name()) else {
        return Ok(());
    };
    let parent = if parent.as_os_str().is_empty() {
        Path::new(".")
    } else {
        parent
    };
    let Ok(entries) = fs::read_dir(parent) else {
        return Ok(());
    };
    let prefix = format!(".{}.", name.to_string_lossy());
    for entry in entries.flatten() {
        let file_name = entry.file_name().to_string_lossy().into_owned();
        let Some((tag, pid)) = file_name
            .strip_prefix(&prefix)
            .and_then(|rest| rest.split_once('.'))
        else {
            continue;
        };
        let Ok(pid) = pid.parse::<u32>() else {
            continue;
        };
        if !matches!(tag, "tmp" | "old") || process_may_run(pid) {
            continue;
        }
        let path = entry.path();
        if tag == "old" && fs::symlink_metadata(dir).is_err() {
            fs::rename(&path, dir).map_err(|err| Error::io(dir, err))?;
        } else if path.is_dir() {
            fs::remove_dir_all(&path).map_err(|err| Error::io(&path, err))?;
        } else {
            fs::remove_file(&path).map_err(|err| Error::io(&path, err))?;
        }
    }
    Ok(())
}

/// Whether process `pid` may still be running (this one, or any on a system without `/proc`).
fn process_may_run(pid: u32) -> bool {
    pid == std::process::id()
        || !Path::new("/proc/self").exists()
        || Path::new("/proc").join(pid.to_string()).exists()
}

/// `dir/.name.tag.PID`: hidden, in the same file system (so `rename` is atomic), unique per
/// process.
fn sibling(path: &Path, tag: &str) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".to_string());
    path.with_file_name(format!(".{name}.{tag}.{}", std::process::id()))
}
