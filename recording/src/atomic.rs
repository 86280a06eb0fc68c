//! Writes that never leave a half-written file where a good one stood.
//!
//! Not `tempfile`: its files are created `0600` with random names, while these keep the
//! umask's permissions and the `.NAME.tmp.PID` / `.NAME.old.PID` names that `hilsim-dataset`
//! recognises as leftovers of an interrupted write and removes.

use std::fs;
use std::io::{self, Read, Write};
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Component, Path, PathBuf};

use crate::{Error, FORMAT};

/// Where an output file goes, decided before anything is written: a user's path is never
/// replaced by something of another kind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputTarget {
    /// A regular file (or nothing yet) at this path, symbolic links followed: written to a
    /// temporary sibling and renamed over it.
    Replace(PathBuf),
    /// A character device or a FIFO (`/dev/null`, a named pipe): written through, as a shell's
    /// `>` would, never replaced.
    WriteThrough(PathBuf),
    /// This process's standard output (`/dev/stdout`, `/dev/fd/1`, or the very file the shell
    /// redirected it to): written through the descriptor the shell opened, so that `>> log`
    /// appends and a pipe is fed, and nothing is renamed over the shell's file.
    Stdout,
}

impl OutputTarget {
    /// Whether writing to `path` writes this process's standard output (then a command's own
    /// lines go beside it, to stderr, not into it).
    #[must_use]
    pub fn is_stdout(path: &Path) -> bool {
        Self::of(path).is_ok_and(|t| t == Self::Stdout)
    }

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
        // `stat` follows the links, `/proc/self/fd/1`'s magic one too (to a pipe, which has no
        // path to canonicalize).
        let meta = match fs::metadata(path) {
            Ok(meta) => meta,
            Err(err) if is_link && err.kind() == io::ErrorKind::NotFound => {
                return Err(refuse("is a symbolic link that leads nowhere"))
            }
            Err(err) => return Err(Error::io(path, err)),
        };
        if is_stdout(&meta) {
            return Ok(Self::Stdout);
        }
        let kind = meta.file_type();
        if kind.is_file() {
            // Follow a link: the file the user names is the one they mean. (Otherwise keep the
            // path as given, so that messages name it as the user wrote it.)
            let target = if is_link {
                fs::canonicalize(path).map_err(|err| Error::io(path, err))?
            } else {
                path.to_path_buf()
            };
            Ok(Self::Replace(target))
        } else if kind.is_char_device() || kind.is_fifo() {
            Ok(Self::WriteThrough(path.to_path_buf()))
        } else if kind.is_dir() {
            Err(refuse("is a directory"))
        } else {
            Err(refuse("is not a regular file"))
        }
    }
}

/// Whether `meta` is the file (or pipe, or terminal) this process's standard output is.
fn is_stdout(meta: &fs::Metadata) -> bool {
    let Ok(stdout) = stdout_file() else {
        return false;
    };
    stdout
        .metadata()
        .is_ok_and(|out| out.dev() == meta.dev() && out.ino() == meta.ino())
}

/// A second descriptor of standard output, sharing the shell's open file (its offset and its
/// append mode).
fn stdout_file() -> io::Result<fs::File> {
    use std::os::fd::AsFd;
    Ok(fs::File::from(io::stdout().as_fd().try_clone_to_owned()?))
}

/// What a single-file output is, so that a previous output of its kind can be told from a
/// user's file at its path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileKind {
    /// What it is, for messages ("an MCAP file").
    pub name: &'static str,
    /// The bytes every file of this kind starts with.
    pub starts_with: &'static [u8],
}

