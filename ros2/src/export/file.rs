//! The entry points: a recording (in memory, or a directory read as streams) into an MCAP file,
//! written atomically.

use std::collections::BTreeMap;
use std::path::Path;

use hilsim_recording::{AtomicFile, Recording, RecordingDir, Rows, Tables};
use mcap::write::NoSeek;
use mcap::{Compression, WriteOptions};

use crate::Error;

use super::extent::Extent;
use super::mcap_file::{mcap_failure, Bag};
use super::options::{ExportOptions, ExportReport, World};
use super::source::{Source, Stream};
use super::write::write_all;

/// Writes `recording` as an MCAP file at `out` (atomically: a temporary sibling renamed into
/// place when complete), with `world` drawn as markers when given; chunks zstd-compressed (as
/// `ros2 bag record --storage-preset-profile zstd_fast` writes them).
///
/// # Errors
/// The file cannot be written.
pub fn export(
    recording: &Recording,
    world: Option<&World>,
    out: &Path,
) -> Result<ExportReport, Error> {
    let options = ExportOptions {
        world,
        ..ExportOptions::default()
    };
    export_with(recording, &options, out)
}

/// As [`export`], with the options given.
///
/// # Errors
/// The file cannot be written.
pub fn export_with(
    recording: &Recording,
    options: &ExportOptions<'_>,
    out: &Path,
) -> Result<ExportReport, Error> {
    let mut extent = Extent::default();
    for c in &recording.commands {
        extent.note_command(c);
    }
    recording
        .odometry
        .iter()
        .flatten()
        .for_each(|o| extent.note_odometry(o));
    recording
        .lidar
        .iter()
        .flatten()
        .for_each(|r| extent.note_lidar(r));
    recording
        .sonar
        .iter()
        .flatten()
        .for_each(|s| extent.note_sonar(s));
    recording
        .truth
        .iter()
        .flatten()
        .for_each(|p| extent.note_truth(p));
    fn rows<T: Copy>(table: Option<&[T]>) -> Stream<'_, T> {
        Box::new(table.unwrap_or_default().iter().copied().map(Ok))
    }
    let source = Source {
        meta: &recording.meta,
        tables: Tables {
            odometry: recording.odometry.is_some(),
            lidar: recording.lidar.is_some(),
            sonar: recording.sonar.is_some(),
            truth: recording.truth.is_some(),
        },
        commands: rows(Some(&recording.commands)),
        odometry: rows(recording.odometry.as_deref()),
        odometry_again: rows(recording.odometry.as_deref()),
        lidar: rows(recording.lidar.as_deref()),
        sonar: rows(recording.sonar.as_deref()),
        truth: rows(recording.truth.as_deref()),
    };
    write_file(source, &extent, options, out)
}

/// As [`export_with`], reading the recording directory as streams: its tables are checked
/// first (a malformed one is the error [`Recording::read_dir`] gives, and nothing is written),
/// then read again row by row, merged by time into the file. Memory is bounded whatever the
/// recording's length: a few rows of each table, one revolution (at most
/// [`MAX_SCAN_READINGS`] readings), the MCAP chunk being filled (768 KiB) and the file's index of
/// its chunks (a few dozen bytes per chunk).
///
/// # Errors
/// A table is malformed, or the file cannot be written.
pub fn export_dir(
    dir: &RecordingDir,
    options: &ExportOptions<'_>,
    out: &Path,
) -> Result<ExportReport, Error> {
    let mut extent = Extent::default();
    dir.check(&mut extent)?;
    fn rows<'a, T: 'a>(table: Option<Rows<T>>) -> Stream<'a, T> {
        match table {
            Some(rows) => Box::new(rows),
            None => Box::new(std::iter::empty()),
        }
    }
    let source = Source {
        meta: dir.meta(),
        tables: dir.tables(),
        commands: Box::new(dir.commands()?),
        odometry: rows(dir.odometry()?),
        odometry_again: rows(dir.odometry()?),
        lidar: rows(dir.lidar()?),
        sonar: rows(dir.sonar()?),
        truth: rows(dir.truth()?),
    };
    write_file(source, &extent, options, out)
}

