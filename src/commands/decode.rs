//! `hilsim decode INPUT [--model M] [--csv OUT] [--json]`: decode a lidar's raw byte stream, the
//! Neato XV-11's by default.
//!
//! INPUT is a capture file or a serial device path. Either is opened read-only and read until
//! the stream ends, in chunks, so a capture of any size or a live port works in constant memory
//! (apart from the rpm histogram, bounded by 65,536 distinct speeds). A live port is therefore
//! read until its writer goes away: end of file, or `EIO`, which is what a pseudo-terminal
//! returns once the other side is closed. A real serial port is read as it is configured
//! (set 115200 8N1 raw with `stty` first); interrupt to stop reading a unit that never stops.
//!
//! `--csv OUT` writes one row per reading, in stream order:
//! `rev,packet_index,angle_deg,distance_mm,range_m,strength,invalid,warning,error_code,rpm`
//! where `rev` counts revolutions from 0 (a partial first one included; a revolution ends on
//! index 89 or when the index wraps), `packet_index` is 0..=89, `angle_deg` is
//! `4 * packet_index + slot` (0..=359, counter-clockwise as the ROS driver reads it),
//! `distance_mm` and `range_m` are 0 for an invalid reading, `invalid` and `warning` are 0/1,
//! `error_code` is the invalid reading's code as `0x21`-style hex (empty when valid) and `rpm`
//! is that packet's motor speed (`hilsim_hil::decode`). The file is written to a hidden temporary
//! sibling and renamed into place when complete, so a failed run never leaves half a file where
//! a good one was.
//!
//! `--json` prints one object: `bytes`, `packets`, `bad_checksum`, `skipped_bytes`,
//! `index_gaps`, `readings`, `invalid`, `strength_warning` (integers) and `rpm_min`,
//! `rpm_median`, `rpm_max` (floats over accepted packets, 0.0 when there are none).
//!
//! With `--model M` for another unit, the rows are `rev,angle_deg,distance_mm,range_m,intensity,
//! rev_hz` (the angle in the unit's own convention, the rate empty when its packets carry none)
//! and the JSON object is `hilsim_hil::decode::UnitDecodeCounts`.

use std::convert::Infallible;
use std::fs::File;
use std::io::{ErrorKind, Write};
use std::path::Path;

use anyhow::{anyhow, bail, Context};
use hilsim_hil::decode::{
    decode_stream, decode_unit_stream, decoded_csv_rows, unit_csv_row, DecodeCounts, DecodeError,
    UnitDecodeCounts, DECODED_CSV_HEADER, UNIT_CSV_HEADER,
};
use hilsim_sim::scenario::LidarModel;

use crate::cli::DecodeArgs;
use hilsim_recording::{check_output_file, AtomicFile, FileKind, OutputTarget};

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

/// `hilsim decode`: the XV-11's stream, or with `--model` another unit's.
///
/// # Errors
/// As [`run_xv11`].
pub fn run(args: &DecodeArgs, stdout: &mut dyn Write) -> anyhow::Result<()> {
    let csv = args.csv.as_deref();
    match hilsim_lidar_protocols::decoder_for(args.model) {
        None => run_xv11(&args.input, csv, args.json, stdout),
        Some(mut decoder) => run_unit(
            &args.input,
            args.model,
            &mut *decoder,
            csv,
            args.json,
            stdout,
        ),
    }
}

/// Decodes a unit's stream as [`run_xv11`] does the XV-11's.
fn run_unit(
    input: &Path,
    model: LidarModel,
    decoder: &mut dyn hilsim_lidar_protocols::HostDecoder,
    csv: Option<&Path>,
    json: bool,
    stdout: &mut dyn Write,
) -> anyhow::Result<()> {
    let mut source = open_input(input)?;
    let cannot_read = |err: std::io::Error| anyhow!("{}: cannot read: {err}", input.display());
    let counts =
        match csv {
            None => decode_unit_stream::<Infallible>(&mut source, model, decoder, None).map_err(
                |err| match err {
                    DecodeError::Read(err) => cannot_read(err),
                    DecodeError::Sink(never) => match never {},
                },
            )?,
            Some(path) => {
                check_output_file(path, UNIT_CSV, &[input])?;
                let mut out = AtomicFile::create(path)?;
                writeln!(out, "{UNIT_CSV_HEADER}")
                    .with_context(|| format!("{}: cannot write", path.display()))?;
                let mut row = String::new();
                let mut write = |rev: u64, point: &_| -> std::io::Result<()> {
                    row.clear();
                    unit_csv_row(rev, point, &mut row);
                    out.write_all(row.as_bytes())
                };
                let counts = decode_unit_stream(&mut source, model, decoder, Some(&mut write))
                    .map_err(|err| match err {
                        DecodeError::Read(err) => cannot_read(err),
                        DecodeError::Sink(err) => anyhow::Error::new(err)
                            .context(format!("{}: cannot write", path.display())),
                    })?;
                out.commit()?;
                counts
            }
        };
    let mut stdout: &mut dyn Write = stdout;
    let mut stderr = std::io::stderr();
    if csv.is_some_and(|path| OutputTarget::of(path).is_ok_and(|t| t == OutputTarget::Stdout)) {
        stdout = &mut stderr;
    }
    report_unit(input, &counts, json, stdout).context("cannot write the counts")
}

