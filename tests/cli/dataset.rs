//! `hilsim dataset`: sharded, interrupted and resumed datasets equal the plain one byte for byte;
//! varied values are recorded; one run can be made again alone; failures give exit code 1, bad
//! input exit code 2 with one line.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::common::*;

/// A 4 m square room with a cylinder 1 m ahead of the robot (radius 0.12 m; the robot's disc
/// touches it when `robot.start.x` > 0.715), `duration_s` of lidar, sonar and odometer.
fn scenario(dir: &Path, duration_s: f64) -> String {
    let text = format!(
        r#"
name = "small-room"
seed = 5
duration_s = {duration_s:?}
[world]
walls = [
    {{ from = [-2.0, -2.0], to = [2.0, -2.0] }},
    {{ from = [2.0, -2.0], to = [2.0, 2.0] }},
    {{ from = [2.0, 2.0], to = [-2.0, 2.0] }},
    {{ from = [-2.0, 2.0], to = [-2.0, -2.0] }},
]
cylinders = [{{ center = [1.0, 0.0], radius = 0.12 }}]
[robot]
start = {{ x = 0.0, y = 0.0 }}
wheel_base_m = 0.23
[[drive]]
speed_mps = 0.2
distance_m = 0.1
[sensors.lidar]
noise = [0.0, 0.0, 0.004]
angle_noise_deg = 0.5
[sensors.sonar]
noise = [0.005]
[sensors.odometer]
noise_m = 0.002
"#
    );
    let path = dir.join("small-room.toml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

const VARY_X: &str = "robot.start.x=-0.5..0.5";
const VARY_NOISE: &str = "sensors.lidar.angle_noise_deg=0..2";

/// Every file under `dir` (hidden ones too) with its bytes.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let rel = path.strip_prefix(root).unwrap().to_path_buf();
            if path.is_dir() {
                out.insert(rel, Vec::new());
                walk(root, &path, out);
            } else {
                out.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn assert_same_tree(a: &Path, b: &Path) {
    let (ta, tb) = (tree(a), tree(b));
    assert_eq!(
        ta.keys().collect::<Vec<_>>(),
        tb.keys().collect::<Vec<_>>(),
        "{} vs {}",
        a.display(),
        b.display()
    );
    for (name, bytes) in &ta {
        assert!(tb[name] == *bytes, "{} differs", name.display());
    }
}

/// The manifest's rows as column → value (the tests' fields hold no commas but the reason,
/// which is last).
fn manifest(path: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|line| {
            let fields: Vec<&str> = line.splitn(header.len(), ',').collect();
            header
                .iter()
                .zip(fields)
                .map(|(h, f)| (h.to_string(), f.trim_matches('"').to_string()))
                .collect()
        })
        .collect()
}

fn run_dirs(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(Result::ok)
                .filter(|e| e.file_name().to_string_lossy().starts_with("run-"))
                .count()
        })
        .unwrap_or(0)
}

