//! Readings that cross the Neato wire (encode → bytes → decode) come back as the same recording
//! rows, timestamps included: the basis of `hilsim run --via serial` giving the in-process result.

use hilsim_lidar_emulator::neato_packet::{Decoder, RevolutionAssembler};
use hilsim_lidar_emulator::wire::{RevolutionCollector, WireTimeline};
use hilsim_lidar_emulator::Emulation;
use hilsim_recording::LidarSample;
use hilsim_sim::Scenario;

#[test]
fn a_wobbling_lidar_survives_the_wire_bit_for_bit() {
    let scenario = Scenario::from_toml(
        r#"
        name = "wire"
        [world]
        walls = [{ from = [2.0, -3.0], to = [2.0, 3.0] }, { from = [-1.0, -3.0], to = [-1.0, 3.0] }]
        cylinders = [{ center = [1.0, 0.8], radius = 0.1 }]
        [robot]
        start = { x = 0.0, y = 0.0 }
        wheel_base_m = 0.23
        [[drive]]
        speed_mps = 0.3
        distance_m = 0.6
        [[drive]]
        turn_deg = 120.0
        [sensors.lidar]
        bias = [0.0525, 0.8838, 0.0584]
        noise = [0.0, 0.0, 0.004]
        angle_noise_deg = 0.5
        rpm_wobble = 4.0
        "#,
        "wire.toml".as_ref(),
    )
    .unwrap();
    let mut emulation = Emulation::new(&scenario, 5).unwrap();
    let mut collector = RevolutionCollector::default();
    let mut wire = Vec::new();
    let mut sent: Vec<LidarSample> = Vec::new();
    let mut revolutions = 0;
    while let Some(step) = emulation.step() {
        let readings = step.lidar.clone();
        for r in &readings {
            let rpm = emulation.lidar().unwrap().rpm_of_revolution(r.rev);
            if let Some(frame) = collector.push(r, rpm) {
                frame.encode(&mut wire);
                revolutions += 1;
            }
        }
        sent.extend(readings.iter().map(|r| LidarSample {
            true_range_m: None,
            ..r.to_sample()
        }));
    }
    assert!(revolutions > 20, "{revolutions}");
    // Only whole revolutions cross the wire.
    sent.truncate(revolutions * 360);

    let mut decoder = Decoder::new();
    let mut assembler = RevolutionAssembler::new();
    let mut timeline = WireTimeline::new();
    let mut received = Vec::new();
    for packet in decoder.feed(&wire).collect::<Vec<_>>() {
        if let Some(rev) = assembler.push(packet) {
            timeline.push(&rev, &mut received);
        }
    }
    if let Some(rev) = assembler.finish() {
        timeline.push(&rev, &mut received);
    }
    assert_eq!(received.len(), sent.len());
    assert_eq!(
        received, sent,
        "timestamps, ranges, flags and strengths all equal"
    );
}
