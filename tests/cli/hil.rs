//! `hilsim hil`: firmware in the loop, end to end. The example firmwares (Rust and C) drive to
//! 0.5 m from the board of a short `hil-approach`; faulty firmwares end the run with exit code
//! 1, the fault on one line, their stderr tail, and none of their processes left.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Duration;

use hilsim_recording::Recording;

use super::common::*;

/// `scenarios/hil-approach.toml` with the robot 1.5 m from the board instead of 2.5 m, so that
/// the approach takes about 5 s of real time.
fn short_approach(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(repo_file("scenarios/hil-approach.toml")).unwrap();
    let moved = text.replace("start = { x = 2.5,", "start = { x = 1.5,");
    assert_ne!(
        moved, text,
        "the start pose line of hil-approach.toml changed"
    );
    let path = dir.join("approach.toml");
    std::fs::write(&path, moved).unwrap();
    path
}

/// The example firmware, built once per test run (the `hilsim` package cannot depend on a
/// binary-only package, so the test asks cargo for it; a no-op when it is up to date).
pub(super) fn example_firmware() -> &'static Path {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT.get_or_init(|| {
        let bin_dir = Path::new(env!("CARGO_BIN_EXE_hilsim")).parent().unwrap();
        let mut cargo = Command::new(env!("CARGO"));
        cargo
            .args(["build", "--quiet", "-p", "hilsim-example-firmware"])
            .current_dir(root());
        if bin_dir.ends_with("release") {
            cargo.arg("--release");
        }
        let out = cargo.output().expect("cargo runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let path = bin_dir.join("example-firmware");
        assert!(path.is_file(), "{} was not built", path.display());
        path
    })
}

/// `firmware/c/firmware.c`, compiled with the machine's C compiler into `dir`.
fn c_firmware(dir: &Path) -> PathBuf {
    let exe = dir.join("c-firmware");
    let out = Command::new("cc")
        .args(["-O2", "-Wall", "-o"])
        .arg(&exe)
        .arg(repo_file("firmware/c/firmware.c"))
        .output()
        .expect("a C compiler (cc) is installed");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    exe
}

/// The firmware's pid from the report's `firmware: pid N` line.
fn firmware_pid(text: &str) -> u32 {
    text.lines()
        .find_map(|l| {
            l.strip_prefix("firmware: pid ")?
                .split(' ')
                .next()?
                .parse()
                .ok()
        })
        .unwrap_or_else(|| panic!("no pid in {text}"))
}

/// The process no longer runs (gone, or a zombie waiting for init to reap it).
fn gone(pid: u32) -> bool {
    hilsim_hil::process::has_exited(pid, Duration::from_secs(2))
}

/// Asserts that the firmware (its summary line starts with `name:`) decoded every revolution
/// hilsim sent: no gap in the packet index sequence, no bad checksum, none dropped, and as many
/// revolutions as were sent (but the one in progress when it exited).
fn assert_every_revolution_seen(text: &str, name: &str) {
    let summary = text
        .lines()
        .find(|l| l.starts_with(&format!("{name}: ")))
        .unwrap_or_else(|| panic!("no summary from {name}: {text}"));
    assert!(
        summary.contains(", index gaps 0, bad checksums 0"),
        "{summary}"
    );
    let number_after = |line: &str, key: &str| -> u64 {
        line.split(key)
            .nth(1)
            .and_then(|r| r.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok())
            .unwrap_or_else(|| panic!("no `{key}` in {line}"))
    };
    let seen = number_after(summary, "; revolutions ");
    let lidar = text
        .lines()
        .find(|l| l.starts_with("lidar: ") && l.contains("revolutions sent"))
        .unwrap();
    let sent = number_after(lidar, "lidar: ");
    assert!(lidar.contains(" revolutions sent, 0 dropped;"), "{lidar}");
    assert!(
        seen + 1 >= sent && seen <= sent && sent >= 10,
        "{summary}\n{lidar}"
    );
}

