//! A log file's text, gzipped or not, whatever its name.

use std::io::Write;

use hilsim_logs::{read_carmen, read_text, CarmenOptions, Clock};

const LOG: &str = "# a log\nODOM 1 2 0 0 0 0 10.0 host 10.5\nODOM 1 2 0 0 0 0 11.0 host 12.5\n";

#[test]
fn gzipped_and_plain_files_give_the_same_text() {
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("a.log");
    std::fs::write(&plain, LOG).unwrap();
    // A gzipped file without `.gz` in its name is known by its magic bytes.
    let zipped = dir.path().join("b.clf");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(LOG.as_bytes()).unwrap();
    std::fs::write(&zipped, gz.finish().unwrap()).unwrap();
    assert_eq!(read_text(&plain).unwrap(), LOG);
    assert_eq!(read_text(&zipped).unwrap(), LOG);
}

#[test]
fn a_missing_or_binary_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("none.log");
    let err = read_text(&missing).unwrap_err();
    assert!(err.to_string().contains("none.log"), "{err}");
    let binary = dir.path().join("bin.log");
    std::fs::write(&binary, [0xff, 0xfe, 0x00]).unwrap();
    let err = read_text(&binary).unwrap_err();
    assert!(err.to_string().contains("not text"), "{err}");
}

#[test]
fn the_clock_option_chooses_ipc_or_logger_time() {
    let ipc = read_carmen(LOG, "a.log", &CarmenOptions::default())
        .unwrap()
        .0;
    assert_eq!(ipc.odometry.unwrap()[1].t_s, 1.0);
    let options = CarmenOptions {
        clock: Clock::Logger,
        ..CarmenOptions::default()
    };
    let logger = read_carmen(LOG, "a.log", &options).unwrap().0;
    assert_eq!(logger.odometry.unwrap()[1].t_s, 2.0);
}
