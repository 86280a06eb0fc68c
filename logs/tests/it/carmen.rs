//! The CARMEN reader on small logs written here: what it reads, what it skips and what it says.

use hilsim_logs::{read_carmen, CarmenOptions, LogError, Poses};
use hilsim_recording::Pose;

/// A FLASER line of 180 beams, beam i at `first + i / 100` metres, the robot at `pose`.
fn flaser(first: f64, pose: [f64; 3], t: f64) -> String {
    let ranges: Vec<String> = (0..180)
        .map(|i| format!("{}", first + f64::from(i) / 100.0))
        .collect();
    let [x, y, th] = pose;
    format!(
        "FLASER 180 {} {x} {y} {th} {x} {y} {th} {t} host {t}",
        ranges.join(" ")
    )
}

fn odom(x: f64, y: f64, th: f64, t: f64) -> String {
    format!("ODOM {x} {y} {th} 0.1 0 0 {t} host {t}")
}

/// Scans at 1, 2, 0.7 (back in time, before both), 3 s; a malformed FLASER at line 6; ODOM
/// lines at 0.5, 1.5, 1.2 (before the last one, after the one before it), 3.5 s; a comment, a
/// PARAM, an unknown kind.
fn log() -> String {
    [
        "# CARMEN Logfile".to_string(),
        "PARAM robot_frontlaser_offset 0.1 host 0".to_string(),
        odom(0.0, 0.0, 0.0, 0.5),
        flaser(1.0, [1.0, 2.0, 0.5], 1.0),
        odom(0.1, 0.0, 0.0, 1.5),
        "FLASER 180 1 2 3".to_string(),
        flaser(2.0, [1.1, 2.0, 0.5], 2.0),
        odom(0.2, 0.0, 0.0, 1.2),
        flaser(9.0, [9.0, 9.0, 0.0], 0.7),
        "NEFF 15".to_string(),
        String::new(),
        flaser(3.0, [1.2, 2.1, 0.6], 3.0),
        odom(0.3, 0.0, 0.0, 3.5),
    ]
    .join("\n")
}

#[test]
fn scans_and_poses_are_read_and_bad_lines_skipped() {
    let (rec, notes) = read_carmen(&log(), "test.log", &CarmenOptions::default()).unwrap();
    let lidar = rec.lidar.as_ref().unwrap();
    assert_eq!(lidar.len(), 3 * 180, "three good scans of 180 beams");
    assert_eq!(lidar.last().unwrap().rev, 2);
    // Time 0 is the first line read (the ODOM at 0.5 s).
    assert_eq!(lidar[0].t_s, 0.5);
    assert_eq!(lidar[0].range_m, 1.0);
    assert_eq!(lidar[179].t_s, 0.5, "all beams at the line's time");
    assert!((lidar[179].range_m - 2.79).abs() < 1e-12);
    assert_eq!(lidar[180].range_m, 2.0, "the second scan is the one at 2 s");
    assert_eq!(lidar[360].t_s, 2.5);
    assert_eq!(lidar[360].range_m, 3.0, "the scan back in time is skipped");
    // First beam at -90°, the last a degree short of +90°.
    assert_eq!(lidar[0].angle_deg, 270.0);
    assert_eq!(lidar[179].angle_deg, 89.0);
    let truth = rec.truth.as_ref().unwrap();
    assert_eq!(truth.len(), 3);
    assert_eq!((truth[0].t_s, truth[0].x_m, truth[0].y_m), (0.5, 1.0, 2.0));
    assert_eq!((truth[2].t_s, truth[2].x_m), (2.5, 1.2));
    // The heading goes through wrap_angle: a rounding.
    assert!((truth[2].yaw_rad - 0.6).abs() < 1e-12);
    let odometry = rec.odometry.as_ref().unwrap();
    assert_eq!(
        odometry.len(),
        3,
        "one of the ODOM lines out of order is skipped"
    );
    assert_eq!(odometry[0].t_s, 0.0);
    assert!(
        (odometry[1].t_s - 0.7).abs() < 1e-12,
        "the later-stamped of the two goes: a stamp far ahead costs one line"
    );
    assert_eq!(odometry[2].t_s, 3.0);
    assert_eq!(
        rec.meta.lidar.unwrap().x_m,
        0.1,
        "PARAM robot_frontlaser_offset"
    );

    assert_eq!(notes.len(), 4, "{notes:#?}");
    assert!(
        notes[0].contains("1 scan line(s) out of time order")
            && notes[0].contains("1.300 s back; the first at line 9)"),
        "{}",
        notes[0]
    );
    assert!(
        notes[1].contains("1 ODOM line(s) out of time order")
            && notes[1].contains("0.300 s back; the first at line 5)"),
        "{}",
        notes[1]
    );
    assert!(
        notes[2].contains("1 line(s) of a known kind could not be read")
            && notes[2].contains("the first at line 6: FLASER"),
        "{}",
        notes[2]
    );
    assert!(
        notes[3].contains("NEFF ×1 (first at line 10)"),
        "{}",
        notes[3]
    );
}

