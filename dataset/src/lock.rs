//! One writer per manifest: two processes making the same runs of one directory would remove
//! each other's half-written runs, so the second is refused while the first lives.
//!
//! The lock is per manifest (the whole dataset's, or a shard's), not per directory: shards of
//! one dataset share a directory by design. It is an advisory `flock` on `DIR/.MANIFEST.lock`,
//! released by the kernel however the holder ends; the file holds the holder's PID for the
//! message, and is removed when the holder is done, so a finished dataset holds only its runs.

use std::fs::{self, File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::os::fd::AsRawFd;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

use nix::errno::Errno;
use nix::fcntl::{flock, FlockArg};

use crate::Error;

/// Held while this process writes a manifest's runs; dropping it removes the lock file.
#[derive(Debug)]
pub(crate) struct WriterLock {
    path: PathBuf,
    // Closed after the file is removed (fields drop after `drop`), so no one locks a file
    // that is about to go.
    _file: File,
}

impl WriterLock {
    /// Takes the lock of `manifest` in `dir`, without waiting.
    ///
    /// # Errors
    /// [`Error::Busy`] when another process holds it; [`Error::Io`] when the file cannot be made.
    pub(crate) fn take(dir: &Path, manifest: &str) -> Result<Self, Error> {
        let path = dir.join(format!(".{manifest}.lock"));
        loop {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(|err| Error::io(&path, err))?;
            match flock(file.as_raw_fd(), FlockArg::LockExclusiveNonblock) {
                Ok(()) => {}
                Err(Errno::EWOULDBLOCK) => {
                    let mut text = String::new();
                    // A PID is a few digits; the holder may not have written it yet.
                    let _ = (&mut file).take(32).read_to_string(&mut text);
                    return Err(Error::Busy {
                        dir: dir.to_path_buf(),
                        manifest: manifest.to_string(),
                        pid: text.trim().parse().ok(),
                    });
                }
                Err(err) => return Err(Error::io(&path, err.into())),
            }
            // A holder that finished removed the file after this process opened it: the lock
            // is on a file no one else will open, so take the one at the path now.
            let current = fs::metadata(&path).map(|m| (m.dev(), m.ino())).ok();
            let locked = file.metadata().map(|m| (m.dev(), m.ino())).ok();
            if current.is_none() || current != locked {
                continue;
            }
            file.set_len(0).map_err(|err| Error::io(&path, err))?;
            file.rewind().map_err(|err| Error::io(&path, err))?;
            write!(file, "{}", std::process::id()).map_err(|err| Error::io(&path, err))?;
            return Ok(Self { path, _file: file });
        }
    }
}

impl Drop for WriterLock {
    fn drop(&mut self) {
        let _ = fs::remove_file(&self.path);
    }
}

/// Whether the process `pid` (from a temporary's name) is alive: its temporaries are its own.
pub(crate) fn alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return false;
    }
    let Ok(pid) = i32::try_from(pid) else {
        return false;
    };
    if pid <= 0 {
        return false;
    }
    // Signal 0 checks that the process exists; EPERM: it does, as another user's.
    matches!(
        nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid), None),
        Ok(()) | Err(Errno::EPERM)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_writer_of_one_manifest_is_refused_naming_the_first() {
        let dir = tempfile::tempdir().unwrap();
        let first = WriterLock::take(dir.path(), "manifest.csv").unwrap();
        let err = WriterLock::take(dir.path(), "manifest.csv").unwrap_err();
        let pid = std::process::id();
        assert!(
            matches!(&err, Error::Busy { pid: Some(p), .. } if *p == pid),
            "{err}"
        );
        assert!(err.to_string().contains(&format!("pid {pid}")), "{err}");
        // Another shard's manifest is another writer's.
        let shard = WriterLock::take(dir.path(), "manifest-shard-1-of-2.csv").unwrap();
        drop((first, shard));
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            0,
            "lock files removed"
        );
        WriterLock::take(dir.path(), "manifest.csv").unwrap();
    }

    #[test]
    fn only_a_live_process_other_than_this_one_is_alive() {
        assert!(!alive(std::process::id()));
        assert!(!alive(0) && !alive(u32::MAX));
        // PID 1 always exists (another user's: EPERM).
        assert!(alive(1));
    }
}
