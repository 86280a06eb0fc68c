//! Finding the scenario files `hilsim scenario test` runs, and loading them all before any runs.

use std::collections::HashSet;
use std::io;
use std::path::{Path, PathBuf};

/// A path that could not be read or listed.
#[derive(Debug, thiserror::Error)]
#[error("{}: {what}: {error}", path.display())]
pub struct DiscoverError {
    /// The file or directory.
    pub path: PathBuf,
    /// What failed ("cannot read", "cannot list").
    pub what: &'static str,
    /// Why.
    pub error: io::Error,
}

impl DiscoverError {
    fn at<'a>(path: &'a Path, what: &'static str) -> impl FnOnce(io::Error) -> Self + 'a {
        move |error| Self {
            path: path.to_path_buf(),
            what,
            error,
        }
    }
}

/// The scenario files at `path`: the file itself, or every `*.toml` below the directory in
/// name order, except `Cargo.toml` (a crate's manifest, as beside the checked-in scenarios);
/// each directory is entered once, however many links lead to it.
///
/// # Errors
/// [`DiscoverError`]: the path that could not be read or listed.
pub fn scenario_files(path: &Path) -> Result<Vec<PathBuf>, DiscoverError> {
    let mut files = Vec::new();
    collect(path, &mut files, &mut HashSet::new())?;
    Ok(files)
}

/// Collects below `path`, entering each directory once (`visited`: canonical paths), so links
/// that lead back up the tree end the walk instead of repeating it.
fn collect(
    path: &Path,
    files: &mut Vec<PathBuf>,
    visited: &mut HashSet<PathBuf>,
) -> Result<(), DiscoverError> {
    let meta = std::fs::metadata(path).map_err(DiscoverError::at(path, "cannot read"))?;
    // Anything but a directory is a scenario file to load (a device or a pipe is refused, with
    // its name, by the scenario reader).
    if !meta.is_dir() {
        files.push(path.to_path_buf());
        return Ok(());
    }
    let canonical = std::fs::canonicalize(path).map_err(DiscoverError::at(path, "cannot read"))?;
    if !visited.insert(canonical) {
        return Ok(());
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
        .map_err(DiscoverError::at(path, "cannot list"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for entry in entries {
        if entry.is_dir() {
            collect(&entry, files, visited)?;
        } else if entry.extension().is_some_and(|e| e == "toml")
            && entry.file_name().is_some_and(|n| n != "Cargo.toml")
        {
            files.push(entry);
        }
    }
    Ok(())
}

/// Why the scenarios under some paths cannot be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LoadError {
    /// A path cannot be searched.
    #[error(transparent)]
    Discover(#[from] DiscoverError),
    /// A scenario file is unreadable or invalid.
    #[error(transparent)]
    Scenario(#[from] hilsim_sim::ScenarioError),
    /// No scenario file under the paths (listed).
    #[error("{0}: no scenario files (*.toml) found")]
    Empty(String),
}

/// Every scenario file under `roots` (as [`scenario_files`] finds them), each loaded: all are
/// validated before any runs, so that bad input fails before work starts.
///
/// # Errors
/// A path cannot be searched, a file is invalid, or there is no file at all.
pub fn load_scenarios(
    roots: &[PathBuf],
) -> Result<Vec<(PathBuf, hilsim_sim::Scenario)>, LoadError> {
    let mut files = Vec::new();
    for root in roots {
        files.extend(scenario_files(root)?);
    }
    let scenarios: Vec<(PathBuf, hilsim_sim::Scenario)> = files
        .into_iter()
        .map(|f| hilsim_sim::Scenario::load(&f).map(|s| (f, s)))
        .collect::<Result<_, _>>()?;
    if scenarios.is_empty() {
        let roots: Vec<String> = roots.iter().map(|p| p.display().to_string()).collect();
        return Err(LoadError::Empty(roots.join(", ")));
    }
    Ok(scenarios)
}