fn write_file(
    source: Source<'_>,
    extent: &Extent,
    options: &ExportOptions<'_>,
    out: &Path,
) -> Result<ExportReport, Error> {
    extent.check_stamps()?;
    let file = AtomicFile::create(out)?;
    let fail = |err: mcap::McapError| mcap_failure(out, err);
    let writer = WriteOptions::new()
        .profile("ros2")
        .library(concat!("hilsim ", env!("CARGO_PKG_VERSION")))
        .compression(options.compress.then_some(Compression::Zstd))
        .disable_seeking(true)
        .create(NoSeek::new(file))
        .map_err(fail)?;
    let mut bag = Bag {
        writer,
        out,
        channels: BTreeMap::new(),
        sequence: 0,
        buffer: Vec::with_capacity(1 << 14),
        report: ExportReport::default(),
    };
    write_all(&mut bag, source, extent, options)?;
    bag.writer.finish().map_err(fail)?;
    let report = std::mem::take(&mut bag.report);
    let file = bag.writer.into_inner().into_inner();
    file.commit()?;
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::merge::{Merge, Next, Revolutions, MAX_SCAN_READINGS};
    use crate::export::options::stamp_ns;
    use crate::msgs::{Odometry, TfMessage, TransformStamped};
    use hilsim_recording::{CommandSample, LidarSample, OdometrySample, SonarSample, TruthSample};

    /// A time that a stamp's int32 seconds cannot hold is refused, naming the table and row,
    /// not wrapped to 1901.
    #[test]
    fn times_no_stamp_holds_are_refused_not_wrapped() {
        use hilsim_recording::{Meta, TruthSample};
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("x.mcap");
        let mut rec = Recording::new(Meta::default());
        let pose = |t_s| TruthSample {
            t_s,
            x_m: 0.0,
            y_m: 0.0,
            yaw_rad: 0.0,
        };
        // The last second a stamp holds, from t = 0 stamped at START_NS.
        rec.truth = Some(vec![pose(0.0), pose(2_147_483_646.5)]);
        export(&rec, None, &out).unwrap();
        // One second later the seconds would be 2³¹: refused, at the nanosecond.
        rec.truth = Some(vec![pose(2_147_483_647.0)]);
        assert!(export(&rec, None, &out).is_err());
        rec.truth = Some(vec![pose(0.0), pose(1.0), pose(3.7e292)]);
        let err = export(&rec, None, &out).unwrap_err().to_string();
        assert!(
            err.starts_with("truth.csv: row 3: t_s 3.7e292 s, beyond what a ROS 2 stamp holds"),
            "{err}"
        );
    }
    use crate::bag::{self, Item};
    use crate::cdr::decode;
    use hilsim_recording::{Meta, Mount};
    use std::cell::Cell;

    /// Every transform of a file (`/tf` and `/tf_static`), and its `/odom` messages.
    fn transforms_and_odometry(path: &Path) -> (Vec<TransformStamped>, Vec<Odometry>) {
        let mut topics = BTreeMap::new();
        let (mut transforms, mut odometry) = (Vec::new(), Vec::new());
        bag::stream(path, |item| {
            match item {
                Item::Channel(c) => {
                    topics.insert(c.id, c.topic);
                }
                Item::Message {
                    channel_id, data, ..
                } => match topics[&channel_id].as_str() {
                    "/tf" | "/tf_static" => {
                        let message: TfMessage = decode(data).unwrap();
                        transforms.extend(message.transforms);
                    }
                    "/odom" => odometry.push(decode(data).unwrap()),
                    _ => {}
                },
                Item::Metadata(_) => {}
            }
            Ok(())
        })
        .unwrap();
        (transforms, odometry)
    }

    /// Each frame's one parent; a frame with two is a broken tree.
    fn parents(transforms: &[TransformStamped]) -> BTreeMap<String, String> {
        let mut parents = BTreeMap::new();
        for tf in transforms {
            let parent = &tf.header.frame_id;
            let old = parents.insert(tf.child_frame_id.clone(), parent.clone());
            assert!(old.is_none_or(|p| &p == parent), "{tf:?}: two parents");
        }
        parents
    }

    fn root(frame: &str, parents: &BTreeMap<String, String>) -> String {
        let mut frame = frame.to_string();
        for _ in 0..10 {
            match parents.get(&frame) {
                Some(parent) => frame.clone_from(parent),
                None => return frame,
            }
        }
        panic!("a cycle through {frame}");
    }

    /// A robot driving an arc, its odometry drifting from the truth (a wheel 2 % long).
    fn run(truth: bool, odometry: bool) -> Recording {
        let mut rec = Recording::new(Meta {
            lidar: Some(Mount::default()),
            ..Meta::default()
        });
        let b = rec.meta.robot.wheel_base_m;
        let (v, w) = (0.2, 0.3);
        let steps = 0..=40;
        if truth {
            rec.truth = Some(
                steps
                    .clone()
                    .map(|i| {
                        let t_s = f64::from(i) * 0.05 + 0.013;
                        let yaw = w * t_s;
                        TruthSample {
                            t_s,
                            x_m: 1.0 + v / w * yaw.sin(),
                            y_m: 2.0 + v / w * (1.0 - yaw.cos()),
                            yaw_rad: yaw,
                        }
                    })
                    .collect(),
            );
        }
        if odometry {
            rec.odometry = Some(
                steps
                    .clone()
                    .map(|i| {
                        let t_s = f64::from(i) * 0.1;
                        OdometrySample {
                            t_s,
                            left_m: (v - 0.5 * w * b) * t_s,
                            right_m: 1.02 * (v + 0.5 * w * b) * t_s,
                        }
                    })
                    .collect(),
            );
        }
        rec.lidar = Some(vec![LidarSample {
            t_s: 0.0,
            rev: 0,
            angle_deg: 0.0,
            range_m: 1.0,
            strength: 10,
            invalid: false,
            warning: false,
            true_range_m: None,
        }]);
        rec.sonar = Some(vec![SonarSample {
            t_s: 0.0,
            range_m: 1.0,
            true_range_m: None,
        }]);
        rec
    }

    /// The frames are one tree rooted at `map` (REP 105: map → odom → base_link → sensors),
    /// `/odom` names its frames as the tree does, and at each truth time the tree puts
    /// base_link where the truth is (odom → base_link interpolated as tf2 does).
    #[test]
    fn the_frames_are_one_tree_that_puts_the_robot_at_the_truth() {
        let dir = tempfile::tempdir().unwrap();
        for (truth, odometry) in [(true, true), (true, false), (false, true), (false, false)] {
            let rec = run(truth, odometry);
            let path = dir.path().join("run.mcap");
            export(&rec, None, &path).unwrap();
            let (transforms, odometry_messages) = transforms_and_odometry(&path);
            let parents = parents(&transforms);
            for frame in ["laser", "sonar", "base_link"] {
                assert_eq!(root(frame, &parents), "map", "{frame} {truth} {odometry}");
            }
            for message in &odometry_messages {
                assert_eq!(message.header.frame_id, "odom");
                assert_eq!(message.child_frame_id, "base_link");
                assert_eq!(root("odom", &parents), "map");
            }
            assert_eq!(
                odometry_messages.len(),
                rec.odometry.as_ref().map_or(0, Vec::len)
            );
            let Some(truth) = &rec.truth else { continue };
            let stamp = |tf: &TransformStamped| tf.header.stamp.ns();
            let planar = |tf: &TransformStamped| {
                let t = &tf.transform;
                hilsim_recording::Pose::new(t.translation.x, t.translation.y, t.rotation.yaw())
            };
            let odom_base: Vec<_> = transforms
                .iter()
                .filter(|tf| tf.child_frame_id == "base_link" && tf.header.frame_id == "odom")
                .collect();
            for p in truth {
                let t_ns = stamp_ns(p.t_s);
                let at = transforms
                    .iter()
                    .find(|tf| tf.header.frame_id == "map" && stamp(tf) == t_ns)
                    .unwrap();
                let in_map = if odom_base.is_empty() {
                    planar(at)
                } else {
                    // odom → base_link at t_ns, between the two stamps around it.
                    let k = odom_base.partition_point(|tf| stamp(tf) <= t_ns);
                    let (a, b) = (odom_base[k - 1], odom_base[k.min(odom_base.len() - 1)]);
                    let f = if k < odom_base.len() {
                        (t_ns - stamp(a)) as f64 / (stamp(b) - stamp(a)) as f64
                    } else {
                        0.0
                    };
                    let between = planar(a).lerp(&planar(b), f);
                    planar(at).compose(between.x, between.y, between.yaw)
                };
                let yaw_error = hilsim_recording::wrap_angle(in_map.yaw - p.yaw_rad);
                // Rounding only: a few sums and products of numbers below 10.
                let close = (in_map.x - p.x_m).abs() < 1e-9 && (in_map.y - p.y_m).abs() < 1e-9;
                assert!(close && yaw_error.abs() < 1e-9, "{p:?}: {in_map:?}");
            }
        }
    }

    /// A recording with every table: the arc of [`run`], three revolutions, commands at times
    /// the other tables share (ties), a sonar.
    fn full() -> Recording {
        let mut rec = run(true, true);
        rec.lidar = Some(
            (0..3u32)
                .flat_map(|rev| {
                    (0..360u32).map(move |a| LidarSample {
                        t_s: f64::from(rev) * 0.2 + f64::from(a) * 0.2 / 360.0,
                        rev: rev.into(),
                        angle_deg: f64::from(a),
                        range_m: 1.0 + f64::from(a) / 100.0,
                        strength: 100,
                        invalid: a % 7 == 0,
                        warning: false,
                        true_range_m: None,
                    })
                })
                .collect(),
        );
        rec.commands = (0..5)
            .map(|i| CommandSample {
                t_s: f64::from(i) * 0.1,
                left_mps: 0.1,
                right_mps: 0.12,
            })
            .collect();
        rec
    }

    /// The streamed export of a directory writes the very bytes of the export of the same
    /// recording held in memory (with the calibrated scans too).
    #[test]
    fn a_directory_exports_the_bytes_of_its_recording_in_memory() {
        let dir = tempfile::tempdir().unwrap();
        let rec = full();
        let path = dir.path().join("run");
        rec.write_dir(&path).unwrap();
        let calibrated = |s: &LidarSample| if s.invalid { f64::NAN } else { 0.9 * s.range_m };
        let world = World {
            walls: vec![[[0.0, 0.0], [1.0, 0.0]]],
            ..World::default()
        };
        let options = ExportOptions {
            world: Some(&world),
            calibrated: Some(&calibrated),
            ..ExportOptions::default()
        };
        let (held, streamed) = (
            dir.path().join("held.mcap"),
            dir.path().join("streamed.mcap"),
        );
        let report = export_with(&rec, &options, &held).unwrap();
        let run = RecordingDir::open(&path).unwrap();
        assert_eq!(export_dir(&run, &options, &streamed).unwrap(), report);
        assert_eq!(report.messages["/scan"], 3);
        assert_eq!(
            std::fs::read(&held).unwrap(),
            std::fs::read(&streamed).unwrap()
        );
    }

    /// A table's stream that counts the rows taken from it.
    fn counted<'a, T: Copy + 'a>(rows: &'a [T], taken: &'a Cell<usize>) -> Stream<'a, T> {
        Box::new(rows.iter().map(move |&row| {
            taken.set(taken.get() + 1);
            Ok(row)
        }))
    }

    /// Merging the tables by time holds one row of each table ahead of the messages given
    /// out (of the lidar, a revolution and a row), in time order: what an export holds does not
    /// grow with the tables.
    #[test]
    fn the_merge_holds_one_row_of_each_table_ahead() {
        let rec = full();
        let taken: [Cell<usize>; 5] = Default::default();
        let mut given = [0usize; 5];
        let mut merge = Merge::new(
            counted(rec.lidar.as_deref().unwrap(), &taken[0]),
            counted(&rec.commands, &taken[1]),
            counted(rec.odometry.as_deref().unwrap(), &taken[2]),
            counted(rec.sonar.as_deref().unwrap(), &taken[3]),
            counted(rec.truth.as_deref().unwrap(), &taken[4]),
        )
        .unwrap();
        let mut last = f64::NEG_INFINITY;
        while let Some((t_s, next)) = merge.next().unwrap() {
            assert!(t_s >= last, "{t_s} after {last}");
            last = t_s;
            match next {
                Next::Scan => given[0] += merge.revolution().len(),
                Next::Command(_) => given[1] += 1,
                Next::Odometry(_) => given[2] += 1,
                Next::Sonar(_) => given[3] += 1,
                Next::Truth(_) => given[4] += 1,
            }
            // A revolution held besides the row after it.
            let ahead = [360 + 1, 1, 1, 1, 1];
            for ((taken, given), ahead) in taken.iter().zip(given).zip(ahead) {
                let taken = taken.get();
                assert!(taken <= given + ahead, "{taken} taken, {given} given");
            }
        }
        let rows = [360 * 3, 5, 41, 1, 41];
        assert_eq!(given, rows);
    }

    /// A revolution longer than [`MAX_SCAN_READINGS`] is sent as several scans, so what is held
    /// for one is bounded whatever the file says.
    #[test]
    fn a_revolution_longer_than_the_bound_is_sent_as_several_scans() {
        let taken = Cell::new(0);
        let rows = 2 * MAX_SCAN_READINGS + 5;
        let lidar = (0..rows).map(|i| {
            taken.set(taken.get() + 1);
            Ok(LidarSample {
                t_s: i as f64 * 1e-6,
                rev: 0,
                angle_deg: (i % 360) as f64,
                range_m: 1.0,
                strength: 1,
                invalid: false,
                warning: false,
                true_range_m: None,
            })
        });
        let mut revolutions = Revolutions::new(Box::new(lidar)).unwrap();
        let mut sizes = Vec::new();
        while !revolutions.current.is_empty() {
            assert!(taken.get() <= sizes.iter().sum::<usize>() + MAX_SCAN_READINGS + 1);
            sizes.push(revolutions.current.len());
            revolutions.advance().unwrap();
        }
        assert_eq!(sizes, [MAX_SCAN_READINGS, MAX_SCAN_READINGS, 5]);
    }

    /// A malformed table stops a streamed export before anything is written, with the error a
    /// reader of the whole recording gives (a row of the wrong width before an earlier bad
    /// value), not the first the merge would meet.
    #[test]
    fn a_malformed_table_is_read_dirs_error_and_nothing_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run");
        full().write_dir(&path).unwrap();
        let sonar = "t_s,range_m\n0,1\n0.1,abc\n0.2\n";
        std::fs::write(path.join("sonar.csv"), sonar).unwrap();
        let whole = Recording::read_dir(&path).unwrap_err().to_string();
        assert!(whole.ends_with("sonar.csv:4: expected 2 fields (t_s,range_m), found 1"));
        let out = dir.path().join("run.mcap");
        let run = RecordingDir::open(&path).unwrap();
        let err = export_dir(&run, &ExportOptions::default(), &out).unwrap_err();
        assert_eq!(err.to_string(), whole);
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "only the recording"
        );
    }
}
