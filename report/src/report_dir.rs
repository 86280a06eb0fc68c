//! Where a report's files go: a directory that is a previous report (or absent, or empty) and
//! never a user's page. Shared by `hilsim report`, `run --report` and `diagnose --report`.

use std::fmt;
use std::fs;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

use hilsim_recording::write_owned_file_atomically;

/// Why a report directory was refused or could not be written; each names the path.
#[derive(Debug)]
#[non_exhaustive]
pub enum ReportDirError {
    /// The path exists and is not a directory.
    NotADirectory(PathBuf),
    /// A file the report would add exists, and the directory holds no previous report (the
    /// file, the directory).
    NotOurs(PathBuf, PathBuf),
    /// The directory's `index.html` is not a report's page.
    NotAReport(PathBuf),
    /// The page could not be read, or the directory created.
    Io(PathBuf, &'static str, io::Error),
    /// A file could not be written.
    Write(hilsim_recording::Error),
}

impl fmt::Display for ReportDirError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotADirectory(dir) => {
                write!(f, "{}: exists and is not a directory", dir.display())
            }
            Self::NotOurs(file, dir) => write!(
                f,
                "{}: exists, and {} is not a previous hilsim report's; not replacing it",
                file.display(),
                dir.display()
            ),
            Self::NotAReport(page) => write!(
                f,
                "{}: exists and is not a hilsim report; not replacing it",
                page.display()
            ),
            Self::Io(path, what, _) => write!(f, "{}: {what}", path.display()),
            Self::Write(err) => err.fmt(f),
        }
    }
}

impl std::error::Error for ReportDirError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io(_, _, err) => Some(err),
            Self::Write(err) => err.source(),
            _ => None,
        }
    }
}

/// Refuses, before any work, a report directory that is not one: a file, or a directory whose
/// `index.html` is not a previous report (the user's page is never replaced). Without a previous
/// report's page there, none of the `files` the report adds beside its page may exist either:
/// they would be the user's.
///
/// # Errors
/// As said, or the page cannot be read.
pub fn check_report_dir(dir: &Path, files: &[&str]) -> Result<(), ReportDirError> {
    if dir.exists() && !dir.is_dir() {
        return Err(ReportDirError::NotADirectory(dir.to_path_buf()));
    }
    let page = dir.join("index.html");
    if fs::symlink_metadata(&page).is_err() {
        let mut theirs = files.iter().map(|f| dir.join(f));
        if let Some(file) = theirs.find(|f| fs::symlink_metadata(f).is_ok()) {
            return Err(ReportDirError::NotOurs(file, dir.to_path_buf()));
        }
        return Ok(());
    }
    let mut head = Vec::new();
    fs::File::open(&page)
        .and_then(|f| f.take(4096).read_to_end(&mut head))
        .map_err(|err| ReportDirError::Io(page.clone(), "cannot read", err))?;
    if !crate::is_report(&String::from_utf8_lossy(&head)) {
        return Err(ReportDirError::NotAReport(page));
    }
    Ok(())
}

/// Writes each of `files` (name, contents; the page `index.html` among them) into `dir`,
/// created if needed, each atomically, once [`check_report_dir`] has allowed them.
///
/// # Errors
/// The directory is refused, cannot be created, or a file cannot be written.
pub fn write_report_files(dir: &Path, files: &[(String, String)]) -> Result<(), ReportDirError> {
    let names: Vec<&str> = files.iter().map(|(name, _)| name.as_str()).collect();
    check_report_dir(dir, &names)?;
    fs::create_dir_all(dir).map_err(|err| ReportDirError::Io(dir.into(), "cannot create", err))?;
    for (name, text) in files {
        write_owned_file_atomically(&dir.join(name), text.as_bytes())
            .map_err(ReportDirError::Write)?;
    }
    Ok(())
}
