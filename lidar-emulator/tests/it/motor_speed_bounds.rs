//! However the motor's speed is set (a wobble deeper than the speed reaches the model only when
//! validation is bypassed), each revolution's rpm stays within what the packet's field carries
//! and the readings' times never go backwards: the emulation ends instead of spinning forever.

use hilsim_lidar_emulator::Emulation;
use hilsim_sim::Scenario;

fn scenario() -> Scenario {
    let text = r#"
        name = "wobble"
        duration_s = 2.0
        [world]
        boards = [{ center = [-0.009, 0.0], length = 1.2 }]
        [robot]
        start = { x = 1.0, y = 0.0, yaw_deg = 180.0 }
        wheel_base_m = 0.23
        [sensors.lidar]
        rpm_wobble = 3.0
    "#;
    Scenario::from_toml(text, "wobble.toml".as_ref()).unwrap()
}

#[test]
fn a_wobble_deeper_than_the_speed_keeps_time_running_forward() {
    for wobble in [1_000.0, 20_000.0, 1e300] {
        let mut scenario = scenario();
        scenario.sensors.lidar.as_mut().unwrap().rpm_wobble = wobble;
        let mut emulation = Emulation::new(&scenario, 7).unwrap();
        let lidar = emulation.lidar().unwrap();
        for rev in 0..100 {
            let rpm = lidar.rpm_of_revolution(rev);
            assert!(
                (1.0 / 64.0..=f64::from(u16::MAX) / 64.0).contains(&rpm),
                "{rpm}"
            );
        }
        let mut last = f64::NEG_INFINITY;
        let mut readings = 0;
        while let Some(samples) = emulation.step() {
            for r in &samples.lidar {
                assert!(r.t_s >= last, "wobble {wobble}: {} after {last}", r.t_s);
                assert!(r.t_s < 2.0, "wobble {wobble}: {}", r.t_s);
                last = r.t_s;
                readings += 1;
            }
        }
        assert!(readings > 0, "wobble {wobble}");
    }
}