/// The robot's final distance to the board's face (x = 0), from the recording's truth.
fn final_distance(dir: &Path) -> f64 {
    let rec = Recording::read_dir(dir).unwrap();
    assert!(rec.lidar.is_some() && rec.sonar.is_some() && rec.odometry.is_some());
    assert!(rec.commands.iter().any(|c| c.left_mps > 0.0));
    rec.truth.unwrap().last().unwrap().x_m
}

#[test]
fn the_example_firmware_stops_half_a_metre_from_the_board_and_misses_no_revolution() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = short_approach(tmp.path());
    let firmware = example_firmware().to_str().unwrap().to_string();
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--firmware",
            &firmware,
            "--duration",
            "12",
            "--out",
            "rec",
        ],
    );
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(0), "{text}{}", stderr(&out));
    assert!(text.starts_with("lidar: /dev/pts/"), "{text}");
    assert!(text.contains("\nrobot: /dev/pts/"), "{text}");
    // The firmware's own summary (its stdout passes through): every revolution arrived.
    assert!(
        text.contains("example-firmware: reached the target"),
        "{text}"
    );
    assert_every_revolution_seen(&text, "example-firmware");
    assert!(
        text.contains("ended: the firmware exited with status 0"),
        "{text}"
    );
    assert!(text.contains("; 0 collision(s)"), "{text}");
    assert!(text.contains(", 0 error(s)"), "{text}");
    // The scenario's assertions, checked under hil.
    for line in [
        "PASS sim.final_x_m",
        "PASS hil.command_errors",
        "PASS hil.fault",
        "SKIP lidar.revolutions",
    ] {
        assert!(text.contains(line), "{line}: {text}");
    }
    let d = final_distance(&tmp.path().join("rec"));
    assert!((d - 0.50).abs() <= 0.05, "stopped {d:.3} m from the board");
    assert!(gone(firmware_pid(&text)));
}

#[test]
fn a_firmware_in_c_does_the_same() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = short_approach(tmp.path());
    let firmware = c_firmware(tmp.path()).to_str().unwrap().to_string();
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--firmware",
            &firmware,
            "--duration",
            "12",
            "--out",
            "rec",
        ],
    );
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(0), "{text}{}", stderr(&out));
    assert!(text.contains("c-firmware: reached the target"), "{text}");
    assert_every_revolution_seen(&text, "c-firmware");
    // Its tolerance: ±0.05 m too (a gentler approach, 250 mm/s at most).
    let d = final_distance(&tmp.path().join("rec"));
    assert!((d - 0.50).abs() <= 0.05, "stopped {d:.3} m from the board");
}

/// Runs `sh -c script` as the firmware on a short approach with a 1 s watchdog; expects a
/// fault: exit code 1, `FAULT … {fault}`, the stderr tail with `last_words`, and the shell
/// and every `pid N` it printed on stderr gone.
fn assert_fault(script: &str, fault: &str, last_words: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = short_approach(tmp.path());
    let firmware = format!("sh -c '{script}'");
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--firmware",
            &firmware,
            "--duration",
            "6",
            "--watchdog",
            "1",
        ],
    );
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(1), "{text}{}", stderr(&out));
    let fault_line = text
        .lines()
        .find(|l| l.starts_with("FAULT at "))
        .unwrap_or_else(|| panic!("no FAULT line: {text}"));
    assert!(fault_line.contains(fault), "{fault_line}");
    assert!(text.contains("firmware stderr (last "), "{text}");
    assert!(text.contains(&format!("  | {last_words}")), "{text}");
    let mut pids = vec![firmware_pid(&text)];
    pids.extend(
        text.lines()
            .filter_map(|l| l.strip_prefix("  | pid ")?.parse::<u32>().ok()),
    );
    for pid in pids {
        assert!(gone(pid), "process {pid} survived: {text}");
    }
    text
}

