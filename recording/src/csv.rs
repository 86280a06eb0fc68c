//! A minimal reader for the recording's numeric CSV tables: a header row naming the columns, then
//! one row of comma-separated numbers per sample. Quoting is not part of the format.
//!
//! Hand-written rather than the `csv` crate: configured to the same rules (no quoting, `\n`
//! records, trimmed fields, blank lines skipped) the crate read a 100,000-row lidar table about
//! 12 % slower (53 ms against 47 ms), and its trimming and line breaks differ at the edges
//! (Unicode spaces, a lone `\r`), which would change what is accepted and where errors point.
//!
//! The table is streamed: one line is held at a time (at most [`MAX_LINE_BYTES`]), each row made
//! into its sample as it is read, so memory is the samples, not the text (see [`crate::input`]).

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::ops::Range;
use std::path::{Path, PathBuf};

use crate::input::{self, MAX_LINE_BYTES, MAX_TABLE_BYTES};
use crate::Error;

/// What a table is called in the errors of its limits.
const WHAT: &str = "a recording's table";

/// Makes each row of a table into a sample, in order; made from the table's header (the columns
/// it needs found there) and keeping what it needs between rows (the previous row's time).
pub(crate) type Parse<T> = Box<dyn FnMut(&Row) -> Result<T, Error>>;

/// Reads a table whole: `columns` finds the columns it needs in the header and gives the parser
/// that makes each row, in order, into a sample, handed to `keep`.
///
/// Errors are those a reader of the whole text finds first, in this order: a line that is not
/// UTF-8 (the first), an empty file, a row with the wrong number of fields (the first), the first
/// error of `columns`, the first error of the parser. So after an error the rest of the file is
/// still read (one line at a time) for an error that comes before it, and `keep` may have been
/// given samples before an error is returned. Two limits end the reading at once, with their own
/// error: a line longer than [`MAX_LINE_BYTES`], and more than [`MAX_TABLE_BYTES`] in all.
pub(crate) fn read_table<T>(
    path: &Path,
    columns: impl FnOnce(&Header) -> Result<Parse<T>, Error>,
    mut keep: impl FnMut(T),
) -> Result<(), Error> {
    let mut lines = Lines::open(path)?;
    let header = read_header(&mut lines)?;
    let width = header.columns.len();
    // The first error found, and whether it is a row of the wrong width (only a line that is not
    // UTF-8 comes before that).
    let (mut first, mut wrong_width) = (None, false);
    let mut parse = columns(&header).map_err(|err| first = Some(err)).ok();
    // Each field's byte range in its line, trimmed: one vector for every row.
    let mut fields = Vec::with_capacity(width);
    while let Some((line, text)) = lines.next()? {
        if wrong_width || text.trim().is_empty() {
            continue;
        }
        split_fields(text, &mut fields);
        if fields.len() != width {
            first = Some(header.wrong_width(line, fields.len()));
            wrong_width = true;
        } else if let (None, Some(parse)) = (&first, &mut parse) {
            let row = Row {
                header: &header,
                line,
                text,
                fields: &fields,
            };
            match parse(&row) {
                Ok(s) => keep(s),
                Err(err) => first = Some(err),
            }
        }
    }
    match first {
        Some(err) => Err(err),
        None => Ok(()),
    }
}

/// A table read one row at a time, holding one line: each row's sample, or the first error met
/// in the file's order (a line that is not UTF-8, a row of the wrong width, a value the parser
/// refuses), after which it ends. [`read_table`] finds the error a whole-file reader finds first;
/// this finds the first on the way.
pub(crate) struct TableRows<T> {
    lines: Lines,
    header: Header,
    parse: Parse<T>,
    fields: Vec<Range<usize>>,
    ended: bool,
}

impl<T> TableRows<T> {
    /// Opens the table and reads its header.
    pub(crate) fn open(
        path: &Path,
        columns: impl FnOnce(&Header) -> Result<Parse<T>, Error>,
    ) -> Result<Self, Error> {
        let mut lines = Lines::open(path)?;
        let header = read_header(&mut lines)?;
        let parse = columns(&header)?;
        Ok(Self {
            fields: Vec::with_capacity(header.columns.len()),
            lines,
            header,
            parse,
            ended: false,
        })
    }

    fn next_row(&mut self) -> Result<Option<T>, Error> {
        while let Some((line, text)) = self.lines.next()? {
            if text.trim().is_empty() {
                continue;
            }
            split_fields(text, &mut self.fields);
            if self.fields.len() != self.header.columns.len() {
                return Err(self.header.wrong_width(line, self.fields.len()));
            }
            let row = Row {
                header: &self.header,
                line,
                text,
                fields: &self.fields,
            };
            return (self.parse)(&row).map(Some);
        }
        Ok(None)
    }
}

impl<T> Iterator for TableRows<T> {
    type Item = Result<T, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.ended {
            return None;
        }
        let next = self.next_row().transpose();
        self.ended = !matches!(next, Some(Ok(_)));
        next
    }
}

/// The header: the first line that is not blank.
fn read_header(lines: &mut Lines) -> Result<Header, Error> {
    loop {
        match lines.next()? {
            None => {
                return Err(Error::format(
                    &lines.path,
                    Some(1),
                    "empty file: expected a header row",
                ))
            }
            Some((_, text)) if text.trim().is_empty() => {}
            Some((_, text)) => {
                let columns = text.split(',').map(|c| c.trim().to_string()).collect();
                return Ok(Header {
                    path: lines.path.clone(),
                    columns,
                });
            }
        }
    }
}

