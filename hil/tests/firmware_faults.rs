//! Firmware faults: a firmware that crashes, hangs, floods the command port or never
//! reads the lidar ends the run with that fault, its stderr tail kept, and nothing of it is
//! left behind: no process of its group, no descriptor of the harness.
//!
//! One test in this binary, so that nothing else opens descriptors in the process meanwhile.

use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use hilsim_hil::firmware::{Ended, Firmware};
use hilsim_hil::hil_run::{run, Ending, Fault, HilConfig, HilPorts, HilReport, HilWorld};
use hilsim_sim::Scenario;

const SCENARIO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../scenarios/hil-approach.toml"
);

/// The process's open descriptors and what they point at.
fn open_fds() -> BTreeMap<String, String> {
    std::fs::read_dir("/proc/self/fd")
        .unwrap()
        .filter_map(|e| {
            let e = e.ok()?;
            let target = std::fs::read_link(e.path()).ok()?;
            Some((
                e.file_name().to_string_lossy().into_owned(),
                target.display().to_string(),
            ))
        })
        // The directory listing's own descriptor.
        .filter(|(_, target)| !target.starts_with("/proc/"))
        .collect()
}

/// The process no longer runs (gone, or a zombie waiting for init to reap it).
fn gone(pid: u32) -> bool {
    hilsim_hil::process::has_exited(pid, Duration::from_secs(2))
}

/// Runs `script` under `sh -c` as the firmware for up to 6 s with a 1 s watchdog. Every
/// process it starts must print `pid N` on stderr; all of them, and the shell, must be gone
/// afterwards, and the harness must hold the descriptors it held before.
fn run_script(script: &str) -> HilReport {
    let before = open_fds();
    let scenario = Scenario::load_with_duration(SCENARIO.as_ref(), Some(6.0)).unwrap();
    let world = HilWorld::new(&scenario, 1).unwrap();
    let ports = HilPorts::open().unwrap();
    let ptys = [
        ports.lidar_path().to_string(),
        ports.robot_path().to_string(),
    ];
    let env = [
        ("HILSIM_LIDAR_PORT", ptys[0].as_str()),
        ("HILSIM_ROBOT_PORT", ptys[1].as_str()),
    ];
    let argv = ["sh".to_string(), "-c".to_string(), script.to_string()];
    let firmware = Firmware::spawn(&argv, &env).unwrap();
    let leader = firmware.pid();
    let config = HilConfig {
        watchdog: Duration::from_secs(1),
        ..HilConfig::new(Duration::from_secs(6))
    };
    let report = run(
        world,
        ports,
        Some(firmware),
        &config,
        &AtomicBool::new(false),
    )
    .unwrap();
    let mut pids = vec![leader];
    pids.extend(
        report
            .stderr
            .lines
            .iter()
            .filter_map(|l| l.strip_prefix("pid ")?.parse::<u32>().ok()),
    );
    assert!(pids.len() >= 2, "{:?}", report.stderr);
    for pid in pids {
        assert!(gone(pid), "process {pid} of `{script}` is still running");
    }
    let after = open_fds();
    assert_eq!(before, after, "descriptors left open after `{script}`");
    for pty in &ptys {
        assert!(!after.values().any(|t| t == pty), "{pty} still open");
    }
    report
}

#[test]
fn each_fault_ends_the_run_and_leaves_nothing_behind() {
    // A crash: a non-zero exit status, with its last words on stderr.
    let report = run_script(
        r#"cat "$HILSIM_LIDAR_PORT" > /dev/null & echo "pid $!" >&2
           printf 'TestMode On\n' > "$HILSIM_ROBOT_PORT"; sleep 0.3
           echo 'assertion failed: pid controller diverged' >&2; exit 3"#,
    );
    let Ending::Fault(Fault::Crashed(status)) = report.ending else {
        panic!("{:?}", report.ending);
    };
    assert_eq!(status.code(), Some(3));
    assert!(report
        .stderr
        .lines
        .iter()
        .any(|l| l.contains("pid controller diverged")));
    assert_eq!(report.firmware.unwrap().ended, Ended::ByItself);
    assert_eq!(report.commands.test_mode, 1);

    // A hang: it reads the lidar but stops talking after one request; the 1 s watchdog fires
    // 1 s after that request.
    let report = run_script(
        r#"cat "$HILSIM_LIDAR_PORT" > /dev/null & echo "pid $!" >&2
           printf 'TestMode On\n' > "$HILSIM_ROBOT_PORT"
           sleep 60 & echo "pid $!" >&2; wait"#,
    );
    assert_eq!(
        report.ending,
        Ending::Fault(Fault::Hung {
            watchdog: Duration::from_secs(1)
        })
    );
    assert!(
        (1.0..1.6).contains(&report.ended_at_s),
        "{}",
        report.ended_at_s
    );
    // Its ports closed, it kept waiting: SIGTERM ended it.
    assert_eq!(report.firmware.unwrap().ended, Ended::Terminated);

    // A flood: requests as fast as the pty takes them.
    let report = run_script(
        r#"cat "$HILSIM_LIDAR_PORT" > /dev/null & echo "pid $!" >&2
           cat "$HILSIM_ROBOT_PORT" > /dev/null & echo "pid $!" >&2
           yes GetSonar > "$HILSIM_ROBOT_PORT""#,
    );
    let Ending::Fault(Fault::Flooded {
        bytes,
        commands,
        limits,
    }) = report.ending
    else {
        panic!("{:?}", report.ending);
    };
    assert!(bytes > limits.bytes_per_s || commands > limits.commands_per_s);
    assert!(report.ended_at_s < 1.0, "{}", report.ended_at_s);

    // The lidar never read: it polls the sonar five times a second and never opens the lidar
    // port; after one watchdog period the stream shows it took nothing.
    let report = run_script(
        r#"cat "$HILSIM_ROBOT_PORT" > /dev/null & echo "pid $!" >&2
           while :; do printf 'GetSonar\n'; sleep 0.2; done > "$HILSIM_ROBOT_PORT""#,
    );
    let Ending::Fault(Fault::LidarNeverRead {
        bytes_read,
        bytes_written,
    }) = report.ending
    else {
        panic!("{:?}", report.ending);
    };
    assert!(
        bytes_read < 1980 && bytes_written >= 4 * 1980,
        "{bytes_read} {bytes_written}"
    );
    assert!(
        report.stream.revolutions_dropped >= 2,
        "{:?}",
        report.stream
    );
    assert!(report.commands.get_sonar >= 3);
}
