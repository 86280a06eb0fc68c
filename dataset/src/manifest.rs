//! The manifest: one CSV row per run made or failed, sorted by run.
//!
//! Columns: `run,seed,KEY…,status,recorded_s,lidar_samples,sonar_samples,odometry_samples,sha256,reason`
//! (one `KEY` column per `--vary`, in the order given). `status` is `ok` or `failed`; a failed
//! run has only `run`, `seed`, its values, `status` and `reason`. A sensor the robot lacks has an
//! empty samples cell. Fields holding a comma or a quote are quoted as RFC 4180 says.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::content::RunContent;
use crate::layout::{entries, is_manifest};
use crate::Error;

/// The largest manifest read (it is read whole): a row for each of [`crate::MAX_RUNS`] runs, at
/// most a KiB each (a failed run's reason is one line).
pub const MAX_MANIFEST_BYTES: u64 = 1 << 30;

/// A run's row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The run's index.
    pub run: u64,
    /// The run's seed.
    pub seed: u64,
    /// The run's value of each varied key.
    pub values: Vec<f64>,
    /// Made (with what its files hold) or failed (with why).
    pub outcome: Outcome,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The run's directory is complete.
    Made(RunContent),
    /// The run could not be made; the reason is one line.
    Failed(String),
}

/// The manifest's text for `rows`, with one column per key of `keys`.
#[must_use]
pub fn render(keys: &[&str], rows: &BTreeMap<u64, Row>) -> String {
    let mut s = String::from("run,seed,");
    for k in keys {
        s.push_str(&field(k));
        s.push(',');
    }
    s.push_str("status,recorded_s,lidar_samples,sonar_samples,odometry_samples,sha256,reason\n");
    let count = |n: Option<u64>| n.map(|n| n.to_string()).unwrap_or_default();
    for row in rows.values() {
        let _ = write!(s, "{},{},", row.run, row.seed);
        for v in &row.values {
            let _ = write!(s, "{v},");
        }
        match &row.outcome {
            Outcome::Made(c) => {
                let _ = writeln!(
                    s,
                    "ok,{},{},{},{},{},",
                    c.recorded_s,
                    count(c.lidar_samples),
                    count(c.sonar_samples),
                    count(c.odometry_samples),
                    c.sha256
                );
            }
            Outcome::Failed(reason) => {
                let _ = writeln!(s, "failed,,,,,,{}", field(reason));
            }
        }
    }
    s
}

/// A CSV field: quoted when it holds a comma, a quote or a line break (which are flattened).
fn field(text: &str) -> String {
    let text = text.replace(['\n', '\r'], " ");
    if text.contains([',', '"']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text
    }
}

/// What a manifest row says, as read back (for merging and carrying failures over).
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// The run's index.
    pub run: u64,
    /// `Some(hash)` for a run made, `None` for a failed one.
    pub sha256: Option<String>,
    /// Why it failed (empty for a run made).
    pub reason: String,
}

/// Reads a manifest's rows (columns found by name).
///
/// # Errors
/// The file cannot be read, or is not a manifest.
pub fn read(path: &Path) -> Result<Vec<Entry>, Error> {
    let text = hilsim_recording::read_small_text(path, MAX_MANIFEST_BYTES, "a manifest")?;
    let mut lines = text.lines();
    let header = split(lines.next().unwrap_or_default())
        .ok_or_else(|| Error::corrupt(path, "line 1: not a manifest header"))?;
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| Error::corrupt(path, format!("line 1: no `{name}` column")))
    };
    let (run, status, sha, reason) = (
        column("run")?,
        column("status")?,
        column("sha256")?,
        column("reason")?,
    );
    let mut out = Vec::new();
    for (i, line) in lines.enumerate() {
        let bad = |what: &str| Error::corrupt(path, format!("line {}: {what}", i + 2));
        let fields = split(line).ok_or_else(|| bad("unbalanced quotes"))?;
        if fields.len() != header.len() {
            return Err(bad(&format!(
                "expected {} fields, found {}",
                header.len(),
                fields.len()
            )));
        }
        let index = fields[run]
            .parse::<u64>()
            .map_err(|_| bad("expected a run number"))?;
        let entry = match fields[status].as_str() {
            "ok" => Entry {
                run: index,
                sha256: Some(fields[sha].clone()),
                reason: String::new(),
            },
            "failed" => Entry {
                run: index,
                sha256: None,
                reason: fields[reason].clone(),
            },
            other => return Err(bad(&format!("status `{other}`, expected ok or failed"))),
        };
        out.push(entry);
    }
    Ok(out)
}

/// The content hashes the manifests in `dir` (whole and shard) record, by run: for each run made,
/// each manifest that has its row, with the hash it records.
///
/// # Errors
/// A manifest cannot be read, or is not a manifest.
pub(crate) fn recorded_hashes(dir: &Path) -> Result<BTreeMap<u64, Vec<(PathBuf, String)>>, Error> {
    let mut hashes: BTreeMap<u64, Vec<(PathBuf, String)>> = BTreeMap::new();
    for (name, path) in entries(dir)? {
        if !is_manifest(&name) {
            continue;
        }
        for e in read(&path)? {
            if let Some(sha) = e.sha256 {
                hashes.entry(e.run).or_default().push((path.clone(), sha));
            }
        }
    }
    Ok(hashes)
}

/// Splits one CSV line (RFC 4180 quoting); `None` if a quote is left open.
fn split(line: &str) -> Option<Vec<String>> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        let cur = fields.last_mut()?;
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                cur.push('"');
            }
            ('"', true) => quoted = false,
            ('"', false) if cur.is_empty() => quoted = true,
            (',', false) => fields.push(String::new()),
            (c, _) => cur.push(c),
        }
    }
    (!quoted).then_some(fields)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    #[test]
    fn rows_render_and_read_back() {
        let mut rows = BTreeMap::new();
        rows.insert(
            1,
            Row {
                run: 1,
                seed: 99,
                values: vec![0.25],
                outcome: Outcome::Failed("robot.start: inside \"cylinder\" 0, or so".into()),
            },
        );
        rows.insert(
            0,
            Row {
                run: 0,
                seed: 7,
                values: vec![1.5],
                outcome: Outcome::Made(RunContent {
                    sha256: "ab".into(),
                    recorded_s: 2.0,
                    lidar_samples: Some(360),
                    sonar_samples: None,
                    odometry_samples: Some(40),
                }),
            },
        );
        let text = render(&["robot.start.x"], &rows);
        assert_eq!(
            text,
            "run,seed,robot.start.x,status,recorded_s,lidar_samples,sonar_samples,\
             odometry_samples,sha256,reason\n\
             0,7,1.5,ok,2,360,,40,ab,\n\
             1,99,0.25,failed,,,,,,\"robot.start: inside \"\"cylinder\"\" 0, or so\"\n"
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.csv");
        fs::write(&path, &text).unwrap();
        let back = read(&path).unwrap();
        assert_eq!(back[0].sha256.as_deref(), Some("ab"));
        assert_eq!(back[1].reason, "robot.start: inside \"cylinder\" 0, or so");
    }

    #[test]
    fn broken_manifests_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.csv");
        fs::write(&path, "run,status,sha256,reason\n0,ok,ab,\n1,maybe,,\n").unwrap();
        let err = read(&path).unwrap_err().to_string();
        assert!(
            err.ends_with("m.csv: line 3: status `maybe`, expected ok or failed"),
            "{err}"
        );
        fs::write(&path, "run,seed\n").unwrap();
        assert!(read(&path)
            .unwrap_err()
            .to_string()
            .contains("no `status` column"));
    }
}
