//! Reading a recording directory, strictly: a malformed file is an error naming the file and line.

use std::path::Path;

use crate::csv::{read_table, Header, Parse};
use crate::input::{self, MAX_META_BYTES};
use crate::{
    CommandSample, Error, LidarSample, Meta, OdometrySample, Recording, SonarSample, TruthSample,
    FORMAT,
};

impl Recording {
    /// Reads a recording directory.
    ///
    /// `meta.toml` and `commands.csv` are required; the sensor tables and `truth.csv` may be
    /// absent. Columns are found by name, so extra columns are ignored; times must be finite,
    /// non-negative and never go backwards.
    ///
    /// Tables are streamed, so memory is what the samples take, about the size of the file.
    /// Every file must be a regular file (a device or pipe may never end); a table's line may be
    /// at most 64 KiB and a table at most 16 GiB; `meta.toml` at most 1 MiB.
    ///
    /// # Errors
    /// A missing required file, or the first malformed line, naming the file and line.
    pub fn read_dir(dir: &Path) -> Result<Self, Error> {
        if !dir.is_dir() {
            return Err(Error::format(dir, None, "not a recording directory"));
        }
        let identity = input::dir_identity(dir)?;
        let meta = read_meta(&dir.join("meta.toml"))?;
        let commands = read_whole(&dir.join("commands.csv"), commands)?;
        let recording = Self {
            meta,
            commands,
            odometry: optional(dir, "odometry.csv", odometry)?,
            lidar: optional(dir, "lidar.csv", lidar)?,
            sonar: optional(dir, "sonar.csv", sonar)?,
            truth: optional(dir, "truth.csv", truth)?,
        };
        input::check_same_dir(dir, identity)?;
        Ok(recording)
    }
}

impl Meta {
    /// Reads and checks a `meta.toml` (as [`Recording::read_dir`] does).
    ///
    /// # Errors
    /// The file cannot be read or is not a valid `meta.toml`, naming it (and the line).
    pub fn read(path: &Path) -> Result<Self, Error> {
        read_meta(path)
    }
}

fn optional<T>(
    dir: &Path,
    name: &str,
    parse: fn(&Header) -> Result<Parse<T>, Error>,
) -> Result<Option<Vec<T>>, Error> {
    let path = dir.join(name);
    if !is_present(&path) {
        return Ok(None);
    }
    read_whole(&path, parse).map(Some)
}

/// Whether a table is there. Absent only when nothing is there: a link that leads nowhere (or
/// round in a loop) is a broken table, reported by the reader, not a sensor the robot lacks.
pub(crate) fn is_present(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok()
}

/// A table's samples, all of them.
fn read_whole<T>(
    path: &Path,
    parse: fn(&Header) -> Result<Parse<T>, Error>,
) -> Result<Vec<T>, Error> {
    let mut samples = Vec::new();
    read_table(path, parse, |s| samples.push(s))?;
    Ok(samples)
}

pub(crate) fn read_meta(path: &Path) -> Result<Meta, Error> {
    let text = input::read_small_text(path, MAX_META_BYTES, "a meta.toml")?;
    let meta: Meta = toml::from_str(&text).map_err(|err| {
        let line = err
            .span()
            .map(|span| 1 + text[..span.start.min(text.len())].matches('\n').count());
        Error::format(path, line, err.message().trim().to_string())
    })?;
    if meta.format != FORMAT {
        return Err(Error::format(
            path,
            None,
            format!("format is `{}`, expected `{FORMAT}`", meta.format),
        ));
    }
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if !positive(meta.robot.wheel_base_m) {
        return Err(Error::format(
            path,
            None,
            "robot.wheel_base_m must be positive",
        ));
    }
    if let Some(sonar) = &meta.sonar {
        if !(sonar.half_angle_deg.is_finite() && (0.0..90.0).contains(&sonar.half_angle_deg)) {
            return Err(Error::format(
                path,
                None,
                "sonar.half_angle_deg must be in [0, 90)",
            ));
        }
    }
    for (key, value) in [
        ("world.landmark_radius_m", meta.world.landmark_radius_m),
        (
            "world.target_start_distance_m",
            meta.world.target_start_distance_m,
        ),
    ] {
        if value.is_some_and(|v| !positive(v)) {
            return Err(Error::format(path, None, format!("{key} must be positive")));
        }
    }
    Ok(meta)
}