#[test]
fn a_crashing_firmware_fails_the_run() {
    assert_fault(
        r#"cat "$HILSIM_LIDAR_PORT" >/dev/null & echo "pid $!" >&2; echo "bad config" >&2; exit 3"#,
        "the firmware crashed: exit status 3",
        "bad config",
    );
    assert_fault(
        r#"cat "$HILSIM_LIDAR_PORT" >/dev/null & echo "pid $!" >&2; echo "null pointer" >&2; kill -SEGV $$"#,
        "the firmware crashed: signal 11 (SIGSEGV)",
        "null pointer",
    );
}

#[test]
fn a_firmware_that_stops_talking_is_caught_by_the_watchdog() {
    let text = assert_fault(
        r#"cat "$HILSIM_LIDAR_PORT" >/dev/null & echo "pid $!" >&2
           printf "TestMode On\n" > "$HILSIM_ROBOT_PORT"; echo "waiting for a semaphore" >&2
           sleep 60 & echo "pid $!" >&2; wait"#,
        "the firmware hung: no request on the robot port for 1.0 s (the watchdog)",
        "waiting for a semaphore",
    );
    assert!(text.contains("requests: 1 (TestMode 1,"), "{text}");
}

#[test]
fn a_firmware_that_floods_the_port_is_stopped() {
    assert_fault(
        r#"cat "$HILSIM_LIDAR_PORT" >/dev/null & echo "pid $!" >&2
           cat "$HILSIM_ROBOT_PORT" >/dev/null & echo "pid $!" >&2
           echo "polling in a tight loop" >&2; exec yes GetMotors > "$HILSIM_ROBOT_PORT""#,
        "the firmware flooded the robot port",
        "polling in a tight loop",
    );
}

#[test]
fn a_firmware_that_never_reads_the_lidar_fails_the_run() {
    let text = assert_fault(
        r#"cat "$HILSIM_ROBOT_PORT" >/dev/null & echo "pid $!" >&2; echo "sonar only" >&2
           while :; do printf "GetSonar\n"; sleep 0.2; done > "$HILSIM_ROBOT_PORT""#,
        "the firmware never read the lidar port: it took ",
        "sonar only",
    );
    // It took nothing. The harness counts written − discarded − backlog, and the backlog it can
    // see (FIONREAD) misses bytes still in the kernel's flip buffers, which a loaded machine may
    // hold for a while: so assert the fault's own threshold, under one revolution (1,980 bytes).
    let took: u64 = text
        .split("it took ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next()?.parse().ok())
        .unwrap();
    assert!(took < 1980, "{text}");
}

#[test]
fn bad_hil_input_is_refused_before_anything_starts() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = short_approach(tmp.path());
    let scenario = scenario.to_str().unwrap();
    for (args, expected) in [
        (
            vec!["--firmware", "true", "--duration", "0"],
            "--duration must be a number of seconds",
        ),
        (
            vec!["--firmware", "true", "--watchdog", "NaN"],
            "--watchdog must be a number of seconds",
        ),
        (
            vec!["--firmware", "fw 'unterminated"],
            "unterminated ' quote",
        ),
        (
            vec!["--firmware", "  "],
            "the firmware command line is empty",
        ),
        (
            vec!["--firmware", "/nonexistent/firmware --fast"],
            "cannot start `/nonexistent/firmware`",
        ),
    ] {
        let mut all = vec!["hil", scenario];
        all.extend(args);
        let err = assert_bad_input(&hilsim(tmp.path(), &all));
        assert!(err.contains(expected), "{all:?}: {err}");
    }
    // A scenario with its own drive program and no duration_s: the firmware drives, so the
    // run needs a length.
    let board = repo_file("scenarios/straight-board.toml");
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["hil", board.to_str().unwrap(), "--firmware", "true"],
    ));
    assert!(err.contains("set `duration_s` or pass --duration"), "{err}");
}

