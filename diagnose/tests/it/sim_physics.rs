//! The simulator's answers to the diagnosis do not depend on what it kept from earlier
//! questions: a call's beams kept for a fit's next step are the same readings' beams.

use hilsim_diagnose::{Hypothesis, LidarQuery, Physics, Pose, SimPhysics, Trajectory};

use crate::catalogue::room;

/// A second along a straight line from (1, 1), heading `yaw`, one pose every 10 ms.
fn path(yaw: f64) -> Trajectory {
    Trajectory::from_poses((0..=300).map(|k| {
        let t = f64::from(k) * 0.01;
        let s = 0.2 * t;
        (t, Pose::new(1.0 + s * yaw.cos(), 1.0 + s * yaw.sin(), yaw))
    }))
    .expect("a path")
}

/// 600 readings a revolution of 360 over the path's 3 s (a degree apart, 5 revolutions a
/// second).
fn queries() -> Vec<LidarQuery> {
    (0..600)
        .map(|k| {
            let t_s = 0.2 + f64::from(k) / 1800.0 * 2.5;
            LidarQuery {
                t_s,
                rev_start_s: t_s,
                angle_deg: f64::from(k % 360),
            }
        })
        .collect()
}

#[test]
fn a_kept_calls_beams_answer_as_a_fresh_simulation_does() {
    let nominal = Hypothesis::nominal();
    let physics = SimPhysics::new(&room()).expect("the physics");
    let (along, turned) = (path(0.0), path(0.3));
    let queries = queries();
    // Asked twice (the second answered from the call kept), then along another path with the
    // same readings (whose beams differ), then a subset of them.
    let first = physics.lidar(&along, &queries, &nominal);
    let again = physics.lidar(&along, &queries, &nominal);
    let other = physics.lidar(&turned, &queries, &nominal);
    let some = physics.lidar(&along, &queries[100..400], &nominal);
    let fresh = |path: &Trajectory, queries: &[LidarQuery]| {
        SimPhysics::new(&room())
            .expect("the physics")
            .lidar(path, queries, &nominal)
    };
    assert_eq!(first, again);
    assert_eq!(first, fresh(&along, &queries));
    assert_eq!(other, fresh(&turned, &queries));
    assert_ne!(first, other, "the turned path sees other ranges");
    assert_eq!(some, first[100..400].to_vec());
}
