//! Where a report's page goes: a directory that is a previous report (or absent, or empty) and
//! never a user's page. Shared by `report`, `run --report` and `diagnose --report`.

use std::fs;
use std::io::Read;
use std::path::Path;

use anyhow::{bail, Context, Result};
use hilsim_recording::write_owned_file_atomically;

/// Refuses, before any work, a report directory that is not one: a file, or a directory whose
/// `index.html` is not a previous report (the user's page is never replaced). Without a previous
/// report's page there, none of the `files` the report adds beside its page may exist either:
/// they would be the user's.
pub fn check_report_dir(dir: &Path, files: &[&str]) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{}: exists and is not a directory", dir.display());
    }
    let page = dir.join("index.html");
    if fs::symlink_metadata(&page).is_err() {
        if let Some(file) = files
            .iter()
            .map(|f| dir.join(f))
            .find(|f| fs::symlink_metadata(f).is_ok())
        {
            bail!(
                "{}: exists, and {} is not a previous hilsim report's; not replacing it",
                file.display(),
                dir.display()
            );
        }
    } else {
        let mut head = Vec::new();
        fs::File::open(&page)
            .and_then(|f| f.take(4096).read_to_end(&mut head))
            .with_context(|| format!("{}: cannot read", page.display()))?;
        if !hilsim_report::is_report(&String::from_utf8_lossy(&head)) {
            bail!(
                "{}: exists and is not a hilsim report; not replacing it",
                page.display()
            );
        }
    }
    Ok(())
}

/// Writes `html` as `dir/index.html` (the directory created if needed), atomically.
pub fn write_report_page(dir: &Path, html: &str) -> Result<()> {
    check_report_dir(dir, &[])?;
    fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    write_owned_file_atomically(&dir.join("index.html"), html.as_bytes())?;
    Ok(())
}