#[test]
fn sharded_halves_merged_equal_the_unsharded_dataset_byte_for_byte() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 1.0);
    let common = [
        "dataset", &s, "--runs", "7", "--vary", VARY_X, "--vary", VARY_NOISE,
    ];
    let go = |extra: &[&str]| {
        let args: Vec<&str> = common.iter().chain(extra).copied().collect();
        let out = hilsim(tmp.path(), &args);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", stderr(&out));
        stdout(&out)
    };
    let text = go(&["--out", "whole"]);
    assert!(
        text.contains("7 runs in this share: 0 made before, 7 to make"),
        "{text}"
    );
    assert!(
        text.contains("dataset whole: 7 made, 0 skipped (made before), 0 failed"),
        "{text}"
    );
    let text = go(&["--out", "half-1", "--shard", "1/2", "--jobs", "1"]);
    assert!(text.contains("4 runs in this share"), "{text}");
    go(&["--out", "half-2", "--shard", "2/2"]);
    assert_eq!(
        (
            run_dirs(&tmp.path().join("half-1")),
            run_dirs(&tmp.path().join("half-2"))
        ),
        (4, 3)
    );

    let out = hilsim(
        tmp.path(),
        &["dataset", "merge", "--out", "merged", "half-1", "half-2"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(
        stdout(&out).starts_with("merged merged: 7 runs: 7 made, 0 failed, 0 missing"),
        "{}",
        stdout(&out)
    );
    assert_same_tree(&tmp.path().join("merged"), &tmp.path().join("whole"));
}

#[test]
fn a_killed_dataset_resumes_to_the_uninterrupted_one() {
    let tmp = tempfile::tempdir().unwrap();
    // Long enough runs (~0.1 s each in the dev profile) that the kill lands mid-way.
    let s = scenario(tmp.path(), 10.0);
    let runs = "30";
    let args = |out: &str, jobs: &str| -> Vec<String> {
        [
            "dataset", &s, "--runs", runs, "--out", out, "--jobs", jobs, "--vary", VARY_X,
        ]
        .iter()
        .map(|a| a.to_string())
        .collect()
    };
    let whole = hilsim(
        tmp.path(),
        &args("whole", "2")
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert_eq!(whole.status.code(), Some(0), "{}", stderr(&whole));

    let mut child = Command::new(env!("CARGO_BIN_EXE_hilsim"))
        .args(args("killed", "1"))
        .current_dir(tmp.path())
        .env_clear()
        .env("PATH", std::env::var_os("PATH").unwrap_or_default())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let dir = tmp.path().join("killed");
    let deadline = Instant::now() + Duration::from_secs(120);
    while run_dirs(&dir) < 3 && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let made = run_dirs(&dir);
    assert!((3..30).contains(&made), "killed after {made} runs");
    // What a kill in the middle of writing a run leaves: a hidden temporary directory.
    let half = dir.join(".run-000029.tmp.4242");
    std::fs::create_dir_all(&half).unwrap();
    std::fs::write(half.join("lidar.csv"), "t_s,rev\n0.1").unwrap();

    let refs = args("killed", "2");
    let out = hilsim(
        tmp.path(),
        &refs.iter().map(String::as_str).collect::<Vec<_>>(),
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(
        text.contains(&format!("30 runs in this share: {made} made before")),
        "{text}"
    );
    assert!(!half.exists(), "the leftover is removed");
    assert_same_tree(&dir, &tmp.path().join("whole"));
}

#[test]
fn varied_values_stay_in_range_and_are_recorded() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 0.5);
    let out = hilsim(
        tmp.path(),
        &[
            "dataset", &s, "--runs", "12", "--out", "d", "--seed", "99", "--vary", VARY_X,
            "--vary", VARY_NOISE,
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let dir = tmp.path().join("d");
    let rows = manifest(&dir.join("manifest.csv"));
    assert_eq!(rows.len(), 12);
    let mut xs = Vec::new();
    for row in &rows {
        let x: f64 = row["robot.start.x"].parse().unwrap();
        let noise: f64 = row["sensors.lidar.angle_noise_deg"].parse().unwrap();
        assert!(
            (-0.5..=0.5).contains(&x) && (0.0..=2.0).contains(&noise),
            "{row:?}"
        );
        xs.push(x);
        let run: u64 = row["run"].parse().unwrap();
        let path = dir.join(format!("run-{run:06}/scenario.toml"));
        let sc = hilsim_sim::Scenario::load(&path).unwrap();
        assert_eq!(sc.robot.start.x, x, "{}", path.display());
        assert_eq!(sc.sensors.lidar.as_ref().unwrap().angle_noise_deg, noise);
        assert_eq!(sc.seed.to_string(), row["seed"]);
    }
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    assert_eq!(xs.len(), 12, "each run draws its own value");
    let toml = std::fs::read_to_string(dir.join("dataset.toml")).unwrap();
    assert!(toml.contains("seed = 99\nruns = 12\n"), "{toml}");
    assert!(
        toml.contains("key = \"robot.start.x\"\nlo = -0.5\nhi = 0.5\n"),
        "{toml}"
    );
}

#[test]
fn one_run_made_alone_equals_the_same_run_in_the_dataset() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 1.0);
    let base = ["dataset", &s, "--runs", "5", "--vary", VARY_X];
    let with = |extra: &[&'static str]| {
        let mut args: Vec<&str> = base.to_vec();
        args.extend_from_slice(extra);
        args
    };
    let out = hilsim(tmp.path(), &with(&["--out", "d"]));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let run = tmp.path().join("d/run-000003");

    // `hilsim record` of the run's own scenario.toml.
    let out = hilsim(
        tmp.path(),
        &["record", "d/run-000003/scenario.toml", "--out", "again"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let again = tree(&tmp.path().join("again"));
    assert_eq!(again.len(), 6);
    for (name, bytes) in &again {
        assert_eq!(
            &std::fs::read(run.join(name)).unwrap(),
            bytes,
            "{}",
            name.display()
        );
    }

    // `--run 3` into a directory of its own.
    let out = hilsim(tmp.path(), &with(&["--out", "alone", "--run", "3"]));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_same_tree(&tmp.path().join("alone/run-000003"), &run);
    assert_eq!(run_dirs(&tmp.path().join("alone")), 1);
}

#[test]
fn a_failing_run_is_recorded_and_the_exit_code_is_1() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 0.5);
    let out = hilsim(
        tmp.path(),
        &[
            "dataset",
            &s,
            "--runs",
            "12",
            "--out",
            "d",
            "--vary",
            "robot.start.x=-0.5..1.2",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    assert_eq!(stderr(&out), "");
    let text = stdout(&out);
    let rows = manifest(&tmp.path().join("d/manifest.csv"));
    assert_eq!(rows.len(), 12);
    let failed: Vec<_> = rows.iter().filter(|r| r["status"] == "failed").collect();
    assert!(!failed.is_empty() && failed.len() < 12, "{text}");
    for row in &failed {
        assert!(row["robot.start.x"].parse::<f64>().unwrap() > 0.715);
        assert_eq!(
            row["reason"],
            "robot.start: the robot (radius 0.165 m) starts inside or touching cylinder 0"
        );
        let name = format!("run-{:06}", row["run"].parse::<u64>().unwrap());
        assert!(
            text.contains(&format!(
                "{name} (seed {}) failed: robot.start:",
                row["seed"]
            )),
            "{text}"
        );
        assert!(!tmp.path().join("d").join(name).exists());
    }
    assert_eq!(run_dirs(&tmp.path().join("d")), 12 - failed.len());
    assert!(
        text.contains(&format!(
            "{} made, 0 skipped (made before), {} failed",
            12 - failed.len(),
            failed.len()
        )),
        "{text}"
    );
    // A merge of a dataset with failed runs also says so with exit code 1.
    let out = hilsim(tmp.path(), &["dataset", "merge", "--out", "m", "d"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
}

#[test]
fn bad_input_exits_2_with_one_line_and_makes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 0.5);
    for (extra, fragment) in [
        (
            vec!["--vary", "robot.start.x"],
            "--vary `robot.start.x`: expected KEY=LO..HI",
        ),
        (
            vec!["--vary", "robot.start.x=1..0"],
            "expected LO ≤ HI, found 1 > 0",
        ),
        (
            vec!["--vary", "robot.start.x=0..big"],
            "`big` is not a finite number",
        ),
        (
            vec!["--vary", "robot.start.z=0..1"],
            "--vary `robot.start.z=0..1`: unknown field `z`",
        ),
        (
            vec!["--vary", "sensors.sonar.half_angle_deg=0..95"],
            "at 95: sensors.sonar.half_angle_deg",
        ),
        (
            vec!["--shard", "0/2"],
            "--shard `0/2`: expected I/K with 1 ≤ I ≤ K",
        ),
        (vec!["--shard", "3/2"], "--shard `3/2`: expected I/K"),
        (vec!["--shard", "2"], "--shard `2`: expected I/K"),
        (vec!["--jobs", "0"], "--jobs 0: expected at least 1"),
        (vec!["--run", "4"], "--run 4: the dataset's runs are 0 to 3"),
        (
            vec!["--seed", "18446744073709551615"],
            "largest TOML integer",
        ),
    ] {
        let mut args = vec!["dataset", s.as_str(), "--runs", "4", "--out", "d"];
        args.extend(extra.iter().copied());
        let out = hilsim(tmp.path(), &args);
        let err = assert_bad_input(&out);
        assert!(err.contains(fragment), "{extra:?}: {err}");
        assert!(!tmp.path().join("d").exists(), "{extra:?}: nothing made");
    }
    let bad = repo_file("tests/data/bad-scenarios/negative-radius.toml");
    let out = hilsim(
        tmp.path(),
        &[
            "dataset",
            bad.to_str().unwrap(),
            "--runs",
            "2",
            "--out",
            "d",
        ],
    );
    let err = assert_bad_input(&out);
    assert!(err.contains("negative-radius.toml:9: "), "{err}");

    // Resuming with other parameters, or into a directory that is not a dataset.
    let out = hilsim(tmp.path(), &["dataset", &s, "--runs", "2", "--out", "d"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let out = hilsim(tmp.path(), &["dataset", &s, "--runs", "3", "--out", "d"]);
    let err = assert_bad_input(&out);
    assert!(err.contains("d/dataset.toml: this directory holds another dataset: it was made with --runs 2, not 3"), "{err}");
    let out = hilsim(tmp.path(), &["dataset", &s, "--runs", "2", "--out", "."]);
    let err = assert_bad_input(&out);
    assert!(err.contains("is not a dataset (no dataset.toml)"), "{err}");
    let out = hilsim(tmp.path(), &["dataset", "merge", "--out", "m", "nowhere"]);
    let err = assert_bad_input(&out);
    assert!(err.contains("nowhere"), "{err}");
}

/// Cuts `file` to its first half of lines: still a well-formed table, with another hash.
fn truncate_lines(file: &Path) {
    let text = std::fs::read_to_string(file).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines.len() > 4, "{} is too short", file.display());
    let kept: String = lines[..lines.len() / 2]
        .iter()
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(file, kept).unwrap();
}

#[test]
fn a_truncated_run_is_made_again_on_resume() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 1.0);
    let args = ["dataset", &s, "--runs", "4", "--vary", VARY_X, "--out", "d"];
    let out = hilsim(tmp.path(), &args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let dir = tmp.path().join("d");
    let before = tree(&dir);
    truncate_lines(&dir.join("run-000001/lidar.csv"));
    let out = hilsim(tmp.path(), &args);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("dataset d: 1 made, 3 skipped (made before)"),
        "{}",
        stdout(&out)
    );
    assert!(
        stdout(&out).contains("(1 of them made before but damaged since"),
        "the user is told why a run is made again: {}",
        stdout(&out)
    );
    assert_eq!(
        tree(&dir),
        before,
        "the run is made again, to its original hash"
    );
}

#[test]
fn merge_refuses_a_corrupt_shard_run_and_the_target_never_holds_it() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 1.0);
    for i in 1..=2 {
        let shard = format!("{i}/2");
        let dir = format!("shard-{i}");
        let args = [
            "dataset", &s, "--runs", "4", "--out", &dir, "--shard", &shard,
        ];
        let out = hilsim(tmp.path(), &args);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    }
    truncate_lines(&tmp.path().join("shard-2/run-000003/lidar.csv"));
    for attempt in 0..2 {
        let out = hilsim(
            tmp.path(),
            &["dataset", "merge", "--out", "merged", "shard-1", "shard-2"],
        );
        let err = assert_bad_input(&out);
        assert!(
            err.contains("manifest-shard-2-of-2.csv: run 3 has content hash"),
            "attempt {attempt}: {err}"
        );
        assert!(
            !tmp.path().join("merged/run-000003").exists(),
            "attempt {attempt}"
        );
    }
}

