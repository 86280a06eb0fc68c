//! The CoreSLAM reader on a few lines written here.

use hilsim_logs::{read_coreslam, CoreSlamOptions, LogError};

/// A line at `t_us` with encoder counts `left`, `right` and 682 ranges, beam i at 1000 + i mm
/// (the first 0: no return).
fn line(t_us: u64, left: i64, right: i64) -> String {
    let mut fields = vec![
        t_us.to_string(),
        "0".into(),
        left.to_string(),
        right.to_string(),
    ];
    fields.extend((0..20).map(|_| "0".to_string()));
    fields.extend((0..682).map(|i| if i == 0 { 0 } else { 1000 + i }.to_string()));
    fields.join(" ")
}

#[test]
fn scans_and_wheel_travel_are_read() {
    let text = [
        line(5_000_000, 100, 200),
        line(5_100_000, 300, 200),
        line(5_200_000, 500, 400),
    ]
    .join("\n");
    let rec = read_coreslam(&text, "exp.dat", &CoreSlamOptions::default()).unwrap();
    let odometry = rec.odometry.unwrap();
    assert_eq!(odometry.len(), 3);
    let metres_per_tick = std::f64::consts::TAU * 0.077 / 2000.0;
    assert_eq!(odometry[0].left_m, 0.0);
    assert!((odometry[2].t_s - 0.2).abs() < 1e-12);
    assert!((odometry[2].left_m - 400.0 * metres_per_tick).abs() < 1e-12);
    assert!((odometry[2].right_m - 200.0 * metres_per_tick).abs() < 1e-12);
    let lidar = rec.lidar.unwrap();
    assert_eq!(lidar.len(), 3 * 682);
    assert!(lidar[0].invalid && lidar[0].range_m == 0.0);
    assert!((lidar[1].range_m - 1.001).abs() < 1e-12);
    // The first beam at step 44, 340 steps right of the front (360/1024° each), the last 341
    // steps left; each a step (0.1 s / 1024) after the one before.
    let step = 360.0 / 1024.0;
    assert!((lidar[0].angle_deg - (360.0 - 340.0 * step)).abs() < 1e-9);
    assert!((lidar[681].angle_deg - 341.0 * step).abs() < 1e-9);
    // Times to the microsecond, as a recording writes them.
    assert!((lidar[681].t_s - 681.0 * 0.1 / 1024.0).abs() <= 0.5e-6);
    assert_eq!(lidar[682].rev, 1);
    assert_eq!(rec.meta.lidar.unwrap().x_m, 0.145);
    assert_eq!(rec.meta.robot.wheel_base_m, 0.33);
}

#[test]
fn a_scan_stamped_before_the_last_one_ended_starts_after_it() {
    // The second scan is stamped 30 ms after the first, whose 682 readings take 66.5 ms.
    let text = [line(5_000_000, 0, 0), line(5_030_000, 0, 0)].join("\n");
    let rec = read_coreslam(&text, "exp.dat", &CoreSlamOptions::default()).unwrap();
    let lidar = rec.lidar.unwrap();
    assert!(
        lidar.windows(2).all(|w| w[1].t_s > w[0].t_s),
        "time runs forward"
    );
    assert!((lidar[682].t_s - 682.0 * 0.1 / 1024.0).abs() <= 0.5e-6);
    assert!(
        (rec.odometry.unwrap()[1].t_s - 0.03).abs() < 1e-12,
        "the wheels keep the stamp"
    );
}

#[test]
fn a_short_line_is_an_error_naming_it() {
    let text = [line(0, 0, 0), "1 2 3".to_string(), line(200_000, 0, 0)].join("\n");
    let err = read_coreslam(&text, "exp.dat", &CoreSlamOptions::default()).unwrap_err();
    assert!(matches!(err, LogError::Line { line: 2, .. }), "{err}");
    assert!(err.to_string().starts_with("exp.dat:2: 3 fields"), "{err}");
}

#[test]
fn an_encoder_jump_beyond_a_wheel_is_an_error() {
    let text = [line(0, 0, 0), line(100_000, 1_000_000, 0)].join("\n");
    let err = read_coreslam(&text, "exp.dat", &CoreSlamOptions::default()).unwrap_err();
    assert!(
        err.to_string().contains("left encoder count jumped"),
        "{err}"
    );
}