#[test]
fn a_scan_stamped_far_ahead_costs_only_itself() {
    let text = [
        flaser(1.0, [0.0; 3], 10.0),
        flaser(2.0, [0.0; 3], 1e9),
        flaser(3.0, [0.0; 3], 10.1),
        flaser(4.0, [0.0; 3], 10.2),
    ]
    .join("\n");
    let (rec, notes) = read_carmen(&text, "ahead.log", &CarmenOptions::default()).unwrap();
    let lidar = rec.lidar.unwrap();
    assert_eq!(lidar.len(), 3 * 180);
    let firsts: Vec<(u64, f64)> = lidar
        .iter()
        .step_by(180)
        .map(|s| (s.rev, s.range_m))
        .collect();
    assert_eq!(firsts, [(0, 1.0), (1, 3.0), (2, 4.0)]);
    assert!((lidar[539].t_s - 0.2).abs() < 1e-9);
    assert_eq!(rec.truth.unwrap().len(), 3);
    assert_eq!(notes.len(), 2, "{notes:?}");
    assert!(
        notes[1].contains("does not give the laser's mount"),
        "{}",
        notes[1]
    );
    assert!(
        notes[0].contains("1 scan line(s)") && notes[0].contains("the first at line 2)"),
        "{}",
        notes[0]
    );
}

#[test]
fn a_first_odom_stamped_far_ahead_costs_only_itself() {
    let text = [
        odom(0.0, 0.0, 0.0, 1e9),
        odom(0.1, 0.0, 0.0, 5.0),
        odom(0.2, 0.0, 0.0, 6.0),
    ]
    .join("\n");
    let (rec, notes) = read_carmen(&text, "ahead.log", &CarmenOptions::default()).unwrap();
    let odometry = rec.odometry.unwrap();
    assert_eq!(odometry.len(), 2);
    assert_eq!((odometry[0].t_s, odometry[1].t_s), (0.0, 1.0));
    assert!((odometry[1].left_m - 0.1).abs() < 1e-12);
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].contains("the first at line 1)"), "{}", notes[0]);
}

#[test]
fn odometry_poses_become_wheel_travel_that_dead_reckons_back() {
    let options = CarmenOptions {
        poses: Poses::Odometry,
        wheel_base_m: 0.4,
        ..CarmenOptions::default()
    };
    // An arc and a turn on the spot, from a pose not at the origin.
    let poses = [
        Pose::new(1.0, 1.0, 0.3),
        Pose::new(1.0, 1.0, 0.3).drive(0.2, 0.3, 0.4),
        Pose::new(1.0, 1.0, 0.3)
            .drive(0.2, 0.3, 0.4)
            .drive(-0.1, 0.1, 0.4),
    ];
    let text: Vec<String> = poses
        .iter()
        .enumerate()
        .map(|(i, p)| odom(p.x, p.y, p.yaw, i as f64))
        .collect();
    let (rec, notes) = read_carmen(&text.join("\n"), "odom.log", &options).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    assert!(rec.truth.is_none() && rec.lidar.is_none());
    let odometry = rec.odometry.unwrap();
    let mut pose = poses[0];
    let (mut left, mut right) = (0.0, 0.0);
    for (s, want) in odometry.iter().zip(&poses).skip(1) {
        pose = pose.drive(s.left_m - left, s.right_m - right, 0.4);
        (left, right) = (s.left_m, s.right_m);
        assert!(
            (pose.x - want.x).abs() < 1e-9
                && (pose.y - want.y).abs() < 1e-9
                && (pose.yaw - want.yaw).abs() < 1e-9,
            "{pose:?} against {want:?}"
        );
    }
    assert!((odometry[1].left_m - 0.2).abs() < 1e-9 && (odometry[1].right_m - 0.3).abs() < 1e-9);
}

