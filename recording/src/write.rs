//! Writing a [`Recording`] as a directory.

use std::path::Path;

use crate::atomic::{replace_recording_dir, write_file_atomically};
use crate::{Error, Recording};

impl Recording {
    /// Writes the recording into `dir`, replacing a recording that was there only once the new
    /// one is complete; anything else at `dir` is refused (see [`replace_recording_dir`]).
    ///
    /// Output is a pure function of the recording: floats are written in Rust's shortest
    /// round-trip form, so equal recordings give byte-identical files.
    ///
    /// # Errors
    /// An I/O error naming the file; `dir` holds something other than a recording.
    pub fn write_dir(&self, dir: &Path) -> Result<(), Error> {
        replace_recording_dir(dir, |tmp| self.write_files(tmp))
    }

    /// Writes the recording's files into an existing directory, each atomically. Use this to add
    /// a recording to a directory that holds other outputs too.
    ///
    /// # Errors
    /// An I/O error naming the file.
    pub fn write_files(&self, dir: &Path) -> Result<(), Error> {
        let meta_path = dir.join("meta.toml");
        let meta = toml::to_string(&self.meta)
            .map_err(|err| Error::format(&meta_path, None, err.to_string()))?;
        write_file_atomically(&meta_path, meta.as_bytes())?;
        for (name, text) in self.tables() {
            write_file_atomically(&dir.join(name), text.as_bytes())?;
        }
        Ok(())
    }

    /// Each present table as (file name, CSV text).
    #[must_use]
    pub fn tables(&self) -> Vec<(&'static str, String)> {
        // Written as bytes (the streamed tables' fast path), then checked as UTF-8 once: every
        // byte is ASCII.
        let text = |bytes: Vec<u8>| {
            String::from_utf8(bytes)
                .unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into())
        };
        let mut out = Vec::new();
        let mut s = rows::COMMANDS_HEADER.as_bytes().to_vec();
        for c in &self.commands {
            rows::command(&mut s, c);
        }
        out.push(("commands.csv", text(s)));
        if let Some(odometry) = &self.odometry {
            let mut s = rows::ODOMETRY_HEADER.as_bytes().to_vec();
            for o in odometry {
                rows::odometry(&mut s, o);
            }
            out.push(("odometry.csv", text(s)));
        }
        if let Some(lidar) = &self.lidar {
            // The truth column is all-or-nothing: a simulator knows every true range.
            let with_truth = lidar.iter().all(|r| r.true_range_m.is_some()) && !lidar.is_empty();
            let mut s = Vec::with_capacity(lidar.len() * 48);
            s.extend_from_slice(rows::lidar_header(with_truth).as_bytes());
            for r in lidar {
                rows::lidar(&mut s, r, with_truth);
            }
            out.push(("lidar.csv", text(s)));
        }
        if let Some(sonar) = &self.sonar {
            let with_truth = sonar.iter().all(|r| r.true_range_m.is_some()) && !sonar.is_empty();
            let mut s = rows::sonar_header(with_truth).as_bytes().to_vec();
            for r in sonar {
                rows::sonar(&mut s, r, with_truth);
            }
            out.push(("sonar.csv", text(s)));
        }
        if let Some(truth) = &self.truth {
            let mut s = rows::TRUTH_HEADER.as_bytes().to_vec();
            for p in truth {
                rows::truth(&mut s, p);
            }
            out.push(("truth.csv", text(s)));
        }
        out
    }
}

/// One row of each table, as the whole-table writer above and the streaming writer
/// (`stream.rs`) both write it: floats in Rust's shortest round-trip form.
pub(crate) mod rows {
    use crate::decimal::{push_f64, push_int, Text};
    use crate::{
        CommandSample, LidarDecimals, LidarSample, OdometrySample, SonarSample, TruthSample,
    };

    pub(crate) const COMMANDS_HEADER: &str = "t_s,left_mps,right_mps\n";
    pub(crate) const ODOMETRY_HEADER: &str = "t_s,left_m,right_m\n";
    pub(crate) const TRUTH_HEADER: &str = "t_s,x_m,y_m,yaw_rad\n";