#[test]
fn duration_makes_a_scenario_without_drive_program_or_duration_runnable() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(short_approach(tmp.path())).unwrap();
    // Without its `when = "hil"` assertion on where the robot stops (`true` drives nowhere).
    let endless = text
        .replace("duration_s = 30.0\n", "")
        .replace("when = \"hil\"", "when = \"run\"");
    assert_ne!(endless, text);
    std::fs::write(tmp.path().join("endless.toml"), endless).unwrap();
    // Validation refuses it on its own...
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &["hil", "endless.toml", "--firmware", "true"],
    ));
    assert!(err.contains("the run would have no end"), "{err}");
    // ... and --duration supplies the end. A firmware that exits at once with status 0 ends
    // the run without a fault.
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            "endless.toml",
            "--firmware",
            "true",
            "--duration",
            "2",
        ],
    );
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(0), "{text}{}", stderr(&out));
    assert!(
        text.contains("ended: the firmware exited with status 0"),
        "{text}"
    );
}

/// A `hilsim hil` started where SIGINT, SIGTERM and SIGHUP are ignored (a script's
/// background job, `nohup`) still gives its firmware the default dispositions, so the polite
/// SIGTERM at the end works and the summary says so.
#[test]
fn the_firmware_starts_with_default_signal_dispositions() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/hil-approach.toml");
    // The firmware reads the lidar (so the run has no fault), records its ignored signals and
    // waits to be told to stop.
    let firmware = r#"sh -c 'cat "$HILSIM_LIDAR_PORT" >/dev/null & grep SigIgn /proc/self/status > sigign.txt; sleep 30'"#;
    let hil = format!(
        "trap '' INT TERM HUP; exec {} hil {} --duration 1 --firmware \"$0\"",
        env!("CARGO_BIN_EXE_hilsim"),
        scenario.display()
    );
    let out = Command::new("sh")
        .args(["-c", &hil, firmware])
        .current_dir(tmp.path())
        .output()
        .unwrap();
    let text = stdout(&out);
    assert!(
        text.contains("firmware: left on SIGTERM once the run was over"),
        "{text}{}",
        stderr(&out)
    );
    let line = std::fs::read_to_string(tmp.path().join("sigign.txt")).unwrap();
    let mask = u64::from_str_radix(line.trim().trim_start_matches("SigIgn:").trim(), 16).unwrap();
    for (name, number) in [("SIGHUP", 1), ("SIGINT", 2), ("SIGTERM", 15)] {
        assert_eq!(mask & (1 << (number - 1)), 0, "{name} ignored: {line}");
    }
}

/// A daemon the firmware starts in a session of its own (out of reach of the group's
/// signals) is reported in the summary and does not outlive the run.
#[test]
fn a_daemon_that_escaped_the_firmware_is_reported_and_killed() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/hil-approach.toml");
    let firmware = r#"sh -c 'cat "$HILSIM_LIDAR_PORT" >/dev/null & setsid sleep 60 </dev/null >/dev/null 2>&1 & echo $! > daemon.pid; sleep 30'"#;
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--duration",
            "1",
            "--firmware",
            firmware,
        ],
    );
    let text = stdout(&out);
    let daemon: u32 = std::fs::read_to_string(tmp.path().join("daemon.pid"))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert!(
        text.contains(&format!(
            "firmware: 1 process(es) it started had left its process group and were still \
             running; killed: {daemon} (sleep)"
        )),
        "{text}{}",
        stderr(&out)
    );
    assert!(gone(daemon));
}

