//! Writes that never leave a half-written file where a good one stood.
//!
//! Not `tempfile`: its files are created `0600` with random names, while these keep the
//! umask's permissions and the `.NAME.tmp.PID` / `.NAME.old.PID` names that `hilsim-dataset`
//! recognises as leftovers of an interrupted write and removes.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::Error;

/// Writes `contents` to `path` through a temporary file in the same directory, then renames it
/// over `path`, so a reader sees either the old file or the whole new one.
///
/// # Errors
/// Any I/O error, naming `path`.
pub fn write_file_atomically(path: &Path, contents: &[u8]) -> Result<(), Error> {
    let tmp = sibling(path, "tmp");
    let result = (|| {
        let mut file = fs::File::create(&tmp)?;
        file.write_all(contents)?;
        file.sync_all()?;
        fs::rename(&tmp, path)
    })();
    result.map_err(|err| {
        let _ = fs::remove_file(&tmp);
        Error::io(path, err)
    })
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
    if let Some(parent) = dir.parent().filter(|p| !p.as_os_str().is_empty()) {
        fs::create_dir_all(parent).map_err(|err| Error::io(parent, err))?;
    }
    let tmp = sibling(dir, "tmp");
    let _ = fs::remove_dir_all(&tmp);
    fs::create_dir(&tmp).map_err(|err| Error::io(&tmp, err))?;
    if let Err(err) = fill(&tmp) {
        let _ = fs::remove_dir_all(&tmp);
        return Err(err);
    }
    let old = sibling(dir, "old");
    let had_old = dir.exists();
    if had_old {
        let _ = fs::remove_dir_all(&old);
        fs::rename(dir, &old).map_err(|err| Error::io(dir, err))?;
    }
    if let Err(err) = fs::rename(&tmp, dir) {
        if had_old {
            let _ = fs::rename(&old, dir);
        }
        let _ = fs::remove_dir_all(&tmp);
        return Err(Error::io(dir, err).into());
    }
    if had_old {
        let _ = fs::remove_dir_all(&old);
    }
    Ok(())
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