/// A time-ordered table of numbers: `t_s` and then `columns`, each row made into a sample by
/// `sample(t_s, values)` (columns looked up, and cells parsed, in that order).
fn numbers<T: 'static, const N: usize>(
    header: &Header,
    columns: [&str; N],
    sample: fn(f64, [f64; N]) -> T,
) -> Result<Parse<T>, Error> {
    let t = header.column("t_s")?;
    let mut indices = [0; N];
    for (index, name) in indices.iter_mut().zip(columns) {
        *index = header.column(name)?;
    }
    let mut prev = None;
    Ok(Box::new(move |row| {
        let t_s = row.f64(t)?;
        row.check_time(t_s, &mut prev)?;
        let mut values = [0.0; N];
        for (value, &index) in values.iter_mut().zip(&indices) {
            *value = row.f64(index)?;
        }
        Ok(sample(t_s, values))
    }))
}

/// `commands.csv`'s rows.
pub(crate) fn commands(header: &Header) -> Result<Parse<CommandSample>, Error> {
    numbers(header, ["left_mps", "right_mps"], |t_s, [l, r]| {
        CommandSample {
            t_s,
            left_mps: l,
            right_mps: r,
        }
    })
}

/// `odometry.csv`'s rows.
pub(crate) fn odometry(header: &Header) -> Result<Parse<OdometrySample>, Error> {
    numbers(header, ["left_m", "right_m"], |t_s, [l, r]| {
        OdometrySample {
            t_s,
            left_m: l,
            right_m: r,
        }
    })
}

/// `lidar.csv`'s rows.
pub(crate) fn lidar(header: &Header) -> Result<Parse<LidarSample>, Error> {
    struct Columns {
        t: usize,
        rev: usize,
        angle: usize,
        range: usize,
        strength: usize,
        invalid: usize,
        warning: usize,
        truth: Option<usize>,
    }
    let c = Columns {
        t: header.column("t_s")?,
        rev: header.column("rev")?,
        angle: header.column("angle_deg")?,
        range: header.column("range_m")?,
        strength: header.column("strength")?,
        invalid: header.column("invalid")?,
        warning: header.column("warning")?,
        truth: header.optional_column("true_range_m"),
    };
    let mut prev = None;
    Ok(Box::new(move |row| {
        let t_s = row.f64(c.t)?;
        row.check_time(t_s, &mut prev)?;
        let angle_deg = row.f64(c.angle)?;
        if !(0.0..360.0).contains(&angle_deg) {
            return Err(row.error(format!(
                "column `angle_deg`: expected a number in [0, 360), found {angle_deg}"
            )));
        }
        let range_m = row.f64(c.range)?;
        if range_m < 0.0 {
            return Err(row.error(format!(
                "column `range_m`: must not be negative, found {range_m}"
            )));
        }
        Ok(LidarSample {
            t_s,
            rev: row.uint(c.rev)?,
            angle_deg,
            range_m,
            strength: row.uint(c.strength)?,
            invalid: row.flag(c.invalid)?,
            warning: row.flag(c.warning)?,
            true_range_m: c.truth.map(|c| row.f64(c)).transpose()?,
        })
    }))
}

/// `sonar.csv`'s rows.
pub(crate) fn sonar(header: &Header) -> Result<Parse<SonarSample>, Error> {
    let (t, range, truth) = (
        header.column("t_s")?,
        header.column("range_m")?,
        header.optional_column("true_range_m"),
    );
    let mut prev = None;
    Ok(Box::new(move |row| {
        let t_s = row.f64(t)?;
        row.check_time(t_s, &mut prev)?;
        Ok(SonarSample {
            t_s,
            range_m: row.f64(range)?,
            true_range_m: truth.map(|c| row.f64(c)).transpose()?,
        })
    }))
}