fn report_unit(
    input: &Path,
    counts: &UnitDecodeCounts,
    json: bool,
    stdout: &mut dyn Write,
) -> anyhow::Result<()> {
    if json {
        serde_json::to_writer(&mut *stdout, counts)?;
        writeln!(stdout)?;
    } else {
        writeln!(
            stdout,
            "{} ({}): {} bytes, {} packets ({} readings, {} without a return), {} bad checksums, \
             {} bytes skipped",
            input.display(),
            counts.model,
            counts.bytes,
            counts.packets,
            counts.readings,
            counts.no_return,
            counts.bad_checksum,
            counts.skipped_bytes,
        )?;
        if counts.rev_hz_median > 0.0 {
            writeln!(
                stdout,
                "revolutions: {} begun, {:.2} Hz median as reported",
                counts.revolutions, counts.rev_hz_median
            )?;
        } else {
            writeln!(stdout, "revolutions: {} begun", counts.revolutions)?;
        }
    }
    stdout.flush()?;
    Ok(())
}

/// Decodes `input`, optionally writes the readings to `csv`, and reports the counts on `stdout`
/// (one JSON object with `json`, else a short human summary).
///
/// # Errors
/// The input cannot be opened or read (a directory, a missing file…), the CSV cannot be
/// written, or `stdout` fails; each message names the path concerned.
pub fn run_xv11(
    input: &Path,
    csv: Option<&Path>,
    json: bool,
    stdout: &mut dyn Write,
) -> anyhow::Result<()> {
    let mut source = open_input(input)?;
    let cannot_read = |err: std::io::Error| anyhow!("{}: cannot read: {err}", input.display());
    let counts = match csv {
        None => decode_stream::<Infallible>(&mut source, None).map_err(|err| match err {
            DecodeError::Read(err) => cannot_read(err),
            DecodeError::Sink(never) => match never {},
        })?,
        Some(path) => {
            let mut out = create_csv(path, input)?;
            let mut rows = String::new();
            let mut write = |revolution: &_| -> std::io::Result<()> {
                rows.clear();
                decoded_csv_rows(revolution, &mut rows);
                out.write_all(rows.as_bytes())
            };
            let counts = decode_stream(&mut source, Some(&mut write)).map_err(|err| match err {
                DecodeError::Read(err) => cannot_read(err),
                DecodeError::Sink(err) => {
                    anyhow::Error::new(err).context(format!("{}: cannot write", path.display()))
                }
            })?;
            out.commit()?;
            counts
        }
    };
    // With the table on standard output, the counts go beside it, not into it.
    if csv.is_some_and(|path| OutputTarget::of(path).is_ok_and(|t| t == OutputTarget::Stdout)) {
        return report(input, &counts, json, &mut std::io::stderr())
            .context("stderr: cannot write");
    }
    report(input, &counts, json, stdout).context("stdout: cannot write")
}

/// The CSV at `path`, its header written: replaced atomically when complete, or written through
/// a device (see [`AtomicFile`]); never over the `input`.
fn create_csv(path: &Path, input: &Path) -> anyhow::Result<AtomicFile> {
    check_output_file(path, DECODED_CSV, &[input])?;
    let mut out = AtomicFile::create(path)?;
    writeln!(out, "{DECODED_CSV_HEADER}")
        .with_context(|| format!("{}: cannot write", path.display()))?;
    Ok(out)
}

fn open_input(input: &Path) -> anyhow::Result<File> {
    let file = match File::open(input) {
        Ok(file) => file,
        Err(err) if err.kind() == ErrorKind::NotFound => {
            bail!("{}: cannot open: no such file or device", input.display())
        }
        Err(err) => bail!("{}: cannot open: {err}", input.display()),
    };
    // Opening a directory succeeds on Unix; reading it would fail with a vaguer message.
    let is_dir = file
        .metadata()
        .map(|meta| meta.is_dir())
        .with_context(|| format!("{}: cannot open", input.display()))?;
    if is_dir {
        bail!(
            "{}: is a directory, expected a capture file or a serial device",
            input.display()
        );
    }
    Ok(file)
}