#[test]
fn shard_processes_started_at_once_on_a_fresh_directory_all_succeed() {
    // What a Slurm job array does: K processes, one per shard, on one fresh --out.
    const K: usize = 4;
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 1.0);
    let common = [
        "dataset", &s, "--runs", "8", "--vary", VARY_X, "--jobs", "1",
    ];
    let whole = hilsim(
        tmp.path(),
        &common
            .iter()
            .chain(&["--out", "whole"])
            .copied()
            .collect::<Vec<_>>(),
    );
    assert_eq!(whole.status.code(), Some(0), "{}", stderr(&whole));
    for round in 0..3 {
        let out = format!("shared-{round}");
        let children: Vec<_> = (1..=K)
            .map(|i| {
                Command::new(env!("CARGO_BIN_EXE_hilsim"))
                    .args(common)
                    .args(["--out", &out, "--shard", &format!("{i}/{K}")])
                    .current_dir(tmp.path())
                    .env_clear()
                    .env("PATH", std::env::var_os("PATH").unwrap_or_default())
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for (i, child) in children.into_iter().enumerate() {
            let done = child.wait_with_output().unwrap();
            assert_eq!(
                done.status.code(),
                Some(0),
                "round {round}, shard {}/{K}: {}",
                i + 1,
                stderr(&done)
            );
        }
        let merged = hilsim(tmp.path(), &["dataset", "merge", "--out", &out]);
        assert_eq!(merged.status.code(), Some(0), "{}", stderr(&merged));
        assert_same_tree(&tmp.path().join(&out), &tmp.path().join("whole"));
    }
}

#[test]
fn a_dataset_directorys_own_files_are_read_within_bounds() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 0.5);
    let make = |out: &str| hilsim(tmp.path(), &["dataset", &s, "--runs", "2", "--out", out]);
    for d in ["params-device", "params-large", "manifest-device", "src"] {
        let out = make(d);
        assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    }
    let swap = |file: &str, to: &dyn Fn(&Path)| {
        let path = tmp.path().join(file);
        std::fs::remove_file(&path).unwrap();
        to(&path);
    };
    let device = |p: &Path| std::os::unix::fs::symlink("/dev/zero", p).unwrap();
    swap("params-device/dataset.toml", &device);
    swap("params-large/dataset.toml", &|p| {
        let comment = format!("#{}\n", "x".repeat(2 << 20));
        std::fs::write(p, comment).unwrap();
    });
    swap("manifest-device/manifest.csv", &device);
    for (d, says) in [
        (
            "params-device",
            "params-device/dataset.toml: not a regular file but a character device",
        ),
        (
            "params-large",
            "params-large/dataset.toml: larger than 1 MiB; not a dataset.toml",
        ),
        (
            "manifest-device",
            "manifest-device/manifest.csv: not a regular file but a character device",
        ),
    ] {
        let err = assert_bad_input(&make(d));
        assert!(err.contains(says), "{d}: {err}");
    }
    // A merge source's dataset.toml likewise: named, not called missing.
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["dataset", "merge", "--out", "m", "src", "params-device"],
    ));
    assert!(
        err.contains("params-device/dataset.toml: not a regular file"),
        "{err}"
    );
}

