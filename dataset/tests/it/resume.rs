//! A dataset must be the same whatever the number of threads, an interrupted one must
//! resume to exactly the dataset an uninterrupted call makes (half-written runs and a stale
//! manifest left behind), a directory of another dataset must be refused, and a run that fails
//! must be recorded while the others go on.

use std::fs;
use std::path::Path;

use super::common::*;
use hilsim_dataset::{Error, Options, Shard};
use hilsim_lidar_emulator::Emulation;
use hilsim_sim::Scenario;

const VARIES: &[&str] = &[
    "robot.start.x=-0.5..0.5",
    "sensors.lidar.angle_noise_deg=0..2",
];

#[test]
fn the_dataset_is_the_same_whatever_the_number_of_threads() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(8, VARIES);
    let one = tmp.path().join("one");
    let two = tmp.path().join("two");
    let s1 = d.generate(&one, &options(1, Shard::ALL), &mut ()).unwrap();
    let s2 = d.generate(&two, &options(2, Shard::ALL), &mut ()).unwrap();
    assert_eq!((s1.made, s1.skipped, s1.failed), (8, 0, 0));
    assert_eq!((s2.made, s2.skipped, s2.failed), (8, 0, 0));
    assert_same_tree(&one, &two);
    // A rerun skips everything and changes nothing.
    let before = tree(&one);
    let again = d.generate(&one, &options(2, Shard::ALL), &mut ()).unwrap();
    assert_eq!((again.made, again.skipped), (0, 8));
    assert_eq!(tree(&one), before);
}

#[test]
fn an_interrupted_dataset_resumes_to_the_uninterrupted_one() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(10, VARIES);
    let reference = tmp.path().join("reference");
    d.generate(&reference, &Options::default(), &mut ())
        .unwrap();

    // What an interruption leaves: some runs complete, one half-written in its temporary
    // directory, a half-written manifest beside a stale one that lacks the last runs made.
    let dir = tmp.path().join("interrupted");
    d.generate(&dir, &Options::default(), &mut ()).unwrap();
    for r in [2, 5, 6, 9] {
        fs::remove_dir_all(dir.join(format!("run-{r:06}"))).unwrap();
    }
    // Left by a writer that is gone: its pid above Linux's largest (2^22), which no live
    // process has (a small pid may be a live process's on a busy machine, and its temporaries
    // are then left alone as another writer's).
    let half = dir.join(".run-000005.tmp.4194305");
    fs::create_dir(&half).unwrap();
    fs::write(half.join("lidar.csv"), "t_s,rev\n0.1,").unwrap();
    fs::write(dir.join(".manifest.csv.tmp.4194305"), "run,se").unwrap();
    let manifest = fs::read_to_string(dir.join("manifest.csv")).unwrap();
    let stale: String = manifest.lines().take(3).map(|l| format!("{l}\n")).collect();
    fs::write(dir.join("manifest.csv"), stale).unwrap();

    let s = d.generate(&dir, &options(2, Shard::ALL), &mut ()).unwrap();
    assert_eq!((s.made, s.skipped, s.failed), (4, 6, 0));
    assert_same_tree(&dir, &reference);
}

#[test]
fn a_directory_of_another_dataset_or_of_something_else_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    small_room(4, VARIES)
        .generate(&dir, &Options::default(), &mut ())
        .unwrap();
    let before = tree(&dir);
    let other_scenario = SMALL_ROOM.replace("duration_s = 1.0", "duration_s = 0.9");
    for (dataset, fragment) in [
        (small_room(5, VARIES), "it was made with --runs 4, not 5"),
        (
            small_room(4, &VARIES[..1]),
            "not --vary robot.start.x=-0.5..0.5;",
        ),
        (
            hilsim_dataset::Dataset::from_toml(SMALL_ROOM, Path::new("s"), Some(6), 4, vec![])
                .unwrap(),
            "made with --seed 5, not 6",
        ),
        (
            hilsim_dataset::Dataset::from_toml(
                &other_scenario,
                Path::new("s"),
                None,
                4,
                VARIES.iter().map(|v| v.parse().unwrap()).collect(),
            )
            .unwrap(),
            "made from another scenario file",
        ),
    ] {
        let err = dataset
            .generate(&dir, &Options::default(), &mut ())
            .unwrap_err();
        assert!(matches!(err, Error::Mismatch { .. }), "{err:?}");
        let text = err.to_string();
        assert!(
            text.contains("d/dataset.toml: this directory holds another dataset"),
            "{text}"
        );
        assert!(text.contains(fragment), "{text}");
    }
    assert_eq!(tree(&dir), before, "nothing touched");

    let busy = tmp.path().join("busy");
    fs::create_dir(&busy).unwrap();
    fs::write(busy.join("notes.txt"), "mine").unwrap();
    let err = small_room(2, &[])
        .generate(&busy, &Options::default(), &mut ())
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("is not a dataset (no dataset.toml)"),
        "{err}"
    );
    assert_eq!(fs::read_dir(&busy).unwrap().count(), 1);
}

