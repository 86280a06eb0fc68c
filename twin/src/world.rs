//! A recorded run's world and its scenario: the map (the user's, or built from the run's own
//! scans at its path), the path, the lidar's scan schedule, and the scenario that names them
//! so that `hilsim record` replays the run.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use hilsim_recording::{check_output_file, write_file_atomically, FileKind, Meta, Mount};
use hilsim_sim::occupancy::{MapBuilder, OccupancyMap};
use hilsim_sim::scan_schedule::ScanSchedule;

use crate::error::TwinError;
use crate::path::{find_path, FoundPath, PoseSource};
use crate::scans::{for_each_scan, open, ScanCounts};

/// How a world is built.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldOptions {
    /// The user's map (map_server YAML); `None`: build one from the scans.
    pub map: Option<PathBuf>,
    /// The built map's cell size, metres.
    pub resolution_m: f64,
    /// Where the path comes from.
    pub poses: PoseSource,
    /// Readings farther than this neither build the map nor match scans, metres: a heading
    /// error of the path moves a far reading's cell more than a near one's.
    pub max_range_m: f64,
}

impl Default for WorldOptions {
    fn default() -> Self {
        Self {
            map: None,
            // A few centimetres: a wall's cell then puts the wall within ±1.5 cm of where the
            // scans saw it, below a SICK's or a Hokuyo's centimetre noise; finer cells leave gaps
            // between the hits of a beam spacing of 0.5–1° at a few metres.
            resolution_m: 0.03,
            poses: PoseSource::Auto,
            // An indoor SICK's or Hokuyo's farthest readings: a wall seen only from afar is still
            // in the map (less exactly: a 0.1° heading error moves it 5 cm at 30 m), so that the
            // twin reads it too.
            max_range_m: 30.0,
        }
    }
}

impl WorldOptions {
    /// The options `hilsim world`'s flags ask for: the user's map, the built map's cell size
    /// (from 0.005 to 1 m) and the path's source by name (`truth`, `odometry`, else `auto`).
    ///
    /// # Errors
    /// A cell size out of range, naming the flag.
    pub fn from_flags(
        map: Option<PathBuf>,
        resolution_m: f64,
        poses: &str,
    ) -> Result<Self, TwinError> {
        if !(resolution_m.is_finite() && (0.005..=1.0).contains(&resolution_m)) {
            return Err(TwinError::Input(format!(
                "--resolution-m {resolution_m}: expected a cell size from 0.005 to 1 m; see \
                 hilsim world --help"
            )));
        }
        let poses = match poses {
            "truth" => PoseSource::Truth,
            "odometry" => PoseSource::Odometry,
            _ => PoseSource::Auto,
        };
        Ok(Self {
            map,
            resolution_m,
            poses,
            ..Self::default()
        })
    }
}

/// A beam's end counts as occupied when at least this many beams ended in its cell …
const MIN_HITS: u32 = 2;
/// … and at least this share of the beams that reached the cell ended there: a person walking
/// through is hit by a few scans and passed through by many.
const OCCUPIED_RATIO: f64 = 0.25;

/// The map of a twin.
#[derive(Debug, Clone)]
pub enum TwinMap {
    /// Built from the scans.
    Built(OccupancyMap),
    /// The user's map_server YAML.
    User(PathBuf),
}

/// A recorded run's world, ready to be written as a scenario.
#[derive(Debug, Clone)]
pub struct TwinWorld {
    /// The recording's directory.
    pub recording: PathBuf,
    /// The recording's `meta.toml`.
    pub meta: Meta,
    /// The map.
    pub map: TwinMap,
    /// The robot's path.
    pub path: FoundPath,
    /// The lidar's scans.
    pub schedule: ScanSchedule,
    /// What reading the scans met.
    pub scans: ScanCounts,
    /// The lidar's nearest and farthest valid reading in the log, metres.
    pub range_limits_m: [f64; 2],
    /// The odometer's rate, Hz, when the recording has one.
    pub odometer_hz: Option<f64>,
    /// What was guessed or left out, one sentence each.
    pub notes: Vec<String>,
}

/// The files a twin is written as.
#[derive(Debug, Clone, PartialEq)]
pub struct TwinFiles {
    /// The scenario.
    pub scenario: PathBuf,
    /// The map's YAML (beside the scenario when built; the user's otherwise).
    pub map: PathBuf,
    /// The path.
    pub path: PathBuf,
    /// The scan schedule.
    pub schedule: PathBuf,
}

