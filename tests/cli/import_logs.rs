//! `hilsim import` of robots' logs (CARMEN, CoreSLAM): each into a recording that reads back,
//! what was skipped said in notes, and options for ROS 2 bags refused.

use hilsim_recording::Recording;

use crate::common::{assert_bad_input, hilsim, stdout};

/// A CARMEN log: a comment, two FLASER scans of 180 beams, two ODOM lines, an unknown kind.
fn carmen() -> String {
    let ranges = vec!["1.5"; 180].join(" ");
    [
        "# CARMEN Logfile".to_string(),
        "ODOM 0 0 0 0 0 0 1.0 host 1.0".to_string(),
        format!("FLASER 180 {ranges} 1 2 0.1 1 2 0.1 1.1 host 1.1"),
        "NEFF 3".to_string(),
        "ODOM 0.1 0 0 0 0 0 1.2 host 1.2".to_string(),
        format!("FLASER 180 {ranges} 1.1 2 0.1 1.1 2 0.1 1.3 host 1.3"),
    ]
    .join("\n")
}

/// A CoreSLAM log of two lines: 24 header fields (time in µs, encoder counts in 3 and 4), 682
/// ranges in mm.
fn coreslam() -> String {
    (0..2)
        .map(|k| {
            let mut f = vec![(k * 100_000).to_string(), "0".into(), (k * 10).to_string()];
            f.push((k * 20).to_string());
            f.extend((0..20).map(|_| "0".to_string()));
            f.extend((0..682).map(|_| "1500".to_string()));
            f.join(" ")
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn a_carmen_log_imports_with_notes() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("run.clf"), carmen()).unwrap();
    let out = hilsim(tmp.path(), &["import", "run.clf", "--out", "r"]);
    let text = stdout(&out);
    assert!(
        out.status.success(),
        "{text}{}",
        crate::common::stderr(&out)
    );
    assert!(text.contains("lidar     2 scans: 360 rows"), "{text}");
    assert!(
        text.contains("odometry  2 rows") && text.contains("truth     2 rows"),
        "{text}"
    );
    assert!(
        text.contains("note: run.clf: lines of kinds not read, skipped: NEFF ×1"),
        "{text}"
    );
    let rec = Recording::read_dir(&tmp.path().join("r")).unwrap();
    assert_eq!(rec.lidar.unwrap().len(), 360);
    assert_eq!(rec.truth.unwrap()[1].x_m, 1.1);
    // The scan lines' poses as the odometry's instead: no truth.
    let out = hilsim(
        tmp.path(),
        &["import", "run.clf", "--out", "o", "--poses", "odometry"],
    );
    assert!(out.status.success(), "{}", crate::common::stderr(&out));
    let rec = Recording::read_dir(&tmp.path().join("o")).unwrap();
    assert!(rec.truth.is_none() && rec.odometry.is_some());
}

#[test]
fn a_coreslam_log_imports() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("exp.dat"), coreslam()).unwrap();
    let out = hilsim(tmp.path(), &["import", "exp.dat", "--out", "r"]);
    let text = stdout(&out);
    assert!(
        out.status.success(),
        "{text}{}",
        crate::common::stderr(&out)
    );
    assert!(text.contains("lidar     2 scans: 1364 rows"), "{text}");
    let rec = Recording::read_dir(&tmp.path().join("r")).unwrap();
    assert_eq!(rec.odometry.unwrap().len(), 2);
    assert_eq!(rec.meta.lidar.unwrap().x_m, 0.145);
}

#[test]
fn bag_options_with_a_log_are_one_line_errors() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("run.log"), carmen()).unwrap();
    let out = hilsim(
        tmp.path(),
        &["import", "run.log", "--out", "r", "--lidar", "/scan"],
    );
    let err = assert_bad_input(&out);
    assert!(err.contains("--lidar is for ROS bags"), "{err}");
    std::fs::write(tmp.path().join("exp.dat"), coreslam()).unwrap();
    let args = ["import", "exp.dat", "--out", "r", "--log-poses", "odometry"];
    let err = assert_bad_input(&hilsim(tmp.path(), &args));
    assert!(err.contains("--poses is for CARMEN logs"), "{err}");
}