#[test]
fn a_run_damaged_by_hand_is_named_not_silently_replaced() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    let d = small_room(3, &[]);
    d.generate(&dir, &Options::default(), &mut ()).unwrap();
    // No manifest vouches for the run (one that does is made again).
    fs::remove_file(dir.join("manifest.csv")).unwrap();
    fs::remove_file(dir.join("run-000001/meta.toml")).unwrap();
    let err = d.generate(&dir, &Options::default(), &mut ()).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("run-000001: not a complete run (no meta.toml)"),
        "{text}"
    );
}

#[test]
fn failing_runs_are_recorded_with_their_reason_and_the_others_go_on() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    let d = small_room(16, &[FAILING_VARY]);
    let s = d.generate(&dir, &Options::default(), &mut ()).unwrap();
    let rows = manifest_rows(&dir.join("manifest.csv"));
    assert_eq!(rows.len(), 16);
    let failed: Vec<_> = rows.iter().filter(|r| r["status"] == "failed").collect();
    assert!(
        !failed.is_empty() && failed.len() < 16,
        "{} failed",
        failed.len()
    );
    assert_eq!(s.failed as usize, failed.len());
    assert_eq!(s.made as usize, 16 - failed.len());
    for row in &rows {
        let x: f64 = row["robot.start.x"].parse().unwrap();
        let run = &row["run"];
        let exists = dir
            .join(format!("run-{:06}", run.parse::<u64>().unwrap()))
            .exists();
        if x > 0.715 {
            assert_eq!(row["status"], "failed", "run {run} at x = {x}");
            assert_eq!(
                row["reason"],
                "robot.start: the robot (radius 0.165 m) starts inside or touching cylinder 0"
            );
            assert!(row["sha256"].is_empty() && !exists);
        } else {
            assert_eq!(row["status"], "ok", "run {run} at x = {x}");
            assert!(row["reason"].is_empty() && exists);
        }
    }
    // Failures are tried again on a rerun (they fail the same way); made runs are skipped.
    let before = fs::read(dir.join("manifest.csv")).unwrap();
    let again = d.generate(&dir, &Options::default(), &mut ()).unwrap();
    assert_eq!(
        (again.made, again.skipped, again.failed),
        (0, s.made, s.failed)
    );
    assert_eq!(fs::read(dir.join("manifest.csv")).unwrap(), before);
}

#[test]
fn one_run_alone_equals_the_same_run_in_the_dataset() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(6, VARIES);
    let full = tmp.path().join("full");
    d.generate(&full, &Options::default(), &mut ()).unwrap();

    // `--run 4` into a fresh directory.
    let alone = tmp.path().join("alone");
    let only = Options {
        only: Some(4),
        ..Options::default()
    };
    let s = d.generate(&alone, &only, &mut ()).unwrap();
    assert_eq!((s.share, s.made), (1, 1));
    assert_same_tree(&alone.join("run-000004"), &full.join("run-000004"));
    let rows = manifest_rows(&alone.join("manifest.csv"));
    let full_rows = manifest_rows(&full.join("manifest.csv"));
    assert_eq!(rows, [full_rows[4].clone()]);

    // What `hilsim record run-000004/scenario.toml` does: the same recording, byte for byte.
    let scenario = Scenario::load(&full.join("run-000004/scenario.toml")).unwrap();
    let recording = Emulation::new(&scenario, scenario.seed)
        .unwrap()
        .run()
        .recording;
    let again = tmp.path().join("again");
    recording.write_dir(&again).unwrap();
    for (name, bytes) in tree(&again) {
        assert_eq!(
            fs::read(full.join("run-000004").join(&name)).unwrap(),
            bytes,
            "{}",
            name.display()
        );
    }

    // A run outside the dataset or the shard is refused.
    let err = d
        .generate(
            &alone,
            &Options {
                only: Some(6),
                ..Options::default()
            },
            &mut (),
        )
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("--run 6: the dataset's runs are 0 to 5"),
        "{err}"
    );
    let shard = Options {
        only: Some(1),
        shard: "1/2".parse().unwrap(),
        ..Options::default()
    };
    let err = d.generate(&alone, &shard, &mut ()).unwrap_err();
    assert!(
        err.to_string().contains("--run 1 is not in shard 1/2"),
        "{err}"
    );
}