/// Sets `fields` to the byte ranges of `text`'s comma-separated fields, each trimmed.
fn split_fields(text: &str, fields: &mut Vec<Range<usize>>) {
    fields.clear();
    let mut start = 0;
    for field in text.split(',') {
        let lead = field.len() - field.trim_start().len();
        let len = field.trim().len();
        fields.push(start + lead..start + lead + len);
        start += field.len() + 1;
    }
}

/// The lines of a file, one at a time, bounded.
struct Lines {
    path: PathBuf,
    reader: BufReader<File>,
    line: usize,
    bytes: u64,
    buf: Vec<u8>,
}

impl Lines {
    fn open(path: &Path) -> Result<Self, Error> {
        let file = input::open_regular(path, MAX_TABLE_BYTES, WHAT)?;
        Ok(Self {
            path: path.to_path_buf(),
            reader: BufReader::with_capacity(1 << 16, file),
            line: 0,
            bytes: 0,
            buf: Vec::with_capacity(256),
        })
    }

    /// The next line with its 1-based number, without its line break (`\n`, and any `\r` before
    /// it), or `None` at the end of the file.
    fn next(&mut self) -> Result<Option<(usize, &str)>, Error> {
        self.buf.clear();
        let n = (&mut self.reader)
            .take(MAX_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut self.buf)
            .map_err(|err| Error::io(&self.path, err))?;
        if n == 0 {
            return Ok(None);
        }
        self.line += 1;
        self.bytes += n as u64;
        if self.bytes > MAX_TABLE_BYTES {
            return Err(input::too_large(&self.path, MAX_TABLE_BYTES, WHAT));
        }
        let bytes = match self.buf.strip_suffix(b"\n") {
            Some(line) => line,
            None if n > MAX_LINE_BYTES => {
                return Err(Error::format(
                    &self.path,
                    Some(self.line),
                    format!(
                        "line longer than {}; not {WHAT}",
                        input::size(MAX_LINE_BYTES as u64)
                    ),
                ))
            }
            None => &self.buf,
        };
        let text = std::str::from_utf8(bytes)
            .map_err(|_| Error::format(&self.path, Some(self.line), "not UTF-8 text"))?;
        // A byte-order mark some editors put first is no part of the header's first name.
        let text = if self.line == 1 {
            text.trim_start_matches('\u{feff}')
        } else {
            text
        };
        Ok(Some((self.line, text.trim_end_matches('\r'))))
    }
}

/// A table's header: its columns, found by name.
pub(crate) struct Header {
    path: PathBuf,
    columns: Vec<String>,
}

impl Header {
    /// The error for a row of `found` fields at `line`.
    fn wrong_width(&self, line: usize, found: usize) -> Error {
        Error::format(
            &self.path,
            Some(line),
            format!(
                "expected {} fields ({}), found {found}",
                self.columns.len(),
                self.columns.join(",")
            ),
        )
    }

    /// The index of a required column.
    pub(crate) fn column(&self, name: &str) -> Result<usize, Error> {
        self.optional_column(name).ok_or_else(|| {
            Error::format(
                &self.path,
                Some(1),
                format!(
                    "missing column `{name}` in header `{}`",
                    self.columns.join(",")
                ),
            )
        })
    }

    /// The index of a column that may be absent.
    pub(crate) fn optional_column(&self, name: &str) -> Option<usize> {
        self.columns.iter().position(|c| c == name)
    }
}

/// One data row.
pub(crate) struct Row<'h, 'f> {
    header: &'h Header,
    pub(crate) line: usize,
    text: &'f str,
    fields: &'f [Range<usize>],
}

impl Row<'_, '_> {
    /// The text of field `col`, trimmed.
    fn field(&self, col: usize) -> &str {
        &self.text[self.fields[col].clone()]
    }

    /// An error at this row's line.
    pub(crate) fn error(&self, msg: String) -> Error {
        Error::format(&self.header.path, Some(self.line), msg)
    }

    /// A finite float.
    pub(crate) fn f64(&self, col: usize) -> Result<f64, Error> {
        let text = self.field(col);
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error(format!(
                "column `{}`: expected a finite number, found `{text}`",
                self.header.columns[col]
            ))),
        }
    }

    /// A non-negative integer that fits `T`.
    pub(crate) fn uint<T: TryFrom<u64>>(&self, col: usize) -> Result<T, Error> {
        let text = self.field(col);
        text.parse::<u64>()
            .ok()
            .and_then(|v| T::try_from(v).ok())
            .ok_or_else(|| {
                self.error(format!(
                    "column `{}`: expected a non-negative integer in range, found `{text}`",
                    self.header.columns[col]
                ))
            })
    }

    /// A 0/1 flag.
    pub(crate) fn flag(&self, col: usize) -> Result<bool, Error> {
        match self.field(col) {
            "0" => Ok(false),
            "1" => Ok(true),
            other => Err(self.error(format!(
                "column `{}`: expected 0 or 1, found `{other}`",
                self.header.columns[col]
            ))),
        }
    }

    /// Fails when time went backwards relative to the previous row.
    pub(crate) fn check_time(&self, t: f64, previous: &mut Option<f64>) -> Result<(), Error> {
        if let Some(prev) = *previous {
            if t < prev {
                return Err(self.error(format!("time goes backwards: t_s = {t} after {prev}")));
            }
        }
        if t < 0.0 {
            return Err(self.error(format!("t_s must not be negative, found {t}")));
        }
        *previous = Some(t);
        Ok(())
    }
}
