//! The small numeric tables a scenario can name beside it (a recorded path, a lidar's scan
//! schedule): a header of known columns, then rows of finite numbers, read a line at a time.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use crate::scenario::ScenarioError;

/// The longest line read: a row of a handful of numbers is well under 200 bytes.
const MAX_LINE_BYTES: u64 = 4096;

/// Reads `path` as a CSV whose first line is exactly `header` (its columns joined by commas) and
/// whose every other line has that many finite numbers, handing each row to `row` with its
/// 1-based line number; at most `max_rows` rows. Blank lines are skipped; a `#` line is a comment.
///
/// # Errors
/// The file cannot be read, its header differs, a row is not numbers, or there are too many
/// rows; and whatever `row` returns (its message, at the row's line).
pub(crate) fn read_rows<const N: usize>(
    path: &Path,
    header: [&str; N],
    max_rows: usize,
    mut row: impl FnMut([f64; N]) -> Result<(), String>,
) -> Result<usize, ScenarioError> {
    let error = |line: Option<usize>, message: String| ScenarioError {
        file: path.to_path_buf(),
        line,
        message,
    };
    let file = std::fs::File::open(path).map_err(|e| error(None, format!("cannot read: {e}")))?;
    let mut reader = BufReader::new(file);
    let mut buf = Vec::new();
    let mut line_no = 0;
    let mut rows = 0;
    let mut header_seen = false;
    loop {
        buf.clear();
        let read = (&mut reader)
            .take(MAX_LINE_BYTES + 1)
            .read_until(b'\n', &mut buf)
            .map_err(|e| error(None, format!("cannot read: {e}")))?;
        if read == 0 {
            break;
        }
        line_no += 1;
        if buf.len() as u64 > MAX_LINE_BYTES {
            return Err(error(
                Some(line_no),
                format!("a line longer than {MAX_LINE_BYTES} bytes; not a table of numbers"),
            ));
        }
        let text = std::str::from_utf8(&buf)
            .map_err(|_| error(Some(line_no), "not UTF-8 text".to_string()))?
            .trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        if !header_seen {
            let expected = header.join(",");
            if text != expected {
                return Err(error(
                    Some(line_no),
                    format!("expected the header `{expected}`"),
                ));
            }
            header_seen = true;
            continue;
        }
        if rows == max_rows {
            return Err(error(
                Some(line_no),
                format!("more than {max_rows} rows; the limit of this table"),
            ));
        }
        let mut values = [0.0; N];
        let mut fields = text.split(',');
        for (k, value) in values.iter_mut().enumerate() {
            let field = fields.next().map(str::trim).unwrap_or_default();
            *value = field
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    error(
                        Some(line_no),
                        format!("`{}`: expected a finite number, found `{field}`", header[k]),
                    )
                })?;
        }
        if fields.next().is_some() {
            return Err(error(
                Some(line_no),
                format!("more than the header's {N} columns"),
            ));
        }
        row(values).map_err(|message| error(Some(line_no), message))?;
        rows += 1;
    }
    if !header_seen {
        return Err(error(
            None,
            format!("empty; expected the header `{}`", header.join(",")),
        ));
    }
    Ok(rows)
}