/// A firmware that reads the lidar but never drives fails the scenario's `when =
/// "hil"` assertion on where the robot stops, and, as `cat` exits 1 when its port closes at the
/// run's end, the one on its exit code: exit 1, and the summary says which.
#[test]
fn a_failed_assertion_under_hil_exits_1_and_says_which() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/hil-approach.toml");
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--duration",
            "2",
            "--firmware",
            r#"sh -c 'exec cat "$HILSIM_LIDAR_PORT" >/dev/null'"#,
        ],
    );
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(1), "{text}{}", stderr(&out));
    assert!(text.contains("FAIL sim.final_x_m = 2.5"), "{text}");
    assert!(text.contains("PASS hil.fault = 0"), "{text}");
    assert!(
        text.contains("2 of 6 assertion(s) failed: sim.final_x_m, hil.firmware_exit_code"),
        "{text}"
    );
    // `--json` ends with one object saying the same.
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--duration",
            "2",
            "--json",
            "--firmware",
            r#"sh -c 'exec cat "$HILSIM_LIDAR_PORT" >/dev/null'"#,
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    let last = stdout(&out).lines().last().unwrap().to_string();
    let j: serde_json::Value = serde_json::from_str(&last).unwrap();
    assert_eq!(j["ending"], "time_up", "{j}");
    assert_eq!(j["passed"], false, "{j}");
    assert_eq!(j["metrics"]["sim.final_x_m"], 2.5, "{j}");
    let failed: Vec<_> = j["expectations"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["passed"] == false)
        .map(|e| e["metric"].as_str().unwrap())
        .collect();
    assert_eq!(failed, ["sim.final_x_m", "hil.firmware_exit_code"]);
    assert!(j["firmware"]["status"].is_string(), "{j}");
}

/// Both example firmwares, over a link that fails as the real capture does (spin-up
/// with every other packet missing below 210 rpm, corrupted packets, a disconnection), still
/// stop half a metre from the board; the scenario's `when = "hil"` assertions hold and the
/// summary counts the faults. The start is moved to 1.5 m to keep the test short.
#[test]
fn both_example_firmwares_converge_over_the_capture_link() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo_file("scenarios/hil-capture-link.toml")).unwrap();
    let moved = text.replace("start = { x = 2.5,", "start = { x = 1.5,");
    assert_ne!(moved, text);
    std::fs::write(tmp.path().join("link.toml"), moved).unwrap();
    // `--allow-gaps`: the link drops packets by design; they are counted, not failed.
    let firmwares = [
        format!("{} --allow-gaps", example_firmware().display()),
        format!("{} --allow-gaps", c_firmware(tmp.path()).display()),
    ];
    for firmware in firmwares {
        let out = hilsim(
            tmp.path(),
            &[
                "hil",
                "link.toml",
                "--firmware",
                &firmware,
                "--duration",
                "15",
            ],
        );
        let text = stdout(&out);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{firmware}: {text}{}",
            stderr(&out)
        );
        assert!(text.contains("PASS sim.final_x_m"), "{text}");
        let faults = text
            .lines()
            .find(|l| l.starts_with("link faults: "))
            .unwrap_or_else(|| panic!("{text}"));
        assert!(
            !faults.starts_with("link faults: 0 packet(s) corrupted, 0 dropped"),
            "{faults}"
        );
    }
}

/// A firmware in Python written into `dir`, run as `python3 fw.py`: no shell stands between
/// hilsim and it, since a shell would reset what it inherits and hide a blocked signal.
fn python_firmware(dir: &Path, script: &str) -> String {
    std::fs::write(dir.join("fw.py"), script).unwrap();
    format!("python3 {}", dir.join("fw.py").display())
}