impl TwinFiles {
    /// The files of a scenario at `scenario`: `STEM.map.yaml`, `STEM.path.csv` and
    /// `STEM.scans.csv` beside it (the map the user's when given).
    #[must_use]
    pub fn beside(scenario: &Path, user_map: Option<&Path>) -> Self {
        let stem = scenario
            .file_stem()
            .map_or_else(|| "twin".into(), |s| s.to_string_lossy().into_owned());
        let sibling = |suffix: &str| scenario.with_file_name(format!("{stem}.{suffix}"));
        Self {
            scenario: scenario.to_path_buf(),
            // The user's map by its absolute name: the scenario may be written elsewhere.
            map: user_map.map_or_else(
                || sibling("map.yaml"),
                |m| std::fs::canonicalize(m).unwrap_or_else(|_| m.to_path_buf()),
            ),
            path: sibling("path.csv"),
            schedule: sibling("scans.csv"),
        }
    }
}

/// The robot and lidar a twin's scenario declares: the recording's meta, unless a calibration
/// says otherwise.
#[derive(Debug, Clone, PartialEq)]
pub struct Declared {
    /// The lidar's range bias polynomial (the papers' eq. 2, metres).
    pub lidar_bias: Vec<f64>,
    /// The lidar's noise polynomial (standard deviation, metres).
    pub lidar_noise: Vec<f64>,
    /// The lidar's mount.
    pub lidar_mount: Mount,
    /// The wheel base, metres.
    pub wheel_base_m: f64,
}

/// The first line of every scenario `hilsim world` writes: how a later run knows the file is
/// its own to replace.
pub const SCENARIO_FIRST_LINE: &str = "# The twin of a recorded run, written by `hilsim world`";

/// What a twin's scenario file is.
pub const SCENARIO_KIND: FileKind = FileKind {
    name: "a twin scenario written by hilsim world",
    starts_with: SCENARIO_FIRST_LINE.as_bytes(),
};

const PATH_KIND: FileKind = FileKind {
    name: "a path written by hilsim world",
    starts_with: b"t_s,x_m,y_m,yaw_deg\n",
};

const SCHEDULE_KIND: FileKind = FileKind {
    name: "a scan schedule written by hilsim world",
    starts_with: b"t_s,rev,beams,first_deg,step_deg,beam_period_s\n",
};

/// Builds the world of the recording at `recording`.
///
/// # Errors
/// The recording cannot be read, has no lidar, or has no path (no truth, no odometry); the
/// user's map cannot be read; the map grows past its limit.
pub fn build_world(recording: &Path, options: &WorldOptions) -> Result<TwinWorld, TwinError> {
    let dir = open(recording)?;
    let meta = dir.meta().clone();
    let mount = meta.lidar.unwrap_or_default();
    let mut notes = Vec::new();
    if meta.lidar.is_none() {
        notes.push(
            "the recording's meta.toml has no [lidar] mount: the lidar is taken to be at the \
             robot's centre, facing forward"
                .to_string(),
        );
    }
    let path = find_path(&dir, options.poses, options.max_range_m)?;
    match path.source {
        PoseSource::Odometry => notes.push(format!(
            "the path is the wheels' dead reckoning corrected by matching each scan to the map \
             the scans before it built ({} of {} scans matched; no loop closure beyond that: a \
             place come back to after a long drift may show as a doubled wall)",
            path.matched,
            path.matched + path.unmatched
        )),
        _ => notes.push("the path is the recording's truth.csv".to_string()),
    }
    if path.skipped_rows > 0 {
        notes.push(format!(
            "{} pose row(s) not after the one before left out of the path",
            path.skipped_rows
        ));
    }
    let mut builder = options
        .map
        .is_none()
        .then(|| MapBuilder::new(options.resolution_m));
    let mut scans = Vec::new();
    let mut limits = [f64::INFINITY, 0.0_f64];
    let counts = for_each_scan(&dir, |log| {
        for r in log
            .readings
            .iter()
            .filter(|r| !r.invalid && r.range_m > 0.0)
        {
            limits = [limits[0].min(r.range_m), limits[1].max(r.range_m)];
        }
        if let Some(builder) = builder.as_mut() {
            for (i, r) in log.readings.iter().enumerate() {
                if r.invalid || r.range_m <= 0.0 || r.range_m > options.max_range_m {
                    continue;
                }
                let t = log.scan.beam_time_s(i as u32);
                let lidar = mount.in_world(&path.path.pose_at(t));
                let a = lidar.yaw + r.angle_deg.to_radians();
                let end = [lidar.x + r.range_m * a.cos(), lidar.y + r.range_m * a.sin()];
                builder.add_beam([lidar.x, lidar.y], end, true)?;
            }
        }
        scans.push(log.scan);
        Ok(())
    })?;
    let schedule = ScanSchedule::new(scans).map_err(TwinError::Input)?;
    if schedule.scans().is_empty() {
        return Err(TwinError::Input(format!(
            "{}: no scan of the lidar lies on a regular grid of angles: nothing to replay",
            recording.display()
        )));
    }
    if counts.irregular + counts.out_of_order > 0 {
        notes.push(format!(
            "{} of {} scans left out of the replay ({} not on a regular grid of angles, {} \
             starting before the scan before)",
            counts.irregular + counts.out_of_order,
            counts.scans,
            counts.irregular,
            counts.out_of_order
        ));
    }
    let map = match (&options.map, builder) {
        (Some(user), _) => TwinMap::User(user.clone()),
        (None, Some(builder)) => TwinMap::Built(builder.finish(MIN_HITS, OCCUPIED_RATIO)),
        (None, None) => unreachable!("a builder exists when no map is given"),
    };
    if !limits[0].is_finite() {
        limits = [0.0, 0.0];
    }
    let odometer_hz = odometer_rate_hz(&dir)?;
    Ok(TwinWorld {
        recording: recording.to_path_buf(),
        meta,
        map,
        path,
        schedule,
        scans: counts,
        range_limits_m: limits,
        odometer_hz,
        notes,
    })
}