/// Checks, before any work, that a command may write its single-file output at `path`: a
/// device, a FIFO or standard output is written through; a regular file (links followed) is
/// replaced only when it is empty or a previous output of `kind`, and never when it is one of
/// the command's `inputs`. What killed writers of `path` left beside it is tidied.
///
/// # Errors
/// `path` is an input, a file of another kind, or refused by [`OutputTarget::of`].
pub fn check_output_file(path: &Path, kind: FileKind, inputs: &[&Path]) -> Result<(), Error> {
    let refuse = |what: String| Error::io(path, io::Error::other(what));
    if let Some(input) = inputs.iter().find(|input| is_same_file(path, input)) {
        return Err(refuse(if input == &path {
            "is an input of this command; refusing to write over it".to_string()
        } else {
            format!(
                "is the same file as the input {}; refusing to write over it",
                input.display()
            )
        }));
    }
    let OutputTarget::Replace(target) = OutputTarget::of(path)? else {
        return Ok(());
    };
    tidy_after_killed_writers(&target)?;
    let mut head = Vec::with_capacity(kind.starts_with.len());
    match fs::File::open(&target) {
        Err(err) if err.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(err) => return Err(Error::io(path, err)),
        Ok(file) => {
            file.take(kind.starts_with.len() as u64)
                .read_to_end(&mut head)
                .map_err(|err| Error::io(path, err))?;
        }
    }
    if head.is_empty() || head == kind.starts_with {
        Ok(())
    } else {
        Err(refuse(format!(
            "exists and is not {}; refusing to replace it (choose another name, or remove it)",
            kind.name
        )))
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

/// [`write_file_atomically`] for a file inside an output directory the command owns (a report's
/// page, a dataset's manifest): a symbolic link there leads to a file that is not the
/// directory's, such as another report's page, so it is refused, never followed.
///
/// # Errors
/// `path` is a symbolic link, or as [`write_file_atomically`].
pub fn write_owned_file_atomically(path: &Path, contents: &[u8]) -> Result<(), Error> {
    if fs::symlink_metadata(path).is_ok_and(|meta| meta.file_type().is_symlink()) {
        return Err(Error::io(
            path,
            io::Error::other(
                "is a symbolic link to a file outside this output; refusing to write through it \
                 (remove the link)",
            ),
        ));
    }
    write_file_atomically(path, contents)
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
        let open = |result: io::Result<fs::File>| result.map_err(|err| Error::io(path, err));
        let (target, tmp, file) = match OutputTarget::of(path)? {
            OutputTarget::Replace(target) => {
                let tmp = sibling(&target, "tmp");
                let file = open(fs::File::create(&tmp))?;
                (target, Some(tmp), file)
            }
            OutputTarget::WriteThrough(device) => {
                let file = open(fs::OpenOptions::new().write(true).open(&device))?;
                (device, None, file)
            }
            OutputTarget::Stdout => (path.to_path_buf(), None, open(stdout_file())?),
        };
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

/// The directory a recording output named `dir` is put at: a symbolic link to a directory is
/// followed (the user means the directory it leads to), and a path without a last name (`.`,
/// `..`, `/`) or one that holds the working directory is refused, since replacing it would pull
/// the directory out from under the shell that runs the command.
///
/// # Errors
/// `dir` names no directory of its own, or holds the working directory.
pub fn resolve_output_dir(dir: &Path) -> Result<PathBuf, Error> {
    let refuse = |what: &str| Error::io(dir, io::Error::other(what.to_string()));
    let meta = match fs::symlink_metadata(dir) {
        Err(err) if err.kind() == io::ErrorKind::NotFound => None,
        Err(err) => return Err(Error::io(dir, err)),
        Ok(meta) => Some(meta),
    };
    let resolved = match &meta {
        Some(meta) if meta.is_dir() || (meta.is_symlink() && dir.is_dir()) => {
            fs::canonicalize(dir).map_err(|err| Error::io(dir, err))?
        }
        _ => dir.to_path_buf(),
    };
    let cwd = std::env::current_dir().and_then(fs::canonicalize);
    if meta.is_some() && cwd.is_ok_and(|cwd| cwd.starts_with(&resolved)) {
        return Err(refuse(
            "is the working directory or holds it, and an output directory is replaced whole; \
             name a new directory (for example --out run1)",
        ));
    }
    if matches!(
        dir.components().next_back(),
        None | Some(Component::CurDir | Component::ParentDir | Component::RootDir)
    ) {
        return Err(refuse(
            "names no directory of its own; name a new directory (for example --out run1)",
        ));
    }
    Ok(if meta.as_ref().is_some_and(fs::Metadata::is_symlink) {
        resolved
    } else {
        dir.to_path_buf()
    })
}

/// Refuses an `input` that lies inside the output directory `dir` (which the command replaces
/// whole), before any work: the command would delete what it reads.
///
/// # Errors
/// `input` is `dir` or inside it.
pub fn check_input_outside(input: &Path, dir: &Path) -> Result<(), Error> {
    let (Ok(input_real), Ok(dir_real)) = (fs::canonicalize(input), fs::canonicalize(dir)) else {
        return Ok(());
    };
    if input_real.starts_with(&dir_real) {
        return Err(Error::io(
            input,
            io::Error::other(format!(
                "lies inside the output directory {}, which is replaced whole; \
                 write the output to another directory",
                dir.display()
            )),
        ));
    }
    Ok(())
}

/// The names a hilsim recording directory's own files have: what a new recording replaces.
/// Anything else in the directory (a user's notes, plots) is the user's and is kept.
const RECORDING_OWN_NAMES: [&str; 7] = [
    "meta.toml",
    "commands.csv",
    "odometry.csv",
    "lidar.csv",
    "sonar.csv",
    "truth.csv",
    // `hilsim run --out`'s calibrations and metrics.
    "results.json",
];

/// Moves what the user keeps in the recording directory `dir` (every entry that is not a
/// recording's own file, nor written anew in `tmp`) into `tmp`, which is about to replace it.
fn carry_over_user_files(dir: &Path, tmp: &Path) -> Result<(), Error> {
    let Ok(entries) = fs::read_dir(dir) else {
        return Ok(());
    };
    for entry in entries {
        let entry = entry.map_err(|err| Error::io(dir, err))?;
        let name = entry.file_name();
        let own = name
            .to_str()
            .is_some_and(|name| RECORDING_OWN_NAMES.contains(&name));
        let to = tmp.join(&name);
        if own || fs::symlink_metadata(&to).is_ok() {
            continue;
        }
        fs::rename(entry.path(), &to).map_err(|err| Error::io(&entry.path(), err))?;
    }
    Ok(())
}

/// Puts the complete recording `tmp` in place of `dir`, carrying over the user's files that
/// `dir` holds beside a previous recording.
pub(crate) fn put_recording_in_place(tmp: &Path, dir: &Path) -> Result<(), Error> {
    if let Err(err) = carry_over_user_files(dir, tmp) {
        let _ = fs::remove_dir_all(tmp);
        return Err(err);
    }
    put_in_place(tmp, dir)
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
    let dir = resolve_output_dir(dir)?;
    tidy_after_killed_writers(&dir)?;
    check_replaceable_recording(&dir)?;
    let tmp = new_sibling_dir(&dir)?;
    if let Err(err) = fill(&tmp) {
        let _ = fs::remove_dir_all(&tmp);
        return Err(err);
    }
    put_recording_in_place(&tmp, &dir).map_err(E::from)
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