/// A firmware that writes which signals it started with blocked and ignored, then sleeps until
/// told to stop: the polite SIGTERM ends it, and the summary says so.
#[test]
fn the_firmware_starts_with_no_signal_blocked_and_leaves_on_sigterm() {
    let tmp = tempfile::tempdir().unwrap();
    let firmware = python_firmware(
        tmp.path(),
        "import re, time\n\
         status = open('/proc/self/status').read()\n\
         open('signals.txt', 'w').write(' '.join(re.findall(r'Sig(?:Blk|Ign):\\s*(\\w+)', status)))\n\
         time.sleep(30)\n",
    );
    let scenario = repo_file("scenarios/hil-approach.toml");
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--duration",
            "1",
            "--firmware",
            &firmware,
        ],
    );
    let text = stdout(&out);
    assert!(
        text.contains("firmware: left on SIGTERM once the run was over: signal 15 (SIGTERM)"),
        "{text}{}",
        stderr(&out)
    );
    let signals = std::fs::read_to_string(tmp.path().join("signals.txt")).unwrap();
    let masks: Vec<u64> = signals
        .split(' ')
        .map(|m| u64::from_str_radix(m, 16).unwrap())
        .collect();
    let [blocked, ignored] = masks[..] else {
        panic!("{signals}")
    };
    assert_eq!(blocked, 0, "{signals}");
    for (name, number) in [("SIGHUP", 1), ("SIGINT", 2), ("SIGTERM", 15)] {
        assert_eq!(
            ignored & (1 << (number - 1)),
            0,
            "{name} ignored: {signals}"
        );
    }
}

/// `hilsim hil` started with piped output, its `firmware: pid N` line read; returns the child,
/// the firmware's pid and the rest of its output once it ends.
fn start_hil(
    dir: &Path,
    firmware: &str,
) -> (std::process::Child, u32, std::thread::JoinHandle<String>) {
    use std::io::BufRead as _;
    let scenario = repo_file("scenarios/hil-approach.toml");
    let mut child = Command::new(env!("CARGO_BIN_EXE_hilsim"))
        .args(["hil", scenario.to_str().unwrap(), "--duration", "60"])
        .args(["--firmware", firmware])
        .current_dir(dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    let line = lines
        .find_map(|l| l.ok().filter(|l| l.starts_with("firmware: pid ")))
        .expect("a firmware line");
    // The rest of the output is read as it comes, so that hilsim never blocks on a full pipe.
    let rest =
        std::thread::spawn(move || lines.map_while(Result::ok).collect::<Vec<_>>().join("\n"));
    (child, firmware_pid(&line), rest)
}

/// Sends `signal` (`TERM`, `INT`…) to `pid`.
fn send(signal: &str, pid: u32) {
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &pid.to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

/// Waits up to `limit` for the child to exit.
fn wait_within(child: &mut std::process::Child, limit: Duration) -> std::process::ExitStatus {
    let deadline = std::time::Instant::now() + limit;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            panic!("still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_sigterm_to_hilsim_ends_the_run_and_the_firmware() {
    let tmp = tempfile::tempdir().unwrap();
    let firmware = python_firmware(tmp.path(), "import time\ntime.sleep(60)\n");
    let (mut child, fw, rest) = start_hil(tmp.path(), &firmware);
    std::thread::sleep(Duration::from_millis(300));
    send("TERM", child.id());
    // The ports close, 1 s for the firmware to leave by itself, then its SIGTERM.
    let status = wait_within(&mut child, Duration::from_secs(10));
    let text = rest.join().unwrap();
    assert_eq!(status.code(), Some(1), "{status}: {text}");
    assert!(text.contains("interrupted at "), "{text}");
    assert!(
        text.contains("firmware: left on SIGTERM once the run was over"),
        "{text}"
    );
    assert!(gone(fw), "firmware {fw} still runs");
}

/// A second signal while the first is being acted on ends hilsim at once, of that signal, and
/// takes the firmware (here one that ignores SIGTERM) with it.
#[test]
fn a_second_signal_ends_hilsim_at_once_with_its_firmware() {
    use std::os::unix::process::ExitStatusExt as _;
    let tmp = tempfile::tempdir().unwrap();
    let firmware = python_firmware(
        tmp.path(),
        "import signal, time\nsignal.signal(signal.SIGTERM, signal.SIG_IGN)\ntime.sleep(60)\n",
    );
    let (mut child, fw, _) = start_hil(tmp.path(), &firmware);
    std::thread::sleep(Duration::from_millis(300));
    send("INT", child.id());
    // Within the second the firmware has to leave by itself.
    std::thread::sleep(Duration::from_millis(300));
    send("TERM", child.id());
    let status = wait_within(&mut child, Duration::from_secs(5));
    assert_eq!(status.signal(), Some(15), "{status}");
    assert!(gone(fw), "firmware {fw} still runs");
}

#[test]
fn hil_out_creates_a_missing_parent_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = repo_file("scenarios/hil-approach.toml");
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--firmware",
            "true",
            "--duration",
            "1",
            "--out",
            "missing/parent/run",
        ],
    );
    assert_ne!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(Recording::read_dir(&tmp.path().join("missing/parent/run")).is_ok());
}

