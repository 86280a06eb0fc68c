//! Outputs never lose a user's data (issue 18): a directory output replaces only a previous
//! recording (or an empty directory), a file output follows links, writes through devices and
//! never overwrites an input.

use std::fs;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;

use super::common::*;

fn record(cwd: &Path, out: &str) -> std::process::Output {
    let scenario = repo_file("scenarios/straight-board.toml");
    hilsim(cwd, &["record", scenario.to_str().unwrap(), "--out", out])
}

#[test]
fn issue_18_record_refuses_a_directory_that_is_not_a_recording() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("x");
    fs::create_dir(&dir).unwrap();
    fs::write(dir.join("p.txt"), "precious").unwrap();
    let err = assert_bad_input(&record(tmp.path(), "x"));
    assert!(
        err.contains("x: exists and holds something other than a hilsim recording"),
        "{err}"
    );
    assert_eq!(fs::read_to_string(dir.join("p.txt")).unwrap(), "precious");
    assert_eq!(fs::read_dir(&dir).unwrap().count(), 1);
}

#[test]
fn issue_18_record_and_run_refuse_a_file_at_the_output() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(tmp.path().join("x"), "precious").unwrap();
    let err = assert_bad_input(&record(tmp.path(), "x"));
    assert!(err.contains("exists and is not a directory"), "{err}");
    let o = hilsim(tmp.path(), &["run", "--out", "x"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(
        fs::read_to_string(tmp.path().join("x")).unwrap(),
        "precious"
    );
    // Nothing of the refused runs is left beside it.
    assert_eq!(fs::read_dir(tmp.path()).unwrap().count(), 1);
}

#[test]
fn issue_18_a_previous_recording_and_an_empty_directory_are_replaced() {
    let tmp = tempfile::tempdir().unwrap();
    fs::create_dir(tmp.path().join("empty")).unwrap();
    for out in ["empty", "rec", "rec"] {
        let o = record(tmp.path(), out);
        assert_eq!(o.status.code(), Some(0), "{out}: {}", stderr(&o));
        assert!(tmp.path().join(out).join("meta.toml").is_file());
    }
    // `run --out` writes a recording too, so it replaces one.
    let o = hilsim(tmp.path(), &["run", "--out", "rec"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(tmp.path().join("rec/results.json").is_file());
}

fn capture() -> std::path::PathBuf {
    repo_file("tests/data/captures/xv11-hand-in-box.bin")
}

#[test]
fn issue_18_decode_writes_through_a_device_and_never_replaces_it() {
    let tmp = tempfile::tempdir().unwrap();
    let o = hilsim(
        tmp.path(),
        &["decode", capture().to_str().unwrap(), "--csv", "/dev/null"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let kind = fs::metadata("/dev/null").unwrap().file_type();
    assert!(kind.is_char_device(), "/dev/null was replaced");
}

#[test]
fn issue_18_decode_refuses_to_write_over_its_input_or_a_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("capture.bin");
    fs::copy(capture(), &input).unwrap();
    let before = fs::read(&input).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["decode", "capture.bin", "--csv", "capture.bin"],
    ));
    assert!(err.contains("is the input"), "{err}");
    assert_eq!(fs::read(&input).unwrap(), before);
    // Through a link to it, too.
    std::os::unix::fs::symlink("capture.bin", tmp.path().join("link.csv")).unwrap();
    assert_bad_input(&hilsim(
        tmp.path(),
        &["decode", "capture.bin", "--csv", "link.csv"],
    ));
    assert_eq!(fs::read(&input).unwrap(), before);
    fs::create_dir(tmp.path().join("d")).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["decode", "capture.bin", "--csv", "d"],
    ));
    assert!(err.contains("is a directory"), "{err}");
}

#[test]
fn issue_18_a_csv_through_a_link_replaces_the_linked_file_and_keeps_the_link() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(tmp.path().join("target.csv"), "old").unwrap();
    std::os::unix::fs::symlink("target.csv", tmp.path().join("link.csv")).unwrap();
    let o = hilsim(
        tmp.path(),
        &["decode", capture().to_str().unwrap(), "--csv", "link.csv"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let link = fs::symlink_metadata(tmp.path().join("link.csv")).unwrap();
    assert!(link.file_type().is_symlink(), "the link was replaced");
    let text = fs::read_to_string(tmp.path().join("target.csv")).unwrap();
    assert!(
        text.starts_with("rev,packet_index"),
        "{}",
        &text[..40.min(text.len())]
    );
}

#[test]
fn issue_18_smooth_refuses_to_write_over_the_recording() {
    let tmp = tempfile::tempdir().unwrap();
    assert_eq!(record(tmp.path(), "rec").status.code(), Some(0));
    fs::write(tmp.path().join("cal.json"), "{}").unwrap();
    let lidar = fs::read(tmp.path().join("rec/lidar.csv")).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &[
            "smooth",
            "rec",
            "--calibration",
            "cal.json",
            "--csv",
            "rec/lidar.csv",
        ],
    ));
    assert!(err.contains("is an input"), "{err}");
    assert_eq!(fs::read(tmp.path().join("rec/lidar.csv")).unwrap(), lidar);
}

/// A process id that is certainly not running: a child that has exited and been reaped.
fn dead_pid() -> u32 {
    let mut child = std::process::Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

#[test]
fn issue_18_what_a_killed_writer_left_is_tidied_and_an_orphaned_recording_restored() {
    let tmp = tempfile::tempdir().unwrap();
    let pid = dead_pid();
    // An unfinished new recording of a killed `record --out rec`.
    let unfinished = tmp.path().join(format!(".rec.tmp.{pid}"));
    fs::create_dir(&unfinished).unwrap();
    fs::write(unfinished.join("lidar.csv"), vec![b'0'; 1 << 20]).unwrap();
    // A writer killed between its renames: the previous recording is only beside `rec`.
    let o = record(tmp.path(), "prev");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    fs::rename(
        tmp.path().join("prev"),
        tmp.path().join(format!(".rec.old.{pid}")),
    )
    .unwrap();
    // Someone else's hidden files are not ours to touch.
    fs::write(tmp.path().join(".rec.notes"), "mine").unwrap();
    let o = record(tmp.path(), "rec");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut left: Vec<String> = fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, [".rec.notes", "rec"]);
    assert!(tmp.path().join("rec/meta.toml").is_file());
}
