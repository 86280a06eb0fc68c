//! The manifest must say, for every run, its seed, its varied values, what its
//! recording holds and a content hash anyone can recompute from the files with standard tools.

use std::fs;
use std::process::Command;

use super::common::*;
use hilsim_dataset::{scan_run, Options};
use hilsim_recording::Recording;
use sha2::{Digest, Sha256};

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn each_row_matches_its_run_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    let d = small_room(5, &["robot.start.y=-0.3..0.3"]);
    d.generate(&dir, &Options::default(), &mut ()).unwrap();
    let text = fs::read_to_string(dir.join("manifest.csv")).unwrap();
    assert!(text.starts_with(
        "run,seed,robot.start.y,status,recorded_s,lidar_samples,sonar_samples,odometry_samples,\
         sha256,reason\n"
    ));
    let rows = manifest_rows(&dir.join("manifest.csv"));
    assert_eq!(rows.len(), 5);
    for (r, row) in rows.iter().enumerate() {
        let r = r as u64;
        let run = dir.join(format!("run-{r:06}"));
        assert_eq!(row["run"], r.to_string());
        assert_eq!(row["seed"], d.run_seed(r).to_string());
        assert_eq!(row["robot.start.y"], d.values(r)[0].to_string());
        assert_eq!(row["status"], "ok");

        let rec = Recording::read_dir(&run).unwrap();
        assert_eq!(row["recorded_s"], rec.duration_s().to_string());
        let count = |t: Option<usize>| t.map(|n| n.to_string()).unwrap_or_default();
        assert_eq!(
            row["lidar_samples"],
            count(rec.lidar.as_ref().map(Vec::len))
        );
        assert_eq!(
            row["sonar_samples"],
            count(rec.sonar.as_ref().map(Vec::len))
        );
        assert_eq!(
            row["odometry_samples"],
            count(rec.odometry.as_ref().map(Vec::len))
        );
        assert_eq!(rec.meta.source.as_ref().unwrap().seed, Some(d.run_seed(r)));

        // The documented hash: SHA-256 of the `sha256sum` listing of the files in name order.
        let mut names: Vec<String> = fs::read_dir(&run)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        assert_eq!(
            names,
            [
                "commands.csv",
                "lidar.csv",
                "meta.toml",
                "odometry.csv",
                "scenario.toml",
                "sonar.csv",
                "truth.csv"
            ]
        );
        let listing: String = names
            .iter()
            .map(|n| {
                format!(
                    "{}  {n}\n",
                    hex(&Sha256::digest(fs::read(run.join(n)).unwrap()))
                )
            })
            .collect();
        assert_eq!(row["sha256"], hex(&Sha256::digest(listing.as_bytes())));
        assert_eq!(row["sha256"], scan_run(&run).unwrap().sha256);
    }
}

#[test]
fn the_hash_is_what_the_shell_computes() {
    // `cd run && LC_ALL=C sha256sum * | sha256sum`, where the tools exist.
    let Ok(probe) = Command::new("sh")
        .args(["-c", "command -v sha256sum"])
        .output()
    else {
        return;
    };
    if !probe.status.success() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    small_room(1, &[])
        .generate(&dir, &Options::default(), &mut ())
        .unwrap();
    let out = Command::new("sh")
        .args(["-c", "LC_ALL=C sha256sum * | sha256sum"])
        .current_dir(dir.join("run-000000"))
        .output()
        .unwrap();
    let shell = String::from_utf8(out.stdout).unwrap();
    let rows = manifest_rows(&dir.join("manifest.csv"));
    assert_eq!(shell.split_whitespace().next().unwrap(), rows[0]["sha256"]);
}

#[test]
fn a_sensor_the_robot_lacks_has_an_empty_cell() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    let no_sonar = SMALL_ROOM.replace("[sensors.sonar]\nnoise = [0.005]\n", "");
    assert_ne!(no_sonar, SMALL_ROOM);
    hilsim_dataset::Dataset::from_toml(&no_sonar, "s.toml".as_ref(), None, 1, vec![])
        .unwrap()
        .generate(&dir, &Options::default(), &mut ())
        .unwrap();
    let rows = manifest_rows(&dir.join("manifest.csv"));
    assert_eq!(rows[0]["sonar_samples"], "");
    assert_eq!(
        rows[0]["lidar_samples"], "1800",
        "one second at 1,800 readings/s"
    );
}