/// The odometer's median rate, Hz.
fn odometer_rate_hz(dir: &hilsim_recording::RecordingDir) -> Result<Option<f64>, TwinError> {
    let Some(rows) = dir.odometry()? else {
        return Ok(None);
    };
    let mut gaps = Vec::new();
    let mut last: Option<f64> = None;
    for row in rows.take(100_000) {
        let t = row?.t_s;
        if let Some(l) = last.filter(|&l| t > l) {
            gaps.push(t - l);
        }
        last = Some(t);
    }
    gaps.sort_by(f64::total_cmp);
    Ok(gaps.get(gaps.len() / 2).map(|g| 1.0 / g))
}

impl TwinWorld {
    /// What the recording's meta declares: an unbiased, noiseless lidar at its mount, its
    /// wheel base.
    #[must_use]
    pub fn declared(&self) -> Declared {
        Declared {
            lidar_bias: vec![0.0, 1.0],
            lidar_noise: vec![0.0],
            lidar_mount: self.meta.lidar.unwrap_or_default(),
            wheel_base_m: self.meta.robot.wheel_base_m,
        }
    }

    /// The scenario's text, naming `files` relative to the scenario's directory, declaring
    /// `declared`.
    #[must_use]
    pub fn scenario_toml(&self, files: &TwinFiles, declared: &Declared) -> String {
        let relative = |file: &Path| -> String {
            let dir = files.scenario.parent().unwrap_or(Path::new(""));
            let shown = file.strip_prefix(dir).unwrap_or(file);
            toml_string(&shown.to_string_lossy())
        };
        let name = self
            .recording
            .file_name()
            .map_or_else(|| "log".into(), |n| n.to_string_lossy().into_owned());
        let start = self.path.path.first();
        let mount = declared.lidar_mount;
        let mut s = String::new();
        let _ = writeln!(s, "{SCENARIO_FIRST_LINE} from {}.", toml_comment(&name));
        let _ = writeln!(
            s,
            "# `hilsim record` on it replays the run: the robot follows the log's path and the \
             lidar takes the log's scans in the map."
        );
        for note in &self.notes {
            let _ = writeln!(s, "# note: {}", toml_comment(note));
        }
        let _ = writeln!(s, "name = {}", toml_string(&format!("{name}-twin")));
        let _ = writeln!(
            s,
            "description = {}",
            toml_string(&format!(
                "The run of {name} replayed in {}.",
                match self.map {
                    TwinMap::Built(_) => "a map built from its own scans",
                    TwinMap::User(_) => "the user's map",
                }
            ))
        );
        let _ = writeln!(
            s,
            "duration_s = {}",
            (self.path.path.end_s().max(self.schedule.end_s()) + 0.01)
                .min(hilsim_sim::scenario::MAX_RUN_S)
        );
        let _ = writeln!(s, "\n[world]\nmap = {}", relative(&files.map));
        let _ = writeln!(s, "\n[robot]");
        let _ = writeln!(
            s,
            "start = {{ x = {}, y = {}, yaw_deg = {} }}",
            start.x,
            start.y,
            start.yaw.to_degrees()
        );
        let _ = writeln!(s, "wheel_base_m = {}", declared.wheel_base_m);
        if let Some(r) = self.meta.robot.wheel_radius_m {
            let _ = writeln!(s, "wheel_radius_m = {r}");
        }
        let _ = writeln!(s, "path = {}", relative(&files.path));
        let [min_m, max_m] = self.range_limits_m;
        let _ = writeln!(s, "\n[sensors.lidar]");
        let _ = writeln!(s, "schedule = {}", relative(&files.schedule));
        let list = |v: &[f64]| {
            v.iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(s, "bias = [{}]", list(&declared.lidar_bias));
        let _ = writeln!(s, "noise = [{}]", list(&declared.lidar_noise));
        let _ = writeln!(s, "min_range_m = {}", round_to(min_m.max(0.001), 1e-3));
        // A reading carries 16 bits of millimetres.
        let _ = writeln!(
            s,
            "max_range_m = {}",
            round_to(max_m.clamp(0.01, 65.535), 1e-3)
        );
        let _ = writeln!(
            s,
            "mount = {{ x_m = {}, y_m = {}, yaw_deg = {} }}",
            mount.x_m, mount.y_m, mount.yaw_deg
        );
        if let Some(hz) = self.odometer_hz {
            let _ = writeln!(s, "\n[sensors.odometer]\nrate_hz = {}", round_to(hz, 1e-3));
        }
        s
    }

    /// Writes the twin: the scenario (declaring `declared`), its path, its scan schedule and,
    /// when built, its map. Each file replaces only a file of its own kind.
    ///
    /// # Errors
    /// A file in the way that is not a twin's, or any I/O error, naming the file.
    pub fn write(&self, files: &TwinFiles, declared: &Declared) -> Result<(), TwinError> {
        let inputs = [self.recording.as_path()];
        check_output_file(&files.scenario, SCENARIO_KIND, &inputs)?;
        // A missing directory is made, as `hilsim record` makes a recording's.
        if let Some(dir) = files
            .scenario
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
        {
            std::fs::create_dir_all(dir)
                .map_err(|e| TwinError::Input(format!("{}: {e}", dir.display())))?;
        }
        check_output_file(&files.path, PATH_KIND, &inputs)?;
        check_output_file(&files.schedule, SCHEDULE_KIND, &inputs)?;
        if let TwinMap::Built(map) = &self.map {
            map.write(&files.map)?;
        }
        write_file_atomically(&files.path, path_csv(&self.path).as_bytes())?;
        write_file_atomically(&files.schedule, self.schedule.to_csv().as_bytes())?;
        write_file_atomically(
            &files.scenario,
            self.scenario_toml(files, declared).as_bytes(),
        )?;
        Ok(())
    }
}

fn path_csv(path: &FoundPath) -> String {
    path.path.to_csv()
}

/// `x` rounded to a multiple of `unit`, printed without float noise.
fn round_to(x: f64, unit: f64) -> f64 {
    let digits = (-unit.log10()).round().max(0.0) as i32;
    let scale = 10f64.powi(digits);
    (x * scale).round() / scale
}

/// A TOML basic string.
fn toml_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04X}", u32::from(c));
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Text safe on one comment line.
fn toml_comment(s: &str) -> String {
    s.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_check_the_cell_size_and_name_the_pose_source() {
        for bad in [0.0, 0.004, 1.5, f64::NAN] {
            let err = WorldOptions::from_flags(None, bad, "auto").unwrap_err();
            assert!(err.to_string().starts_with("--resolution-m "), "{err}");
        }
        let options = WorldOptions::from_flags(None, 0.05, "odometry").unwrap();
        assert_eq!(options.poses, PoseSource::Odometry);
        assert_eq!(options.resolution_m, 0.05);
        assert_eq!(
            WorldOptions::from_flags(None, 0.05, "auto").unwrap().poses,
            PoseSource::Auto
        );
    }
}
