//! A capture file or a serial device decoded to its end, as `hilsim decode` does: the counts,
//! the readings as a CSV table written atomically, and the counts' summary as it is printed.
//!
//! The input is opened read-only and read until the stream ends (see [`crate::decode`]). The
//! CSV is written to a hidden temporary sibling and renamed into place when complete, so a
//! failed run never leaves half a file where a good one was.

use std::convert::Infallible;
use std::fmt;
use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use hilsim_lidar_protocols::{HostDecoder, LidarModel, Point};
use hilsim_recording::{check_output_file, AtomicFile, FileKind};
use serde::Serialize;

use crate::decode::{
    decode_stream, decode_unit_stream, decoded_csv_rows, unit_csv_row, DecodeCounts, DecodeError,
    UnitDecodeCounts, DECODED_CSV_HEADER, UNIT_CSV_HEADER,
};

/// `decode --csv`'s table, as a previous one is recognised: by its header.
const DECODED_CSV: FileKind = FileKind {
    name: "a table of decoded readings",
    starts_with: DECODED_CSV_HEADER.as_bytes(),
};

/// `decode --csv --model M`'s table, recognised by its header.
const UNIT_CSV: FileKind = FileKind {
    name: "a table of decoded readings",
    starts_with: UNIT_CSV_HEADER.as_bytes(),
};

/// What a capture held: the XV-11's counts, or another unit's. Serialises as the counts
/// themselves (`hilsim decode --json`'s object).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Decoded {
    /// The Neato XV-11's stream.
    Xv11(DecodeCounts),
    /// Another unit's stream (`--model M`).
    Unit(UnitDecodeCounts),
}

/// Why a capture could not be decoded; each names the path concerned.
#[derive(Debug)]
#[non_exhaustive]
pub enum CaptureError {
    /// The input could not be opened (`detail` says why).
    Open {
        /// The input.
        path: PathBuf,
        /// Why, as one phrase.
        detail: String,
    },
    /// The input is a directory.
    IsDirectory(PathBuf),
    /// Reading the input failed.
    Read(PathBuf, io::Error),
    /// Writing the CSV failed.
    Write(PathBuf, io::Error),
    /// The CSV's place was refused, or its file could not be created or committed.
    Output(hilsim_recording::Error),
}

impl fmt::Display for CaptureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Open { path, detail } => write!(f, "{}: cannot open: {detail}", path.display()),
            Self::IsDirectory(path) => write!(
                f,
                "{}: is a directory, expected a capture file or a serial device",
                path.display()
            ),
            Self::Read(path, _) => write!(f, "{}: cannot read", path.display()),
            Self::Write(path, _) => write!(f, "{}: cannot write", path.display()),
            Self::Output(err) => err.fmt(f),
        }
    }
}

impl std::error::Error for CaptureError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Read(_, err) | Self::Write(_, err) => Some(err),
            Self::Output(err) => err.source(),
            Self::Open { .. } | Self::IsDirectory(_) => None,
        }
    }
}

impl From<hilsim_recording::Error> for CaptureError {
    fn from(err: hilsim_recording::Error) -> Self {
        Self::Output(err)
    }
}

/// Decodes `input` (a capture file or a serial device) in the protocol of `model`, writing one
/// CSV row per reading to `csv` when given (never over the input).
///
/// # Errors
/// The input cannot be opened or read (a directory, a missing file…), or the CSV refused or
/// not written.
pub fn decode_capture(
    input: &Path,
    model: LidarModel,
    csv: Option<&Path>,
) -> Result<Decoded, CaptureError> {
    let mut source = open_input(input)?;
    let cannot_read = |err| CaptureError::Read(input.to_path_buf(), err);
    let Some(mut decoder) = hilsim_lidar_protocols::decoder_for(model) else {
        let Some(path) = csv else {
            return decode_stream::<Infallible>(&mut source, None)
                .map(Decoded::Xv11)
                .map_err(|err| sink_error(err, cannot_read, |never| match never {}));
        };
        let mut out = create_csv(path, input, DECODED_CSV, DECODED_CSV_HEADER)?;
        let mut rows = String::new();
        let mut write = |revolution: &_| -> io::Result<()> {
            rows.clear();
            decoded_csv_rows(revolution, &mut rows);
            out.write_all(rows.as_bytes())
        };
        let counts = decode_stream(&mut source, Some(&mut write))
            .map_err(|err| sink_error(err, cannot_read, cannot_write(path)))?;
        out.commit()?;
        return Ok(Decoded::Xv11(counts));
    };
    decode_unit(&mut source, input, model, &mut *decoder, csv).map(Decoded::Unit)
}