/// `[link] rpm_wobble` is an rpm amplitude: at or above the lidar's rpm it would stop the motor
/// (the stream's time then ran backwards, or never advanced), so it is refused with the line.
#[test]
fn a_link_wobble_as_large_as_the_rpm_is_refused_before_the_firmware_starts() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo_file("scenarios/hil-capture-link.toml")).unwrap();
    let line = text
        .lines()
        .position(|l| l == "[link]")
        .expect("a [link] table")
        + 2;
    let wobbly = text.replacen("[link]\n", "[link]\nrpm_wobble = 20000\n", 1);
    std::fs::write(tmp.path().join("wobbly.toml"), wobbly).unwrap();
    let err = assert_bad_input(&hilsim(
        tmp.path(),
        &[
            "hil",
            "wobbly.toml",
            "--firmware",
            "true",
            "--duration",
            "3",
        ],
    ));
    assert_eq!(
        err.trim_end(),
        format!(
            "hilsim: wobbly.toml:{line}: link.rpm_wobble: the wobble must be smaller than the \
             rpm ([sensors.lidar] rpm = 300), found 20000"
        )
    );
}

/// Another unit in the loop: with `model = "rplidar-a1"` the lidar port speaks the RPLIDAR's
/// protocol, and stays silent until the firmware sends SCAN; the example firmware, told its
/// robot carries an RPLIDAR, starts it, reads its nodes and stops half a metre from the board
/// as it does with the XV-11; the recording holds whole revolutions of the unit's readings.
#[test]
fn a_firmware_that_starts_its_rplidar_reaches_the_target() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = short_approach(tmp.path());
    let text = std::fs::read_to_string(&scenario).unwrap();
    let rplidar = text.replace(
        "[sensors.lidar]\n",
        "[sensors.lidar]\nmodel = \"rplidar-a1\"\n",
    );
    assert_ne!(rplidar, text);
    std::fs::write(&scenario, rplidar).unwrap();
    let firmware = format!("{} --lidar rplidar-a1", example_firmware().display());
    let out = hilsim(
        tmp.path(),
        &[
            "hil",
            scenario.to_str().unwrap(),
            "--firmware",
            &firmware,
            "--duration",
            "12",
            "--out",
            "rec",
        ],
    );
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(0), "{text}{}", stderr(&out));
    assert!(
        text.contains("example-firmware: reached the target"),
        "{text}"
    );
    assert!(text.contains("bad checksums 0"), "{text}");
    let distance = final_distance(&tmp.path().join("rec"));
    // As with the XV-11: 0.5 m, give or take a revolution's travel at the approach's speed.
    assert!((0.4..0.65).contains(&distance), "{distance}");
    let rec = Recording::read_dir(&tmp.path().join("rec")).unwrap();
    let lidar = rec.lidar.unwrap();
    // The RPLIDAR's revolutions hold about 364 readings, not the XV-11's 360 at whole degrees.
    assert!(lidar.iter().any(|r| r.angle_deg.fract() != 0.0));
}
