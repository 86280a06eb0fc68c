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

/// A room 4 m square drawn into a map of 5 cm cells by beams from its middle, every quarter
/// degree.
fn mapped_room() -> hilsim_sim::Scenario {
    let mut builder = hilsim_sim::MapBuilder::new(0.05);
    let centre = [2.0, 2.0];
    for k in 0..1440 {
        let a = f64::from(k) * 0.25f64.to_radians();
        let (sin, cos) = a.sin_cos();
        // The nearest of the walls x = 0, x = 4, y = 0, y = 4 along the beam.
        let reach = [cos, sin]
            .iter()
            .filter(|d| d.abs() > 1e-9)
            .map(|d| 2.0 / d.abs())
            .fold(f64::INFINITY, f64::min);
        for _ in 0..3 {
            builder
                .add_beam(
                    centre,
                    [centre[0] + reach * cos, centre[1] + reach * sin],
                    true,
                )
                .expect("a beam");
        }
    }
    let map = builder.finish(
        hilsim_sim::MapBuilder::DEFAULT_MIN_HITS,
        hilsim_sim::MapBuilder::DEFAULT_OCCUPIED_RATIO,
    );
    let mut scenario = room();
    scenario.world = hilsim_sim::scenario::World::default();
    scenario.files.map = Some(std::sync::Arc::new(map));
    scenario
}

/// A scan matcher's question (a short piece of path, asked once) leaves out the world's reach
/// of each reading and nothing else: the distributions are the full answer's, and in a map,
/// whose cells can move a reading, the full answer has a reach to leave out.
#[test]
fn the_distributions_alone_are_the_full_answers_without_the_worlds_reach() {
    let nominal = Hypothesis::nominal();
    let physics = SimPhysics::new(&mapped_room()).expect("the physics");
    let piece =
        Trajectory::from_poses((0..=20).map(|k| (f64::from(k) * 0.01, Pose::new(2.0, 2.1, 0.2))))
            .expect("a path");
    let queries: Vec<LidarQuery> = (0..90)
        .map(|k| LidarQuery {
            t_s: 0.05,
            rev_start_s: 0.05,
            angle_deg: f64::from(k * 4),
        })
        .collect();
    let full = physics.lidar(&piece, &queries, &nominal);
    let distributions = physics.lidar_distributions(&piece, &queries, &nominal);
    assert!(
        full.iter().filter(|p| p.world_reach_m > 0.0).count() > 80,
        "a map's cells move the readings"
    );
    assert!(full.iter().filter(|p| !p.components.is_empty()).count() > 80);
    for (f, d) in full.iter().zip(&distributions) {
        assert_eq!(d.world_reach_m, 0.0);
        let mut f = f.clone();
        f.world_reach_m = 0.0;
        assert_eq!(&f, d);
    }
}