fn report(
    input: &Path,
    counts: &DecodeCounts,
    json: bool,
    stdout: &mut dyn Write,
) -> anyhow::Result<()> {
    if json {
        serde_json::to_writer(&mut *stdout, counts)?;
        writeln!(stdout)?;
    } else {
        writeln!(
            stdout,
            "{}: {} bytes, {} packets ({} readings), {} bad checksums, {} bytes skipped, {} index gaps",
            input.display(),
            counts.bytes,
            counts.packets,
            counts.readings,
            counts.bad_checksum,
            counts.skipped_bytes,
            counts.index_gaps,
        )?;
        writeln!(
            stdout,
            "readings: {} invalid, {} with strength warning",
            counts.invalid, counts.strength_warning
        )?;
        if counts.packets > 0 {
            writeln!(
                stdout,
                "motor: {:.2} rpm median ({:.2} to {:.2})",
                counts.rpm_median, counts.rpm_min, counts.rpm_max
            )?;
        } else {
            writeln!(stdout, "motor: no packets, no speed")?;
        }
    }
    stdout.flush()?;
    Ok(())
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

    fn run_on(bytes: &[u8], csv: bool, json: bool) -> (String, Option<String>) {
        let dir = tempfile::tempdir().expect("temp dir");
        let input = dir.path().join("capture.bin");
        std::fs::write(&input, bytes).expect("write capture");
        let csv_path = dir.path().join("out.csv");
        let mut stdout = Vec::new();
        run_xv11(&input, csv.then_some(csv_path.as_path()), json, &mut stdout)
            .expect("decode runs");
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .expect("list dir")
            .filter_map(|entry| entry.ok())
            .filter(|entry| entry.file_name().to_string_lossy().contains(".tmp."))
            .collect();
        assert!(leftovers.is_empty(), "temporary file left behind");
        let csv_text = csv.then(|| std::fs::read_to_string(&csv_path).expect("csv written"));
        (String::from_utf8(stdout).expect("utf-8"), csv_text)
    }

    #[test]
    fn json_has_the_interface_keys_and_counts() {
        let (stdout, _) = run_on(&sample_capture(), false, true);
        let value: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
        assert_eq!(value["bytes"], 1980 * 2 - 22);
        assert_eq!(value["packets"], 178);
        assert_eq!(value["bad_checksum"], 1);
        assert_eq!(value["skipped_bytes"], 22);
        assert_eq!(value["index_gaps"], 1);
        assert_eq!(value["readings"], 4 * 178);
        assert_eq!(value["invalid"], 2);
        assert_eq!(value["strength_warning"], 2);
        assert_eq!(value["rpm_min"], 300.0);
        // 90 packets at 300 and 88 at 310: the two middle ones (ranks 88 and 89) are at 300.
        assert_eq!(value["rpm_median"], 300.0);
        assert_eq!(value["rpm_max"], 310.0);
        assert_eq!(stdout.lines().count(), 1);
    }

    #[test]
    fn csv_has_one_row_per_reading() {
        let (stdout, csv) = run_on(&sample_capture(), true, false);
        assert!(stdout.contains("178 packets"), "{stdout}");
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
        let (stdout, csv) = run_on(&[], true, true);
        let value: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
        assert_eq!(value["packets"], 0);
        assert_eq!(value["rpm_median"], 0.0);
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
        let err = run_xv11(&input, Some(&csv), true, &mut Vec::new()).expect_err("missing input");
        let message = format!("{err:#}");
        assert!(
            message.contains("nope.bin") && message.contains("cannot open"),
            "{message}"
        );
        assert_eq!(std::fs::read_to_string(&csv).expect("csv kept"), "keep me");
    }

    #[test]
    fn directory_input_is_a_clean_error() {
        let dir = tempfile::tempdir().expect("temp dir");
        let err = run_xv11(dir.path(), None, false, &mut Vec::new()).expect_err("directory");
        assert!(format!("{err:#}").contains("is a directory"));
    }

    #[test]
    fn unwritable_csv_names_the_csv() {
        let dir = tempfile::tempdir().expect("temp dir");
        let input = dir.path().join("capture.bin");
        std::fs::write(&input, sample_capture()).expect("write capture");
        let csv = dir.path().join("no-such-dir").join("out.csv");
        let err = run_xv11(&input, Some(&csv), false, &mut Vec::new()).expect_err("bad csv dir");
        assert!(format!("{err:#}").contains("out.csv"), "{err:#}");
    }
}