#[test]
fn an_os_error_is_said_once() {
    let tmp = tempfile::tempdir().unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["dataset", "merge", "--out", "m", "nowhere"],
    ));
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
}

#[test]
fn a_range_with_three_dots_is_refused_not_read_as_a_fraction() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 0.5);
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &[
            "dataset",
            &s,
            "--runs",
            "2",
            "--out",
            "d",
            "--vary",
            "robot.start.y=1...2",
        ],
    ));
    assert!(
        err.contains("more than two dots between the bounds"),
        "{err}"
    );
    assert!(!err.contains("0.2"), "{err}");
}

#[test]
fn a_second_writer_of_the_same_runs_is_refused_and_the_first_completes() {
    let tmp = tempfile::tempdir().unwrap();
    let s = scenario(tmp.path(), 1.0);
    let args = ["dataset", &s, "--runs", "16", "--jobs", "1", "--out", "d"];
    let first = Command::new(env!("CARGO_BIN_EXE_hilsim"))
        .args(args)
        .current_dir(tmp.path())
        .env_clear()
        .env("PATH", std::env::var_os("PATH").unwrap_or_default())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Until the first holds the lock (its file appears once dataset.toml exists).
    let lock = tmp.path().join("d/.manifest.csv.lock");
    let start = Instant::now();
    while !lock.exists() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(5));
    }
    let second = hilsim(tmp.path(), &args);
    let first = first.wait_with_output().unwrap();
    assert_eq!(first.status.code(), Some(0), "{}", stderr(&first));
    // The second either found the first at work, or (on a slow machine) started after it ended.
    if second.status.code() != Some(0) {
        let err = assert_bad_input(&second);
        assert!(err.contains("another hilsim (pid "), "{err}");
        assert!(
            err.contains("is writing this dataset's manifest.csv"),
            "{err}"
        );
    }
    assert_eq!(run_dirs(&tmp.path().join("d")), 16);
    assert!(!lock.exists(), "the lock file goes with its holder");
}