/// [`decode_capture`] for a unit other than the XV-11.
fn decode_unit(
    source: &mut File,
    input: &Path,
    model: LidarModel,
    decoder: &mut dyn HostDecoder,
    csv: Option<&Path>,
) -> Result<UnitDecodeCounts, CaptureError> {
    let cannot_read = |err| CaptureError::Read(input.to_path_buf(), err);
    let Some(path) = csv else {
        return decode_unit_stream::<Infallible>(source, model, decoder, None)
            .map_err(|err| sink_error(err, cannot_read, |never| match never {}));
    };
    let mut out = create_csv(path, input, UNIT_CSV, UNIT_CSV_HEADER)?;
    let mut row = String::new();
    let mut write = |rev: u64, point: &Point| -> io::Result<()> {
        row.clear();
        unit_csv_row(rev, point, &mut row);
        out.write_all(row.as_bytes())
    };
    let counts = decode_unit_stream(source, model, decoder, Some(&mut write))
        .map_err(|err| sink_error(err, cannot_read, cannot_write(path)))?;
    out.commit()?;
    Ok(counts)
}

fn sink_error<E>(
    err: DecodeError<E>,
    read: impl FnOnce(io::Error) -> CaptureError,
    sink: impl FnOnce(E) -> CaptureError,
) -> CaptureError {
    match err {
        DecodeError::Read(err) => read(err),
        DecodeError::Sink(err) => sink(err),
    }
}

fn cannot_write(path: &Path) -> impl FnOnce(io::Error) -> CaptureError + '_ {
    move |err| CaptureError::Write(path.to_path_buf(), err)
}

/// The CSV at `path`, its header written: replaced atomically when complete, or written through
/// a device (see [`AtomicFile`]); never over the `input`.
fn create_csv(
    path: &Path,
    input: &Path,
    kind: FileKind,
    header: &str,
) -> Result<AtomicFile, CaptureError> {
    check_output_file(path, kind, &[input])?;
    let mut out = AtomicFile::create(path)?;
    writeln!(out, "{header}").map_err(cannot_write(path))?;
    Ok(out)
}

fn open_input(input: &Path) -> Result<File, CaptureError> {
    let open = |detail: String| CaptureError::Open {
        path: input.to_path_buf(),
        detail,
    };
    let file = match File::open(input) {
        Ok(file) => file,
        Err(err) if err.kind() == io::ErrorKind::NotFound => {
            return Err(open("no such file or device".to_string()))
        }
        Err(err) => return Err(open(err.to_string())),
    };
    // Opening a directory succeeds on Unix; reading it would fail with a vaguer message.
    match file.metadata() {
        Ok(meta) if meta.is_dir() => Err(CaptureError::IsDirectory(input.to_path_buf())),
        Ok(_) => Ok(file),
        Err(err) => Err(open(err.to_string())),
    }
}

