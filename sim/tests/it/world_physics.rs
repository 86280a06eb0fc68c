//! The simulated world's physics: the drive program moves the robot where it says, walls stop
//! it (logged, not a crash), and a run is a pure function of the scenario.

use hilsim_sim::{Obstacle, Scenario, Simulation};

/// A scenario with `top` keys before the robot table and `extra` tables after it.
fn scenario_with(top: &str, extra: &str) -> Scenario {
    let text = format!(
        "name = \"t\"\n{top}\n[robot]\nstart = {{ x = 0.0, y = 0.0, yaw_deg = 0.0 }}\nwheel_base_m = 0.23\n{extra}"
    );
    Scenario::from_toml(&text, "t.toml".as_ref()).unwrap()
}

fn scenario(extra: &str) -> Scenario {
    scenario_with("", extra)
}

fn run(s: &Scenario) -> Simulation {
    let mut sim = Simulation::new(s);
    while sim.step().is_some() {}
    sim
}

#[test]
fn straight_then_turn_then_straight_ends_where_the_program_says() {
    let s = scenario(
        "[[drive]]\nspeed_mps = 0.2\ndistance_m = 1.0\n[[drive]]\nturn_deg = 90.0\n[[drive]]\nspeed_mps = -0.1\ndistance_m = 0.5\n",
    );
    let sim = run(&s);
    let p = sim.pose();
    // Physics in f32 over ~1000 steps: a millimetre is ample and still catches a wrong sign or
    // a missed step (0.2 m/s × 10 ms = 2 mm per step).
    assert!((p.x - 1.0).abs() < 1e-3, "{p:?}");
    assert!((p.y + 0.5).abs() < 1e-3, "{p:?}");
    assert!((p.yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-3, "{p:?}");
    // 5 s + 2 s + 5 s at 100 Hz, plus the pose at t = 0.
    assert_eq!(sim.truth().len(), 1201);
    assert!(sim.collisions().is_empty());
    let cmds = sim.commands();
    assert_eq!(cmds.len(), 3);
    assert_eq!(cmds[1].t_s, 5.0);
    assert!(cmds[1].left_mps < 0.0 && cmds[1].right_mps > 0.0);
}

#[test]
fn a_wall_stops_the_robot_and_the_contact_is_logged() {
    // The wall is 1 m ahead; the robot (radius 0.165 m) is told to drive 2 m.
    let s = scenario(
        "[world]\nwalls = [{ from = [1.0, -1.0], to = [1.0, 1.0] }]\n[[drive]]\nspeed_mps = 0.3\ndistance_m = 2.0\n",
    );
    let sim = run(&s);
    let x = sim.pose().x;
    assert!((x - (1.0 - 0.165)).abs() < 0.01, "stopped at x = {x}");
    let c = sim.collisions();
    assert_eq!(c.len(), 1, "{c:?}");
    assert_eq!(c[0].obstacle, Obstacle::Wall(0));
    // Contact starts when the disc reaches the wall: at (1 - 0.165) / 0.3 ≈ 2.78 s.
    assert!((c[0].t_s - 0.835 / 0.3).abs() < 0.05, "{c:?}");
}

#[test]
fn duration_longer_than_the_program_stands_still_after_it() {
    let s = scenario_with(
        "duration_s = 3.0",
        "[[drive]]\nspeed_mps = 0.5\ndistance_m = 0.5\n",
    );
    let sim = run(&s);
    assert_eq!(sim.truth().last().unwrap().t_s, 3.0);
    assert!((sim.pose().x - 0.5).abs() < 1e-3);
    assert_eq!(sim.commands().last().unwrap().left_mps, 0.0);
}

#[test]
fn the_same_scenario_gives_the_same_trajectory_bit_for_bit() {
    let s = scenario(
        "[world]\ncylinders = [{ center = [1.0, 0.05], radius = 0.1 }]\n[[drive]]\nspeed_mps = 0.4\ndistance_m = 2.0\n[[drive]]\nturn_deg = -30.0\n",
    );
    let a = run(&s);
    let b = run(&s);
    assert_eq!(a.truth(), b.truth());
    assert!(!a.collisions().is_empty(), "the cylinder is in the way");
}

#[test]
fn rays_hit_obstacles_but_never_the_robot() {
    let s = scenario_with(
        "duration_s = 0.1",
        "[world]\ncylinders = [{ center = [2.0, 0.0], radius = 0.12 }]\n",
    );
    let sim = Simulation::new(&s);
    let hit = sim.world().cast_ray([0.0, 0.0], 0.0, 10.0).unwrap();
    // f32 geometry: ~1e-6 relative at 2 m.
    assert!((hit.distance - 1.88).abs() < 1e-4, "{hit:?}");
    assert_eq!(hit.obstacle, Obstacle::Cylinder(0));
    // From inside the robot's own disc, looking away from the cylinder: nothing.
    assert!(sim
        .world()
        .cast_ray([0.0, 0.0], std::f64::consts::PI, 10.0)
        .is_none());
}

#[test]
fn actuation_error_makes_the_robot_miss_the_commanded_distance_but_not_the_commands() {
    let drive = "[[drive]]\nspeed_mps = 0.2\ndistance_m = 2.0\n";
    let exact = run(&scenario(drive));
    let with_error = |seed: u64| {
        let mut s = scenario(&format!(
            "{drive}[robot.actuation]\nscale_sd = 0.03\nwander_sd = 0.01\nwander_tau_s = 5.0\n"
        ));
        s.seed = seed;
        run(&s)
    };
    let a = with_error(1);
    let b = with_error(2);
    // The commands are what was issued, whatever the wheels did.
    assert_eq!(a.commands(), exact.commands());
    // A 3 % scale error moves the end by ~6 cm; two seeds differ, one seed repeats exactly.
    let (xa, xb) = (a.pose().x, b.pose().x);
    assert!(
        (xa - 2.0).abs() > 1e-3 && (xb - 2.0).abs() > 1e-3,
        "{xa} {xb}"
    );
    assert_ne!(xa, xb);
    assert_eq!(with_error(1).truth(), a.truth());
    // Bounded by 10 standard deviations of the combined error: |error| < 10·√(0.03²+0.01²)·2 m.
    assert!((xa - 2.0).abs() < 10.0 * (0.03f64.powi(2) + 0.01f64.powi(2)).sqrt() * 2.0);
}