#[test]
fn robotlaser_gives_angles_and_the_mount() {
    // 3 beams from -0.5 rad, 0.5 rad apart, max range 5 (the last reads 5: no return); 2
    // remissions; the laser 0.2 m ahead of the robot at (1, 0, 0); no turn_axis field.
    let line = "ROBOTLASER1 0 -0.5 1.0 0.5 5 0.01 0 3 1 2 5 2 0.1 0.2 1.2 0 0 1 0 0 0 0 0 0 \
                10.0 host 10.1";
    let (rec, notes) = read_carmen(line, "rl.log", &CarmenOptions::default()).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    let lidar = rec.lidar.unwrap();
    assert_eq!(lidar.len(), 3);
    assert!((lidar[0].angle_deg - (360.0 - 0.5f64.to_degrees())).abs() < 1e-9);
    assert!((lidar[2].angle_deg - 0.5f64.to_degrees()).abs() < 1e-9);
    assert!(lidar[2].invalid && !lidar[1].invalid);
    let mount = rec.meta.lidar.unwrap();
    assert!((mount.x_m - 0.2).abs() < 1e-12 && mount.y_m.abs() < 1e-12);
    assert_eq!(rec.truth.unwrap()[0].x_m, 1.0);
}

#[test]
fn a_log_of_nothing_readable_is_refused() {
    let err = read_carmen(
        "# nothing\nNEFF 3\n",
        "empty.log",
        &CarmenOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(err, LogError::Empty { .. }), "{err}");
}

/// A corrected log's odometry restarts at each scan's corrected pose (an ODOM line with the
/// scan's very pose, stamped 0, as in the Radish logs): the jump to it is the correction, and
/// the wheels' travel is only the dead reckoning on either side of it.
#[test]
fn a_corrected_logs_restart_at_the_scans_pose_is_not_wheel_travel() {
    let corrected = [2.0, 1.05, 0.0];
    let text = [
        odom(1.0, 1.0, 0.0, 1.0),
        odom(1.1, 1.0, 0.0, 1.5),
        odom(1.2, 1.0, 0.0, 2.0),
        flaser(1.0, corrected, 2.0),
        // The restart: the scan's pose, stamped 0 (out of time order).
        odom(corrected[0], corrected[1], corrected[2], 0.0),
        odom(2.1, 1.05, 0.0, 2.5),
        odom(2.2, 1.05, 0.0, 3.0),
    ]
    .join("\n");
    let (rec, notes) = read_carmen(&text, "corrected.log", &CarmenOptions::default()).unwrap();
    let odometry = rec.odometry.unwrap();
    let last = odometry.last().unwrap();
    // Four steps of 0.1 m straight ahead; the 0.8 m and 5 cm sideways jump to the scan's pose
    // is not in it.
    assert!(
        (last.left_m - 0.4).abs() < 1e-9 && (last.right_m - 0.4).abs() < 1e-9,
        "{odometry:?}"
    );
    assert!(
        notes
            .iter()
            .any(|n| n.contains("1 ODOM line(s) restart the odometry")),
        "{notes:?}"
    );
    assert!(!notes.iter().any(|n| n.contains("sideways")), "{notes:?}");
}
