//! Writing a [`Recording`] as a directory.

use std::fmt::Write as _;
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
        let mut out = Vec::new();
        let mut s = String::from("t_s,left_mps,right_mps\n");
        for c in &self.commands {
            let _ = writeln!(s, "{},{},{}", c.t_s, c.left_mps, c.right_mps);
        }
        out.push(("commands.csv", s));
        if let Some(odometry) = &self.odometry {
            let mut s = String::from("t_s,left_m,right_m\n");
            for o in odometry {
                let _ = writeln!(s, "{},{},{}", o.t_s, o.left_m, o.right_m);
            }
            out.push(("odometry.csv", s));
        }
        if let Some(lidar) = &self.lidar {
            // The truth column is all-or-nothing: a simulator knows every true range.
            let with_truth = lidar.iter().all(|r| r.true_range_m.is_some()) && !lidar.is_empty();
            let mut s = String::with_capacity(lidar.len() * 48);
            s.push_str("t_s,rev,angle_deg,range_m,strength,invalid,warning");
            s.push_str(if with_truth { ",true_range_m\n" } else { "\n" });
            for r in lidar {
                let _ = write!(
                    s,
                    "{},{},{},{},{},{},{}",
                    r.t_s,
                    r.rev,
                    r.angle_deg,
                    r.range_m,
                    r.strength,
                    u8::from(r.invalid),
                    u8::from(r.warning)
                );
                match r.true_range_m.filter(|_| with_truth) {
                    Some(t) => {
                        let _ = writeln!(s, ",{t}");
                    }
                    None => s.push('\n'),
                }
            }
            out.push(("lidar.csv", s));
        }
        if let Some(sonar) = &self.sonar {
            let with_truth = sonar.iter().all(|r| r.true_range_m.is_some()) && !sonar.is_empty();
            let mut s = String::from(if with_truth {
                "t_s,range_m,true_range_m\n"
            } else {
                "t_s,range_m\n"
            });
            for r in sonar {
                let _ = write!(s, "{},{}", r.t_s, r.range_m);
                match r.true_range_m.filter(|_| with_truth) {
                    Some(t) => {
                        let _ = writeln!(s, ",{t}");
                    }
                    None => s.push('\n'),
                }
            }
            out.push(("sonar.csv", s));
        }
        if let Some(truth) = &self.truth {
            let mut s = String::from("t_s,x_m,y_m,yaw_rad\n");
            for p in truth {
                let _ = writeln!(s, "{},{},{},{}", p.t_s, p.x_m, p.y_m, p.yaw_rad);
            }
            out.push(("truth.csv", s));
        }
        out
    }
}
