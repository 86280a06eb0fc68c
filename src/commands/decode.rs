//! `hilsim decode INPUT [--model M] [--csv OUT] [--json]`: decode a lidar's raw byte stream, the
//! Neato XV-11's by default (`hilsim_hil::decode_capture`; the CSV's columns and the JSON's keys
//! are in `hilsim_hil::decode` and docs/interfaces.md).

use std::io::Write;
use std::process::ExitCode;

use anyhow::{Context, Result};
use hilsim_hil::{decode_capture, CaptureError, Decoded};
use hilsim_recording::OutputTarget;

use crate::cli::DecodeArgs;

/// Decodes the capture, writes `--csv`, and prints the counts (one JSON object with `--json`).
pub fn decode(args: &DecodeArgs, stdout: &mut dyn Write) -> Result<ExitCode> {
    let decoded =
        decode_capture(&args.input, args.model, args.csv.as_deref()).map_err(|err| match err {
            // Its own type, so that a closed pipe is recognised.
            CaptureError::Output(err) => anyhow::Error::new(err),
            err => anyhow::Error::new(err),
        })?;
    // With the table on standard output, the counts go beside it, not into it.
    let beside = args.csv.as_deref().is_some_and(OutputTarget::is_stdout);
    let mut stderr = std::io::stderr();
    let out: &mut dyn Write = if beside { &mut stderr } else { stdout };
    let written = if args.json {
        serde_json::to_writer(&mut *out, &decoded)
            .map_err(std::io::Error::from)
            .and_then(|()| writeln!(out))
    } else {
        decoded.write_summary(&args.input, out)
    };
    written
        .and_then(|()| out.flush())
        .with_context(|| match (&decoded, beside) {
            (Decoded::Unit(_), _) => "cannot write the counts",
            (Decoded::Xv11(_), true) => "stderr: cannot write",
            (Decoded::Xv11(_), false) => "stdout: cannot write",
        })?;
    Ok(ExitCode::SUCCESS)
}
