//! Dataset integrity. Resuming must not re-bless a run whose files no longer
//! match the content hash its manifest recorded (it is made again, to the same hash); merging
//! must refuse such a run without ever bringing it into the target, however often it is asked;
//! shards started at the same instant on a fresh directory (a Slurm job array) must all succeed.

use std::fs;
use std::path::Path;
use std::sync::{Arc, Barrier};

use super::common::*;
use hilsim_dataset::{merge, Error, Options, Plan, Progress, Shard};

const VARIES: &[&str] = &[
    "robot.start.x=-0.5..0.5",
    "sensors.lidar.angle_noise_deg=0..2",
];

/// Keeps the last plan.
#[derive(Default)]
struct Planned(Option<Plan>);

impl Progress for Planned {
    fn planned(&mut self, plan: &Plan) {
        self.0 = Some(plan.clone());
    }
}

/// Cuts `file` to its first half of lines: still a well-formed table, with another hash.
fn truncate_lines(file: &Path) {
    let text = fs::read_to_string(file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(
        lines.len() > 4,
        "{} is too short to truncate",
        file.display()
    );
    let kept: String = lines[..lines.len() / 2]
        .iter()
        .map(|l| format!("{l}\n"))
        .collect();
    fs::write(file, kept).unwrap();
}

/// Run `r`'s `sha256` in the manifest at `path`.
fn recorded_sha(path: &Path, r: u64) -> String {
    manifest_rows(path)
        .into_iter()
        .find(|row| row["run"] == r.to_string())
        .map(|row| row["sha256"].clone())
        .unwrap()
}

#[test]
fn a_truncated_run_is_remade_on_resume_to_its_original_hash() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(6, VARIES);
    let dir = tmp.path().join("d");
    d.generate(&dir, &Options::default(), &mut ()).unwrap();
    let before = tree(&dir);
    let original = recorded_sha(&dir.join("manifest.csv"), 2);

    // Damage three runs the manifest vouches for: a table cut at a line boundary (it still
    // scans, to another hash: what used to be re-blessed), a table cut to nothing, and a
    // missing meta.toml (neither scans as a run).
    truncate_lines(&dir.join("run-000002/lidar.csv"));
    fs::write(dir.join("run-000004/odometry.csv"), "").unwrap();
    fs::remove_file(dir.join("run-000005/meta.toml")).unwrap();

    // `--run` of another run refuses (naming the damaged one) and changes nothing.
    let only = Options {
        only: Some(3),
        ..Options::default()
    };
    let err = d.generate(&dir, &only, &mut ()).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("run-000002: its files differ from the content hash its manifest recorded"),
        "{text}"
    );
    assert_eq!(
        fs::read(dir.join("manifest.csv")).unwrap(),
        before[Path::new("manifest.csv")]
    );

    let mut planned = Planned::default();
    let s = d
        .generate(&dir, &options(2, Shard::ALL), &mut planned)
        .unwrap();
    assert_eq!((s.made, s.skipped, s.failed), (3, 3, 0));
    let plan = planned.0.unwrap();
    assert_eq!((plan.to_make, plan.remade), (3, 3));
    assert_eq!(recorded_sha(&dir.join("manifest.csv"), 2), original);
    assert_eq!(
        tree(&dir),
        before,
        "the dataset is whole again, byte for byte"
    );

    // The same in a shard's directory, vouched for by the shard's manifest; and `--run` of
    // the damaged run itself makes it again.
    let shard = Shard::new(2, 2).unwrap();
    let sdir = tmp.path().join("s");
    d.generate(&sdir, &options(1, shard), &mut ()).unwrap();
    let sbefore = tree(&sdir);
    truncate_lines(&sdir.join("run-000003/sonar.csv"));
    let s = d
        .generate(
            &sdir,
            &Options {
                only: Some(3),
                ..options(1, shard)
            },
            &mut (),
        )
        .unwrap();
    assert_eq!(s.made, 1);
    assert_eq!(tree(&sdir), sbefore);
}

#[test]
fn a_run_no_manifest_vouches_for_is_still_trusted_or_named() {
    // Runs made after the last manifest write of an interrupted call are trusted (they were
    // renamed into place whole); one that does not even scan as a run is named, not replaced.
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(3, &[]);
    let dir = tmp.path().join("d");
    d.generate(&dir, &Options::default(), &mut ()).unwrap();
    let before = tree(&dir);
    fs::remove_file(dir.join("manifest.csv")).unwrap();
    let s = d.generate(&dir, &Options::default(), &mut ()).unwrap();
    assert_eq!((s.made, s.skipped), (0, 3));
    assert_eq!(tree(&dir), before);

    fs::remove_file(dir.join("manifest.csv")).unwrap();
    fs::remove_file(dir.join("run-000001/meta.toml")).unwrap();
    let err = d.generate(&dir, &Options::default(), &mut ()).unwrap_err();
    assert!(
        err.to_string()
            .contains("run-000001: not a complete run (no meta.toml)"),
        "{err}"
    );
}