    pub(crate) fn lidar_header(with_truth: bool) -> &'static str {
        if with_truth {
            "t_s,rev,angle_deg,range_m,strength,invalid,warning,true_range_m\n"
        } else {
            "t_s,rev,angle_deg,range_m,strength,invalid,warning\n"
        }
    }

    pub(crate) fn sonar_header(with_truth: bool) -> &'static str {
        if with_truth {
            "t_s,range_m,true_range_m\n"
        } else {
            "t_s,range_m\n"
        }
    }

    /// Fields joined by commas, each written as `Display` writes it.
    fn fields(s: &mut impl Text, numbers: &[f64]) {
        // In one piece when every field takes the fast path (wheel travel, sonar ranges).
        let in_one_piece = s.push_row(|row| {
            for (i, &x) in numbers.iter().enumerate() {
                if i > 0 {
                    row.byte(b',')?;
                }
                row.f64(x)?;
            }
            Some(())
        });
        if in_one_piece {
            return;
        }
        for (i, &x) in numbers.iter().enumerate() {
            if i > 0 {
                s.push_byte(b',');
            }
            push_f64(s, x);
        }
    }

    pub(crate) fn command(s: &mut impl Text, c: &CommandSample) {
        fields(s, &[c.t_s, c.left_mps, c.right_mps]);
        s.push_byte(b'\n');
    }

    pub(crate) fn odometry(s: &mut impl Text, o: &OdometrySample) {
        fields(s, &[o.t_s, o.left_m, o.right_m]);
        s.push_byte(b'\n');
    }

    pub(crate) fn truth(s: &mut impl Text, p: &TruthSample) {
        fields(s, &[p.t_s, p.x_m, p.y_m, p.yaw_rad]);
        s.push_byte(b'\n');
    }

    pub(crate) fn lidar(s: &mut impl Text, r: &LidarSample, with_truth: bool) {
        // Nearly every row in one piece (a `Row`); the same bytes the long way below.
        let in_one_piece = s.push_row(|row| {
            row.f64(r.t_s)?;
            row.byte(b',')?;
            row.int(r.rev)?;
            row.byte(b',')?;
            row.f64(r.angle_deg)?;
            row.byte(b',')?;
            row.f64(r.range_m)?;
            row.byte(b',')?;
            row.int(r.strength)?;
            for flag in [r.invalid, r.warning] {
                row.byte(b',')?;
                row.byte(if flag { b'1' } else { b'0' })?;
            }
            if let Some(t) = r.true_range_m.filter(|_| with_truth) {
                row.byte(b',')?;
                row.f64(t)?;
            }
            row.byte(b'\n')
        });
        if in_one_piece {
            return;
        }
        push_f64(s, r.t_s);
        s.push_byte(b',');
        push_int(s, r.rev);
        s.push_byte(b',');
        // A whole angle prints as the integer it is ("90"), as the XV-11's always did.
        push_f64(s, r.angle_deg);
        s.push_byte(b',');
        push_f64(s, r.range_m);
        s.push_byte(b',');
        push_int(s, r.strength);
        for flag in [r.invalid, r.warning] {
            s.push_byte(b',');
            s.push_byte(if flag { b'1' } else { b'0' });
        }
        true_range(s, r.true_range_m.filter(|_| with_truth));
    }

    /// A reading whose numbers are decimals already: the same bytes as [`lidar`] writes for
    /// [`LidarDecimals::sample`], from the digits.
    pub(crate) fn lidar_decimals(s: &mut impl Text, r: &LidarDecimals) {
        let in_one_piece = s.push_row(|row| {
            row.decimal(r.t_us, 6)?;
            row.byte(b',')?;
            row.int(r.rev)?;
            row.byte(b',')?;
            row.decimal(r.angle_e4_deg.into(), 4)?;
            row.byte(b',')?;
            row.decimal(r.range_digits, r.range_scale)?;
            row.byte(b',')?;
            row.int(r.strength)?;
            for flag in [r.invalid, r.warning] {
                row.byte(b',')?;
                row.byte(if flag { b'1' } else { b'0' })?;
            }
            row.byte(b'\n')
        });
        if !in_one_piece {
            lidar(s, &r.sample(), false);
        }
    }

    pub(crate) fn sonar(s: &mut impl Text, r: &SonarSample, with_truth: bool) {
        fields(s, &[r.t_s, r.range_m]);
        true_range(s, r.true_range_m.filter(|_| with_truth));
    }

    fn true_range(s: &mut impl Text, t: Option<f64>) {
        if let Some(t) = t {
            s.push_byte(b',');
            push_f64(s, t);
        }
        s.push_byte(b'\n');
    }
}

#[cfg(test)]
mod tests {
    use super::rows;
    use crate::LidarDecimals;
    use proptest::prelude::*;

    proptest! {
        /// A reading written from its decimals is, byte for byte, the reading written from the
        /// `f64`s closest to them, on either kind of text.
        #[test]
        fn decimals_write_what_their_floats_write(
            t_us in 0u64..100_000_000_000, rev in any::<u64>(), angle_e4_deg in 0u32..3_600_000,
            range_digits in 0u64..100_000_000, range_scale in 0u32..13, strength in any::<u16>(),
            invalid in any::<bool>(), warning in any::<bool>(),
        ) {
            let r = LidarDecimals {
                t_us, rev, angle_e4_deg, range_digits, range_scale, strength, invalid, warning,
            };
            let (mut from_decimals, mut from_floats) = (Vec::new(), Vec::new());
            rows::lidar_decimals(&mut from_decimals, &r);
            rows::lidar(&mut from_floats, &r.sample(), false);
            prop_assert_eq!(&from_decimals, &from_floats);
            let mut text = String::new();
            rows::lidar_decimals(&mut text, &r);
            prop_assert_eq!(text.as_bytes(), from_floats.as_slice());
        }
    }
}
