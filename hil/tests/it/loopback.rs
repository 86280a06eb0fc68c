//! `hilsim run --via serial`: lidar data that crosses a real pty and the decoder equals the
//! in-process data, reading for reading, timestamps included.

use hilsim_hil::loopback::run_through_pty;
use hilsim_lidar_emulator::Emulation;
use hilsim_sim::Scenario;

#[test]
fn the_serial_path_delivers_exactly_the_in_process_readings() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenarios/room-tour.toml");
    let scenario = Scenario::load(path.as_ref()).unwrap();
    let memory = Emulation::new(&scenario, 21).unwrap().run();
    let (serial, report) = run_through_pty(Emulation::new(&scenario, 21).unwrap()).unwrap();
    let memory_lidar = memory.recording.lidar.clone().unwrap();
    let serial_lidar = serial.recording.lidar.as_ref().unwrap();
    assert!(memory_lidar.len() > 100 * 360);
    assert_eq!(serial_lidar.len(), memory_lidar.len());
    // Ranges, flags, strengths and timestamps decoded from the wire; true ranges attached.
    assert_eq!(*serial_lidar, memory_lidar);
    // The rest of the recording does not travel the wire and is untouched.
    assert_eq!(serial.recording.sonar, memory.recording.sonar);
    assert_eq!(serial.recording.truth, memory.recording.truth);
    assert_eq!(report.decoder.bad_checksum, 0);
    assert_eq!(report.stream.revolutions_dropped, 0);
    assert!(report.client_path.starts_with("/dev/pts/"));
}