#[test]
fn merge_refuses_a_corrupt_shard_run_and_never_brings_it_in() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(7, VARIES);
    let whole = tmp.path().join("whole");
    d.generate(&whole, &Options::default(), &mut ()).unwrap();
    let mut dirs = Vec::new();
    for i in 1..=3 {
        let dir = tmp.path().join(format!("shard-{i}"));
        d.generate(&dir, &options(1, Shard::new(i, 3).unwrap()), &mut ())
            .unwrap();
        dirs.push(dir);
    }
    // Run 4 is shard 2's: cut, it still scans, to another hash.
    truncate_lines(&dirs[1].join("run-000004/lidar.csv"));

    let merged = tmp.path().join("merged");
    for attempt in 0..2 {
        let err = merge(&merged, &dirs, None).unwrap_err();
        assert!(matches!(err, Error::Mismatch { .. }), "{err:?}");
        let text = err.to_string();
        assert!(
            text.contains("manifest-shard-2-of-3.csv: run 4 has content hash")
                && text.contains("the run's files changed after it was made; nothing was merged"),
            "attempt {attempt}: {text}"
        );
        assert!(
            !merged.join("run-000004").exists(),
            "attempt {attempt}: the refused run is not in the target"
        );
    }
    // Nothing was written at all, so there is no target to merge in place either.
    assert!(!merged.exists());

    // A target that already holds the other shards: still refused, still without run 4.
    let partial = merge(&merged, &[dirs[0].clone(), dirs[2].clone()], None).unwrap();
    assert_eq!((partial.made, partial.missing), (5, 2));
    for _ in 0..2 {
        assert!(merge(&merged, &dirs, None).is_err());
        assert!(!merged.join("run-000004").exists());
        let again = merge(&merged, &[], None).unwrap();
        assert_eq!((again.made, again.missing), (5, 2));
    }

    // Resuming shard 2 makes run 4 again; then the merge is the unsharded dataset.
    let s = d
        .generate(&dirs[1], &options(1, Shard::new(2, 3).unwrap()), &mut ())
        .unwrap();
    assert_eq!(s.made, 1);
    let m = merge(&merged, &dirs, None).unwrap();
    assert_eq!((m.made, m.missing), (7, 0));
    assert_same_tree(&merged, &whole);
}

#[test]
fn merge_in_place_refuses_a_corrupt_run_every_time_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(6, &[]);
    let shared = tmp.path().join("shared");
    for i in 1..=2 {
        d.generate(&shared, &options(1, Shard::new(i, 2).unwrap()), &mut ())
            .unwrap();
    }
    truncate_lines(&shared.join("run-000003/truth.csv"));
    let before = tree(&shared);
    for _ in 0..2 {
        let err = merge(&shared, &[], None).unwrap_err();
        assert!(
            err.to_string()
                .contains("manifest-shard-2-of-2.csv: run 3 has content hash"),
            "{err}"
        );
        assert_eq!(tree(&shared), before, "nothing written");
    }
}

#[test]
fn shards_started_at_once_on_a_fresh_directory_all_succeed() {
    const K: u64 = 4;
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(9, VARIES);
    let whole = tmp.path().join("whole");
    d.generate(&whole, &Options::default(), &mut ()).unwrap();
    // Several rounds, each on a fresh directory, the K shards released together by a barrier.
    for round in 0..5 {
        let shared = tmp.path().join(format!("shared-{round}"));
        let barrier = Arc::new(Barrier::new(K as usize));
        let results: Vec<_> = std::thread::scope(|scope| {
            let handles: Vec<_> = (1..=K)
                .map(|i| {
                    let (barrier, d, shared) = (Arc::clone(&barrier), &d, &shared);
                    scope.spawn(move || {
                        barrier.wait();
                        d.generate(shared, &options(1, Shard::new(i, K).unwrap()), &mut ())
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for (i, r) in results.into_iter().enumerate() {
            let s = r.unwrap_or_else(|err| panic!("round {round}, shard {}: {err}", i + 1));
            assert_eq!(s.failed, 0);
        }
        let m = merge(&shared, &[], None).unwrap();
        assert_eq!((m.made, m.missing), (9, 0));
        assert_same_tree(&shared, &whole);
    }
}

#[test]
fn another_writers_dataset_toml_in_progress_is_left_alone() {
    // What a shard started a moment earlier leaves while it creates dataset.toml: its
    // temporary. The old code removed it (and that shard then failed: `dataset.toml: No such
    // file or directory`); now it is another writer's, left alone until the merge.
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(4, &[]);
    let shared = tmp.path().join("shared");
    fs::create_dir(&shared).unwrap();
    let theirs = shared.join(".dataset.toml.tmp.4242");
    fs::write(&theirs, "# A hilsim dataset").unwrap();
    d.generate(&shared, &options(1, Shard::new(1, 2).unwrap()), &mut ())
        .unwrap();
    assert!(theirs.exists());
    d.generate(&shared, &options(1, Shard::new(2, 2).unwrap()), &mut ())
        .unwrap();
    assert!(theirs.exists());
    merge(&shared, &[], None).unwrap();
    assert!(!theirs.exists(), "the merge removes leftovers");
    let whole = tmp.path().join("whole");
    d.generate(&whole, &Options::default(), &mut ()).unwrap();
    assert_same_tree(&shared, &whole);
}