impl Decoded {
    /// The counts as `hilsim decode` prints them, a few lines naming `input`.
    ///
    /// # Errors
    /// Writing to `w` failed.
    pub fn write_summary(&self, input: &Path, w: &mut dyn Write) -> io::Result<()> {
        match self {
            Self::Xv11(c) => {
                writeln!(
                    w,
                    "{}: {} bytes, {} packets ({} readings), {} bad checksums, {} bytes skipped, \
                     {} index gaps",
                    input.display(),
                    c.bytes,
                    c.packets,
                    c.readings,
                    c.bad_checksum,
                    c.skipped_bytes,
                    c.index_gaps,
                )?;
                writeln!(
                    w,
                    "readings: {} invalid, {} with strength warning",
                    c.invalid, c.strength_warning
                )?;
                if c.packets > 0 {
                    writeln!(
                        w,
                        "motor: {:.2} rpm median ({:.2} to {:.2})",
                        c.rpm_median, c.rpm_min, c.rpm_max
                    )
                } else {
                    writeln!(w, "motor: no packets, no speed")
                }
            }
            Self::Unit(c) => {
                writeln!(
                    w,
                    "{} ({}): {} bytes, {} packets ({} readings, {} without a return), {} bad \
                     checksums, {} bytes skipped",
                    input.display(),
                    c.model,
                    c.bytes,
                    c.packets,
                    c.readings,
                    c.no_return,
                    c.bad_checksum,
                    c.skipped_bytes,
                )?;
                if c.rev_hz_median > 0.0 {
                    writeln!(
                        w,
                        "revolutions: {} begun, {:.2} Hz median as reported",
                        c.revolutions, c.rev_hz_median
                    )
                } else {
                    writeln!(w, "revolutions: {} begun", c.revolutions)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_lidar_emulator::neato_packet::{encode_revolution, Reading};

    /// Two revolutions, the second with a damaged packet (index 5) and a lost one (index 6).
    fn sample_capture() -> Vec<u8> {
        let mut readings: [Reading; 360] =
            std::array::from_fn(|angle| Reading::distance(1000 + angle as u16, 50));
        readings[2] = Reading::error(0x35);
        readings[3].strength_warning = true;
        let mut wire = Vec::new();
        encode_revolution(&readings, 300.0, &mut wire);
        encode_revolution(&readings, 310.0, &mut wire);
        let second = 1980;
        wire[second + 5 * 22 + 9] ^= 0xFF;
        wire.drain(second + 6 * 22..second + 7 * 22);
        wire
    }

    fn decode_xv11(input: &Path, csv: Option<&Path>) -> Result<Decoded, CaptureError> {
        decode_capture(input, LidarModel::Xv11, csv)
    }

    /// The counts and the summary of `bytes`, with the CSV's text when `csv`.
    fn run_on(bytes: &[u8], csv: bool) -> (DecodeCounts, String, Option<String>) {
        let dir = tempfile::tempdir().expect("temp dir");
        let input = dir.path().join("capture.bin");
        std::fs::write(&input, bytes).expect("write capture");
        let csv_path = dir.path().join("out.csv");
        let decoded = decode_xv11(&input, csv.then_some(csv_path.as_path())).expect("decodes");
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .expect("list dir")
            .filter_map(|entry| entry.ok())
            .filter(|entry| entry.file_name().to_string_lossy().contains(".tmp."))
            .collect();
        assert!(leftovers.is_empty(), "temporary file left behind");
        let csv_text = csv.then(|| std::fs::read_to_string(&csv_path).expect("csv written"));
        let mut summary = Vec::new();
        decoded
            .write_summary(&input, &mut summary)
            .expect("in memory");
        let Decoded::Xv11(counts) = decoded else {
            panic!("an XV-11 capture")
        };
        let summary = String::from_utf8(summary).expect("utf-8");
        (counts, summary, csv_text)
    }

    #[test]
    fn counts_what_the_capture_holds() {
        let (c, summary, _) = run_on(&sample_capture(), false);
        assert_eq!(c.bytes, 1980 * 2 - 22);
        assert_eq!(c.packets, 178);
        assert_eq!(c.bad_checksum, 1);
        assert_eq!(c.skipped_bytes, 22);
        assert_eq!(c.index_gaps, 1);
        assert_eq!(c.readings, 4 * 178);
        assert_eq!(c.invalid, 2);
        assert_eq!(c.strength_warning, 2);
        assert_eq!(c.rpm_min, 300.0);
        // 90 packets at 300 and 88 at 310: the two middle ones (ranks 88 and 89) are at 300.
        assert_eq!(c.rpm_median, 300.0);
        assert_eq!(c.rpm_max, 310.0);
        assert!(summary.contains("178 packets"), "{summary}");
        assert!(summary.contains("motor: 300.00 rpm median (300.00 to 310.00)"));
    }

    #[test]
    fn csv_has_one_row_per_reading() {
        let (_, _, csv) = run_on(&sample_capture(), true);
        let csv = csv.expect("csv requested");
        let mut lines = csv.lines();
        assert_eq!(lines.next(), Some(DECODED_CSV_HEADER));
        let rows: Vec<Vec<&str>> = lines.map(|line| line.split(',').collect()).collect();
        assert_eq!(rows.len(), 4 * 178);
        assert_eq!(
            rows[0],
            ["0", "0", "0", "1000", "1.000", "50", "0", "0", "", "300"]
        );
        assert_eq!(
            rows[2],
            ["0", "0", "2", "0", "0.000", "0", "1", "0", "0x35", "300"]
        );
        assert_eq!(rows[3][7], "1");
        let second: Vec<_> = rows.iter().filter(|row| row[0] == "1").collect();
        assert_eq!(second.len(), 4 * 88);
        assert!(second.iter().all(|row| row[1] != "5" && row[1] != "6"));
        assert_eq!(second[4 * 5][2], "28", "angles 20..27 are missing");
    }

    #[test]
    fn empty_input_reports_zeros_not_nan() {
        let (c, summary, csv) = run_on(&[], true);
        assert_eq!(c.packets, 0);
        assert_eq!(c.rpm_median, 0.0);
        assert!(
            summary.ends_with("motor: no packets, no speed\n"),
            "{summary}"
        );
        assert_eq!(
            csv.as_deref(),
            Some(format!("{DECODED_CSV_HEADER}\n").as_str())
        );
    }

    #[test]
    fn missing_input_names_the_file_and_leaves_the_csv_alone() {
        let dir = tempfile::tempdir().expect("temp dir");
        let input = dir.path().join("nope.bin");
        let csv = dir.path().join("good.csv");
        std::fs::write(&csv, "keep me").expect("write csv");
        let err = decode_xv11(&input, Some(&csv)).expect_err("missing input");
        let message = err.to_string();
        assert!(
            message.contains("nope.bin") && message.contains("cannot open"),
            "{message}"
        );
        assert_eq!(std::fs::read_to_string(&csv).expect("csv kept"), "keep me");
    }

    #[test]
    fn directory_input_is_a_clean_error() {
        let dir = tempfile::tempdir().expect("temp dir");
        let err = decode_xv11(dir.path(), None).expect_err("directory");
        assert!(err.to_string().contains("is a directory"));
    }

    #[test]
    fn unwritable_csv_names_the_csv() {
        let dir = tempfile::tempdir().expect("temp dir");
        let input = dir.path().join("capture.bin");
        std::fs::write(&input, sample_capture()).expect("write capture");
        let csv = dir.path().join("no-such-dir").join("out.csv");
        let err = decode_xv11(&input, Some(&csv)).expect_err("bad csv dir");
        assert!(err.to_string().contains("out.csv"), "{err}");
    }
}
