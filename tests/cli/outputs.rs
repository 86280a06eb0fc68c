//! Outputs never lose a user's data: a directory output replaces only a previous
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
fn record_refuses_a_directory_that_is_not_a_recording() {
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
fn record_and_run_refuse_a_file_at_the_output() {
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
fn a_previous_recording_and_an_empty_directory_are_replaced() {
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
fn decode_writes_through_a_device_and_never_replaces_it() {
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
fn decode_refuses_to_write_over_its_input_or_a_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("capture.bin");
    fs::copy(capture(), &input).unwrap();
    let before = fs::read(&input).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["decode", "capture.bin", "--csv", "capture.bin"],
    ));
    assert!(err.contains("is an input"), "{err}");
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
fn a_csv_through_a_link_replaces_the_linked_previous_csv_and_keeps_the_link() {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(
        tmp.path().join("target.csv"),
        "rev,packet_index,angle_deg,distance_mm,range_m,strength,invalid,warning,error_code,rpm\n",
    )
    .unwrap();
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
fn smooth_refuses_to_write_over_the_recording() {
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
fn what_a_killed_writer_left_is_tidied_and_an_orphaned_recording_restored() {
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

/// A recording `R` made by `record`, with the user's own notes and plots beside it.
fn recording_with_user_files(cwd: &Path) {
    let o = record(cwd, "R");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    fs::write(cwd.join("R/NOTES.txt"), "calibrated on Tuesday").unwrap();
    fs::create_dir(cwd.join("R/plots")).unwrap();
    fs::write(cwd.join("R/plots/fit.json"), "{}").unwrap();
}

#[test]
fn a_recording_replaced_by_record_run_or_import_keeps_the_users_files_beside_it() {
    let tmp = tempfile::tempdir().unwrap();
    recording_with_user_files(tmp.path());
    let scenario = repo_file("scenarios/straight-board.toml");
    let scenario = scenario.to_str().unwrap();
    let o = hilsim(tmp.path(), &["export", "R", "--mcap", "robot.mcap"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for args in [
        vec!["record", scenario, "--out", "R"],
        vec!["run", scenario, "--out", "R"],
        vec!["import", "robot.mcap", "--out", "R"],
    ] {
        let o = hilsim(tmp.path(), &args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let notes = fs::read_to_string(tmp.path().join("R/NOTES.txt"));
        assert_eq!(notes.unwrap(), "calibrated on Tuesday", "{args:?}");
        assert!(tmp.path().join("R/plots/fit.json").is_file(), "{args:?}");
        assert!(tmp.path().join("R/lidar.csv").is_file(), "{args:?}");
    }
    // What was the previous run's own is not kept beside a recording that is not a run's.
    assert!(!tmp.path().join("R/results.json").exists());
}

#[test]
fn import_refuses_a_bag_inside_the_directory_it_would_replace() {
    let tmp = tempfile::tempdir().unwrap();
    recording_with_user_files(tmp.path());
    let o = hilsim(tmp.path(), &["export", "R", "--mcap", "R/robot.mcap"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let bag = fs::read(tmp.path().join("R/robot.mcap")).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["import", "R/robot.mcap", "--out", "R"],
    ));
    assert!(err.contains("inside the output directory"), "{err}");
    assert_eq!(fs::read(tmp.path().join("R/robot.mcap")).unwrap(), bag);
    // Through a link to the directory, too.
    std::os::unix::fs::symlink("R", tmp.path().join("linkR")).unwrap();
    assert_bad_input(&hilsim(
        tmp.path(),
        &["import", "R/robot.mcap", "--out", "linkR"],
    ));
    assert_eq!(fs::read(tmp.path().join("R/robot.mcap")).unwrap(), bag);
}

#[test]
fn an_output_directory_that_holds_the_working_directory_is_refused_and_nothing_is_left() {
    let tmp = tempfile::tempdir().unwrap();
    let inner = tmp.path().join("inner");
    fs::create_dir(&inner).unwrap();
    let scenario = repo_file("scenarios/straight-board.toml");
    for command in ["record", "run"] {
        for out in [".", ".."] {
            let args = [command, scenario.to_str().unwrap(), "--out", out];
            let err = assert_bad_input(&hilsim(&inner, &args));
            assert!(err.contains("working directory"), "{err}");
        }
    }
    assert_eq!(
        fs::read_dir(&inner).unwrap().count(),
        0,
        "a leftover in the cwd"
    );
    assert_eq!(
        fs::read_dir(tmp.path()).unwrap().count(),
        1,
        "a leftover beside it"
    );
}

#[test]
fn a_single_file_output_never_replaces_an_input_or_a_file_of_another_kind() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    assert_eq!(record(cwd, "R").status.code(), Some(0));
    fs::copy(
        repo_file("scenarios/straight-board.toml"),
        cwd.join("s.toml"),
    )
    .unwrap();
    fs::write(cwd.join("thesis.txt"), "chapter one").unwrap();
    std::os::unix::fs::symlink("thesis.txt", cwd.join("link.mcap")).unwrap();
    let lidar = fs::read(cwd.join("R/lidar.csv")).unwrap();
    for args in [
        vec!["export", "R", "--mcap", "R/lidar.csv"],
        vec!["export", "R", "--scenario", "s.toml", "--mcap", "s.toml"],
        vec!["record", "s.toml", "--out", "R2", "--mcap", "s.toml"],
        vec!["run", "s.toml", "--mcap", "s.toml"],
        vec!["export", "R", "--mcap", "thesis.txt"],
        vec!["export", "R", "--mcap", "link.mcap"],
    ] {
        let err = assert_bad_input(&hilsim(cwd, &args));
        assert!(err.contains("refusing"), "{args:?}: {err}");
    }
    assert_eq!(fs::read(cwd.join("R/lidar.csv")).unwrap(), lidar);
    assert_eq!(
        fs::read_to_string(cwd.join("thesis.txt")).unwrap(),
        "chapter one"
    );
    assert!(fs::read_to_string(cwd.join("s.toml"))
        .unwrap()
        .contains("[robot]"));
    assert!(
        !cwd.join("R2").exists(),
        "record ran before refusing its --mcap"
    );
    // A previous MCAP is replaced, and what a killed export left beside it is tidied.
    let leftover = cwd.join(format!(".x.mcap.tmp.{}", dead_pid()));
    fs::write(&leftover, "half").unwrap();
    for _ in 0..2 {
        let o = hilsim(cwd, &["export", "R", "--mcap", "x.mcap"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    assert!(
        !leftover.exists(),
        "a killed export's temporary file was kept"
    );
}

/// Runs `sh -c SCRIPT` in `cwd` with the hilsim binary as `$H`; its exit code.
fn shell(cwd: &Path, script: &str) -> Option<i32> {
    std::process::Command::new("bash")
        .args(["-c", script])
        .current_dir(cwd)
        .env("H", env!("CARGO_BIN_EXE_hilsim"))
        .status()
        .unwrap()
        .code()
}

#[test]
fn standard_output_as_the_output_file_appends_where_the_shell_said_and_feeds_a_pipe() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    assert_eq!(record(cwd, "R").status.code(), Some(0));
    let cap = capture();
    let cap = cap.to_str().unwrap();
    fs::write(cwd.join("log"), "earlier line\n").unwrap();
    let script = format!("\"$H\" decode {cap} --csv /dev/stdout >> log");
    assert_eq!(shell(cwd, &script), Some(0));
    let log = fs::read_to_string(cwd.join("log")).unwrap();
    assert!(
        log.starts_with("earlier line\nrev,packet_index"),
        "{}",
        &log[..60]
    );
    // The counts go to stderr, not into the table.
    assert!(!log.contains("packets"), "the summary went into the table");
    fs::write(cwd.join("log.bin"), "earlier\n").unwrap();
    assert_eq!(
        shell(
            cwd,
            "\"$H\" export R --mcap /dev/stdout >> log.bin 2>/dev/null"
        ),
        Some(0)
    );
    let bytes = fs::read(cwd.join("log.bin")).unwrap();
    assert!(bytes.starts_with(b"earlier\n\x89MCAP0\r\n"));
    // Into a pipe, and into one whose reader stops early: success either way.
    let pipe = format!(
        "\"$H\" decode {cap} --csv /dev/stdout | wc -c >/dev/null; exit ${{PIPESTATUS[0]}}"
    );
    assert_eq!(shell(cwd, &pipe), Some(0));
    let closed = format!(
        "\"$H\" decode {cap} --csv /dev/stdout | head -c 1 >/dev/null; exit ${{PIPESTATUS[0]}}"
    );
    assert_eq!(shell(cwd, &closed), Some(0));
    let export_closed =
        "\"$H\" export R --mcap /dev/stdout 2>/dev/null | head -c 1 >/dev/null; exit ${PIPESTATUS[0]}";
    assert_eq!(shell(cwd, export_closed), Some(0));
}

#[test]
fn report_pages_and_dataset_manifests_refuse_a_link_and_a_users_page() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    assert_eq!(record(cwd, "R").status.code(), Some(0));
    let o = hilsim(cwd, &["report", "R", "--out", "rep1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let page = fs::read(cwd.join("rep1/index.html")).unwrap();
    fs::create_dir(cwd.join("rep2")).unwrap();
    std::os::unix::fs::symlink("../rep1/index.html", cwd.join("rep2/index.html")).unwrap();
    let err = assert_bad_input(&hilsim(cwd, &["report", "R", "--out", "rep2"]));
    assert!(err.contains("symbolic link"), "{err}");
    assert_eq!(fs::read(cwd.join("rep1/index.html")).unwrap(), page);
    // diagnose --report: a user's page, or a user's map beside no report, stays.
    fs::create_dir_all(cwd.join("mine")).unwrap();
    fs::write(cwd.join("mine/index.html"), "<html>mine</html>").unwrap();
    fs::create_dir_all(cwd.join("maps")).unwrap();
    fs::write(cwd.join("maps/map.svg"), "<svg/>").unwrap();
    let room = repo_file("scenarios/diagnose-room.toml");
    for dir in ["mine", "maps"] {
        let args = [
            "diagnose",
            "--sim",
            room.to_str().unwrap(),
            "--real",
            "R",
            "--report",
            dir,
        ];
        let err = assert_bad_input(&hilsim(cwd, &args));
        assert!(err.contains("not"), "{err}");
    }
    assert_eq!(
        fs::read_to_string(cwd.join("mine/index.html")).unwrap(),
        "<html>mine</html>"
    );
    assert_eq!(
        fs::read_to_string(cwd.join("maps/map.svg")).unwrap(),
        "<svg/>"
    );
    // A dataset's manifest that links to another dataset's is not written through.
    let scenario = repo_file("scenarios/straight-board.toml");
    let scenario = scenario.to_str().unwrap();
    for out in ["a", "b"] {
        let o = hilsim(cwd, &["dataset", scenario, "--runs", "2", "--out", out]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let manifest_a = fs::read(cwd.join("a/manifest.csv")).unwrap();
    fs::remove_file(cwd.join("b/manifest.csv")).unwrap();
    std::os::unix::fs::symlink("../a/manifest.csv", cwd.join("b/manifest.csv")).unwrap();
    let err = assert_bad_input(&hilsim(
        cwd,
        &["dataset", scenario, "--runs", "2", "--out", "b"],
    ));
    assert!(err.contains("symbolic link"), "{err}");
    assert_eq!(fs::read(cwd.join("a/manifest.csv")).unwrap(), manifest_a);
}
