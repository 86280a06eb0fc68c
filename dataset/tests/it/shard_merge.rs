//! K machines must be able to split a dataset with `--shard I/K` and no coordination,
//! and merging their directories (or their shared directory in place) must give the unsharded
//! dataset byte for byte; a merge of different datasets, or of a run changed after it was made,
//! must be refused.

use std::fs;

use super::common::*;
use hilsim_dataset::{merge, Error, Options, Shard};

const VARIES: &[&str] = &[
    "robot.start.x=-0.5..0.5",
    "sensors.sonar.half_angle_deg=5..25",
];

#[test]
fn shards_in_their_own_directories_merge_into_the_unsharded_dataset() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(11, VARIES);
    let whole = tmp.path().join("whole");
    d.generate(&whole, &Options::default(), &mut ()).unwrap();

    let mut dirs = Vec::new();
    for i in 1..=3 {
        let dir = tmp.path().join(format!("shard-{i}"));
        let shard = Shard::new(i, 3).unwrap();
        let s = d.generate(&dir, &options(1, shard), &mut ()).unwrap();
        assert_eq!(s.share, (0..11).filter(|r| r % 3 == i - 1).count() as u64);
        assert!(dir.join(format!("manifest-shard-{i}-of-3.csv")).is_file());
        dirs.push(dir);
    }
    let merged = tmp.path().join("merged");
    let s = merge(&merged, &dirs, None).unwrap();
    assert_eq!(
        (s.runs, s.made, s.failed, s.missing, s.copied),
        (11, 11, 0, 0, 11)
    );
    assert_same_tree(&merged, &whole);
    // Merging again changes nothing.
    let s = merge(&merged, &dirs, None).unwrap();
    assert_eq!(s.copied, 0);
    assert_same_tree(&merged, &whole);
}

#[test]
fn shards_sharing_one_directory_merge_in_place() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(9, &[FAILING_VARY]);
    let whole = tmp.path().join("whole");
    let s = d.generate(&whole, &Options::default(), &mut ()).unwrap();
    assert!(s.failed > 0, "the fixture has failing runs");

    let shared = tmp.path().join("shared");
    for i in [2, 1] {
        d.generate(&shared, &options(2, Shard::new(i, 2).unwrap()), &mut ())
            .unwrap();
    }
    assert!(shared.join("manifest-shard-1-of-2.csv").is_file());
    assert!(shared.join("manifest-shard-2-of-2.csv").is_file());
    let m = merge(&shared, &[], None).unwrap();
    assert_eq!((m.made, m.failed, m.missing), (s.made, s.failed, 0));
    assert_same_tree(&shared, &whole);
}

#[test]
fn a_merge_before_every_shard_finished_counts_the_missing_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let d = small_room(6, &[]);
    let first = tmp.path().join("first");
    d.generate(&first, &options(1, Shard::new(1, 2).unwrap()), &mut ())
        .unwrap();
    let merged = tmp.path().join("merged");
    let s = merge(&merged, &[first], None).unwrap();
    assert_eq!((s.made, s.failed, s.missing), (3, 0, 3));
    assert_eq!(manifest_rows(&merged.join("manifest.csv")).len(), 3);
}

#[test]
fn different_datasets_or_changed_runs_are_not_merged() {
    let tmp = tempfile::tempdir().unwrap();
    let a = tmp.path().join("a");
    let b = tmp.path().join("b");
    small_room(4, VARIES)
        .generate(&a, &options(1, Shard::new(1, 2).unwrap()), &mut ())
        .unwrap();
    small_room(4, &VARIES[..1])
        .generate(&b, &options(1, Shard::new(2, 2).unwrap()), &mut ())
        .unwrap();
    let err = merge(&tmp.path().join("m"), &[a.clone(), b.clone()], None).unwrap_err();
    assert!(matches!(err, Error::Mismatch { .. }), "{err:?}");
    let text = err.to_string();
    assert!(
        text.contains("b/dataset.toml: another dataset than"),
        "{text}"
    );

    // A run whose files changed after its shard recorded its hash.
    let c = tmp.path().join("c");
    small_room(4, VARIES)
        .generate(&c, &options(1, Shard::new(2, 2).unwrap()), &mut ())
        .unwrap();
    let lidar = c.join("run-000001/lidar.csv");
    let mut bytes = fs::read(&lidar).unwrap();
    let last = bytes.len() - 2;
    bytes[last] = if bytes[last] == b'1' { b'2' } else { b'1' };
    fs::write(&lidar, bytes).unwrap();
    let err = merge(&tmp.path().join("m2"), &[a, c], None).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("manifest-shard-2-of-2.csv: run 1 has content hash"),
        "{text}"
    );
    assert!(
        text.contains("the run's files changed after it was made"),
        "{text}"
    );

    let err = merge(&tmp.path().join("nothing"), &[], None).unwrap_err();
    assert!(err.to_string().contains("not a dataset"), "{err}");
}