/// `truth.csv`'s rows.
pub(crate) fn truth(header: &Header) -> Result<Parse<TruthSample>, Error> {
    numbers(header, ["x_m", "y_m", "yaw_rad"], |t_s, [x, y, yaw]| {
        TruthSample {
            t_s,
            x_m: x,
            y_m: y,
            yaw_rad: yaw,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn write(dir: &Path, name: &str, text: &str) {
        fs::write(dir.join(name), text).unwrap();
    }

    fn minimal(dir: &Path) {
        write(
            dir,
            "meta.toml",
            "format = \"hilsim-recording/1\"\n[robot]\nwheel_base_m = 0.23\n",
        );
        write(dir, "commands.csv", "t_s,left_mps,right_mps\n0,0.1,0.1\n");
    }

    fn err(dir: &Path) -> String {
        Recording::read_dir(dir).unwrap_err().to_string()
    }

    #[test]
    fn minimal_recording_reads() {
        let dir = tempfile::tempdir().unwrap();
        minimal(dir.path());
        let rec = Recording::read_dir(dir.path()).unwrap();
        assert_eq!(rec.commands.len(), 1);
        assert!(rec.lidar.is_none());
    }

    #[test]
    fn malformed_rows_name_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        minimal(dir.path());
        write(dir.path(), "sonar.csv", "t_s,range_m\n0.0,1.0\n0.1,abc\n");
        let msg = err(dir.path());
        assert!(
            msg.ends_with("sonar.csv:3: column `range_m`: expected a finite number, found `abc`"),
            "{msg}"
        );
        write(dir.path(), "sonar.csv", "t_s,range_m\n0.2,1.0\n0.1,1.0\n");
        assert!(err(dir.path()).contains("sonar.csv:3: time goes backwards"));
        write(dir.path(), "sonar.csv", "t_s,range_m\n0.0,NaN\n");
        assert!(err(dir.path()).contains("sonar.csv:2:"));
        write(dir.path(), "sonar.csv", "t_s,range\n0.0,1\n");
        assert!(err(dir.path()).contains("sonar.csv:1: missing column `range_m`"));
        write(dir.path(), "sonar.csv", "t_s,range_m\n0.0\n");
        assert!(err(dir.path()).contains("sonar.csv:2: expected 2 fields"));
        write(dir.path(), "sonar.csv", "");
        assert!(err(dir.path()).contains("sonar.csv:1: empty file"));
    }

    #[test]
    fn lidar_flags_and_angles_are_checked() {
        let dir = tempfile::tempdir().unwrap();
        minimal(dir.path());
        let header = "t_s,rev,angle_deg,range_m,strength,invalid,warning\n";
        write(
            dir.path(),
            "lidar.csv",
            &format!("{header}0,0,360,1.0,100,0,0\n"),
        );
        assert!(err(dir.path()).contains("lidar.csv:2: column `angle_deg`"));
        write(
            dir.path(),
            "lidar.csv",
            &format!("{header}0,0,1,1.0,100,2,0\n"),
        );
        assert!(err(dir.path()).contains("lidar.csv:2: column `invalid`: expected 0 or 1"));
        write(
            dir.path(),
            "lidar.csv",
            &format!("{header}0,0,1,1.0,70000,0,0\n"),
        );
        assert!(err(dir.path()).contains("column `strength`"));
    }

    #[test]
    fn the_first_error_is_the_one_a_whole_file_reader_found_first() {
        let dir = tempfile::tempdir().unwrap();
        minimal(dir.path());
        // A row of the wrong width comes before an earlier row's bad value …
        write(dir.path(), "sonar.csv", "t_s,range_m\n0,abc\n0.1\n");
        assert!(err(dir.path()).contains("sonar.csv:3: expected 2 fields"));
        // … and before a missing column; a line that is not UTF-8 comes before everything.
        write(dir.path(), "sonar.csv", "t_s,range\n0\n0,1\n\n0,\u{ff}\n");
        assert!(err(dir.path()).contains("sonar.csv:2: expected 2 fields"));
        fs::write(dir.path().join("sonar.csv"), b"t_s,range\n0\n\n0,\xff\n").unwrap();
        assert!(err(dir.path()).ends_with("sonar.csv:4: not UTF-8 text"));
        // Blank lines count, and `\r\n` line breaks are read as `\n`.
        write(
            dir.path(),
            "sonar.csv",
            "\r\nt_s,range_m\r\n \r\n0,1\r\n0,x\r\n",
        );
        assert!(err(dir.path())
            .ends_with("sonar.csv:5: column `range_m`: expected a finite number, found `x`"));
    }

    #[test]
    fn limits_end_reading_with_one_error() {
        let dir = tempfile::tempdir().unwrap();
        minimal(dir.path());
        let long = format!(
            "t_s,range_m\n0,1\n0,{}\n",
            "1".repeat(crate::input::MAX_LINE_BYTES)
        );
        write(dir.path(), "sonar.csv", &long);
        assert!(err(dir.path())
            .ends_with("sonar.csv:3: line longer than 64 KiB; not a recording's table"));
        // A line of exactly the limit is read (and here is a number too large).
        let longest = format!(
            "t_s,range_m\n0,1\n0,{}\r\n",
            "1".repeat(crate::input::MAX_LINE_BYTES - 3)
        );
        write(dir.path(), "sonar.csv", &longest);
        assert!(err(dir.path()).contains("sonar.csv:3: column `range_m`"));
        // Devices, which may never end, are refused before they are opened.
        fs::remove_file(dir.path().join("sonar.csv")).unwrap();
        std::os::unix::fs::symlink("/dev/zero", dir.path().join("sonar.csv")).unwrap();
        assert!(err(dir.path()).ends_with("sonar.csv: not a regular file but a character device"));
        let meta = format!(
            "format = \"hilsim-recording/1\"\n[robot]\nwheel_base_m = 0.23\n#{}\n",
            "x".repeat(1 << 20)
        );
        write(dir.path(), "meta.toml", &meta);
        assert!(err(dir.path()).ends_with("meta.toml: larger than 1 MiB; not a meta.toml"));
    }

    #[test]
    fn meta_is_validated() {
        let dir = tempfile::tempdir().unwrap();
        minimal(dir.path());
        write(
            dir.path(),
            "meta.toml",
            "format = \"other/2\"\n[robot]\nwheel_base_m = 0.23\n",
        );
        assert!(err(dir.path()).contains("meta.toml: format is `other/2`"));
        write(
            dir.path(),
            "meta.toml",
            "format = \"hilsim-recording/1\"\n[robot]\nwheel_base_m = -1\n",
        );
        assert!(err(dir.path()).contains("wheel_base_m must be positive"));
        write(
            dir.path(),
            "meta.toml",
            "format = \"hilsim-recording/1\"\n[robot]\n",
        );
        assert!(err(dir.path()).contains("meta.toml:"));
        fs::remove_file(dir.path().join("meta.toml")).unwrap();
        assert!(err(dir.path()).contains("meta.toml: "));
    }

    #[test]
    fn write_then_read_is_identity_and_replaces_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("rec");
        let mut rec = Recording::new(Meta::default());
        rec.commands.push(CommandSample {
            t_s: 0.0,
            left_mps: 0.1,
            right_mps: 0.1,
        });
        rec.lidar = Some(vec![LidarSample {
            t_s: 0.1 + 0.2,
            rev: 0,
            angle_deg: 359.5,
            range_m: 1.234,
            strength: 3000,
            invalid: false,
            warning: true,
            true_range_m: Some(1.2299999999),
        }]);
        rec.sonar = Some(vec![]);
        rec.write_dir(&out).unwrap();
        assert_eq!(Recording::read_dir(&out).unwrap(), rec);
        // A second write without the lidar must not leave the old lidar.csv behind.
        rec.lidar = None;
        rec.write_dir(&out).unwrap();
        assert!(!out.join("lidar.csv").exists());
        assert_eq!(Recording::read_dir(&out).unwrap(), rec);
        // No temporary siblings remain.
        let names: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("rec")]);
    }
}
