//! Fixtures shared by the dataset tests: a small, fast scenario and whole-directory comparison.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use hilsim_dataset::{Dataset, Options, Shard, Vary};

/// A 4 m square room with one cylinder 1 m ahead of the robot; one second of lidar, sonar and
/// odometer while the robot creeps 0.1 m forward. Fast in the dev profile (~10 ms a run).
pub const SMALL_ROOM: &str = r#"
name = "small-room"
seed = 5
duration_s = 1.0
[world]
walls = [
    { from = [-2.0, -2.0], to = [2.0, -2.0] },
    { from = [2.0, -2.0], to = [2.0, 2.0] },
    { from = [2.0, 2.0], to = [-2.0, 2.0] },
    { from = [-2.0, 2.0], to = [-2.0, -2.0] },
]
cylinders = [{ center = [1.0, 0.0], radius = 0.12 }]
[robot]
start = { x = 0.0, y = 0.0 }
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
"#;

/// The robot's disc (radius 0.165 m) touches the cylinder (radius 0.12 m at x = 1) when
/// `robot.start.x` > 1 − 0.285 = 0.715: about a quarter of the runs of this range fail.
pub const FAILING_VARY: &str = "robot.start.x=-0.5..1.2";

/// The small room with the given `--vary`s, `runs` runs, the scenario's seed.
pub fn small_room(runs: u64, varies: &[&str]) -> Dataset {
    let varies: Vec<Vary> = varies.iter().map(|v| v.parse().unwrap()).collect();
    Dataset::from_toml(SMALL_ROOM, Path::new("small-room.toml"), None, runs, varies).unwrap()
}

/// Options for `jobs` threads and a shard.
pub fn options(jobs: usize, shard: Shard) -> Options {
    Options {
        jobs: std::num::NonZeroUsize::new(jobs),
        shard,
        only: None,
    }
}

/// Every file under `dir`, by path relative to it, with its bytes (hidden entries included).
pub fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            walk(root, &path, out);
            // Empty directories count too.
            out.entry(path.strip_prefix(root).unwrap().to_path_buf())
                .or_default();
        } else {
            out.insert(
                path.strip_prefix(root).unwrap().to_path_buf(),
                std::fs::read(&path).unwrap(),
            );
        }
    }
}

/// Asserts two directory trees are identical, naming the first difference.
pub fn assert_same_tree(a: &Path, b: &Path) {
    let (ta, tb) = (tree(a), tree(b));
    let names = |t: &BTreeMap<PathBuf, Vec<u8>>| t.keys().cloned().collect::<Vec<_>>();
    assert_eq!(names(&ta), names(&tb), "{} vs {}", a.display(), b.display());
    for (name, bytes) in &ta {
        assert!(
            tb[name] == *bytes,
            "{} differs between {} and {}",
            name.display(),
            a.display(),
            b.display()
        );
    }
}

/// The manifest's rows as header → value maps.
pub fn manifest_rows(path: &Path) -> Vec<BTreeMap<String, String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|line| {
            // The tests' reasons hold no quotes; a reason with a comma is quoted and last.
            let mut fields: Vec<String> = Vec::new();
            let mut rest = line;
            while fields.len() + 1 < header.len() {
                let (f, r) = rest.split_once(',').unwrap();
                fields.push(f.to_string());
                rest = r;
            }
            fields.push(rest.trim_matches('"').to_string());
            header.iter().cloned().zip(fields).collect()
        })
        .collect()
}
