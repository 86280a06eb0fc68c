//! The loop: each physics step computed when its start time comes on the wall clock, each lidar
//! packet written when due, and requests answered in between.

use std::collections::VecDeque;
use std::io;
use std::os::unix::io::{AsRawFd, RawFd};
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::{Duration, Instant};

use hilsim_lidar_emulator::lidar::reading_period_s;
use hilsim_lidar_emulator::neato_packet::{READINGS_PER_REVOLUTION, REVOLUTION_LEN};
use hilsim_lidar_emulator::wire::RevolutionCollector;
use hilsim_lidar_emulator::{Emulation, LidarReading, Run};
use hilsim_recording::Recording;
use nix::errno::Errno;
use nix::poll::{ppoll, PollFd, PollFlags};
use nix::sys::time::TimeSpec;

use super::config::HilConfig;
use super::flood::FloodMeter;
use super::lidar_wire::LidarWire;
use super::report::{Ending, Fault, HilReport};
use super::sensors::{RobotView, Sensors};
use super::setup::{HilPorts, HilWorld};
use crate::command_port::CommandPort;
use crate::firmware::{Firmware, StderrTail};
use crate::motion::MotionController;
use crate::pty::PtyLink;

/// Replies waiting for a firmware that does not read them are capped at this many bytes; later
/// replies are dropped (and counted).
const REPLY_BACKLOG_LIMIT: usize = 256 * 1024;

/// The loop looks at the firmware and the clock at least this often.
const MAX_WAIT: Duration = Duration::from_millis(10);

/// Command-port bytes taken per pass of the loop, so a flood cannot starve the pacing.
const READ_PER_PASS: usize = 64 * 1024;

/// Runs the firmware in the loop until the time is up, the firmware exits, a fault, or `stop`.
/// `firmware`, when given, was started with the paths of `ports`; it is shut down before this
/// returns, and killed if this fails.
///
/// # Errors
/// A port or the firmware's process failed.
pub fn run(
    world: HilWorld,
    ports: HilPorts,
    firmware: Option<Firmware>,
    config: &HilConfig,
    stop: &AtomicBool,
) -> io::Result<HilReport> {
    run_with_progress(world, ports, firmware, config, stop, &mut |_| {})
}

/// How far a run has come, for a status line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HilProgress {
    /// Simulated time, seconds.
    pub t_s: f64,
    /// Lidar revolutions written whole.
    pub revolutions_sent: u64,
    /// Lidar revolutions thrown away (the firmware did not read them in time).
    pub revolutions_dropped: u64,
    /// Requests the command port answered.
    pub requests: u64,
}

impl HilProgress {
    /// One line for a status line: how far a run of `total_s` seconds has come.
    #[must_use]
    pub fn describe(&self, total_s: f64) -> String {
        format!(
            "{:.1} of {total_s:.1} s, {} requests, {} lidar revolutions sent, {} dropped",
            self.t_s, self.requests, self.revolutions_sent, self.revolutions_dropped
        )
    }
}

/// Simulated time between two calls of a run's progress callback, seconds.
const PROGRESS_EVERY_S: f64 = 0.1;

/// As [`run`], telling `progress` how far the run has come every 0.1 s of simulated time.
///
/// # Errors
/// As [`run`].
pub fn run_with_progress(
    world: HilWorld,
    ports: HilPorts,
    firmware: Option<Firmware>,
    config: &HilConfig,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(&HilProgress),
) -> io::Result<HilReport> {
    let HilPorts { lidar, robot } = ports;
    let mut firmware = firmware;
    let mut world = world;
    let model = world
        .emulation
        .lidar()
        .map(hilsim_lidar_emulator::Lidar::unit)
        .unwrap_or_default();
    let wire = LidarWire::new(lidar, model, world.wire_faults.take());
    let mut session = Session::new(world, wire, robot, config);
    let ending = session.run(firmware.as_mut(), stop, progress)?;
    session.finish(ending, firmware)
}

/// The loop's state.
struct Session<'c> {
    emulation: Emulation,
    wire: LidarWire,
    robot: PtyLink,
    robot_fd: RawFd,
    config: &'c HilConfig,
    origin: Instant,
    step_s: f64,
    steps_done: u64,
    end_steps: u64,
    motion: MotionController,
    port: CommandPort,
    sensors: Sensors,
    collector: RevolutionCollector,
    readings: Vec<LidarReading>,
    replies: Vec<u8>,
    replies_sent: usize,
    replies_dropped: u64,
    flood: FloodMeter,
    last_request: Instant,
    lidar_checked: bool,
    max_step_lateness: Duration,
}

impl<'c> Session<'c> {
    fn new(world: HilWorld, wire: LidarWire, mut robot: PtyLink, config: &'c HilConfig) -> Self {
        let HilWorld {
            emulation,
            sonar_period_s,
            odometer,
            ..
        } = world;
        let step_s = emulation.simulation().step_s();
        let sensors = Sensors {
            lidar: emulation.lidar().map(|_| Vec::new()),
            sonar: sonar_period_s.map(|_| Vec::new()),
            odometry: odometer.then(Vec::new),
            sonar_period_s: sonar_period_s.unwrap_or(1.0),
            frames: VecDeque::new(),
            lidar_rpm: emulation.lidar().map(|l| l.rpm_of_revolution(0)),
            xv11: wire.is_xv11(),
        };
        let robot_fd = robot.master().as_raw_fd();
        let now = Instant::now();
        Self {
            end_steps: (config.duration.as_secs_f64() / step_s).round() as u64,
            emulation,
            wire,
            robot,
            robot_fd,
            config,
            origin: now,
            step_s,
            steps_done: 0,
            motion: MotionController::new(),
            port: CommandPort::new(),
            sensors,
            collector: RevolutionCollector::default(),
            readings: Vec::new(),
            replies: Vec::new(),
            replies_sent: 0,
            replies_dropped: 0,
            flood: FloodMeter::default(),
            last_request: now,
            lidar_checked: false,
            max_step_lateness: Duration::ZERO,
        }
    }

    /// The wall-clock instant of simulation time `t_s`.
    fn wall(&self, t_s: f64) -> Instant {
        self.origin + Duration::from_secs_f64(t_s.max(0.0))
    }

    fn run(
        &mut self,
        mut firmware: Option<&mut Firmware>,
        stop: &AtomicBool,
        progress: &mut dyn FnMut(&HilProgress),
    ) -> io::Result<Ending> {
        self.origin = Instant::now();
        self.wire.start(self.origin);
        self.last_request = self.origin;
        let steps_per_progress = ((PROGRESS_EVERY_S / self.step_s).round() as u64).max(1);
        let mut progress_steps = 0;
        loop {
            let now = Instant::now();
            self.simulate_until(now);
            if self.steps_done >= progress_steps + steps_per_progress {
                progress_steps = self.steps_done;
                let stream = self.wire.stats();
                progress(&HilProgress {
                    t_s: self.steps_done as f64 * self.step_s,
                    revolutions_sent: stream.revolutions_sent,
                    revolutions_dropped: stream.revolutions_dropped,
                    requests: self.port.stats().requests,
                });
            }
            self.send_due_packets(now)?;
            if let Some(fault) = self.serve_requests(now)? {
                return Ok(Ending::Fault(fault));
            }
            self.flush_replies()?;
            if stop.load(Ordering::Relaxed) {
                return Ok(Ending::Stopped);
            }
            if let Some(fw) = firmware.as_deref_mut() {
                if let Some(status) = fw.try_exit()? {
                    return Ok(if status.success() {
                        Ending::FirmwareExited
                    } else {
                        Ending::Fault(Fault::Crashed(status))
                    });
                }
            }
            if now.duration_since(self.last_request) >= self.config.watchdog {
                return Ok(Ending::Fault(Fault::Hung {
                    watchdog: self.config.watchdog,
                }));
            }
            let end = self.origin + self.config.duration;
            if !self.lidar_checked && now.duration_since(self.origin) >= self.config.watchdog {
                if let Some(fault) = self.check_lidar_read(0)? {
                    return Ok(Ending::Fault(fault));
                }
            }
            if self.steps_done >= self.end_steps && now >= end {
                if !self.lidar_checked {
                    // A run shorter than the watchdog: judge it if the firmware had two
                    // revolutions' time to read.
                    if let Some(fault) = self.check_lidar_read(2 * REVOLUTION_LEN as u64)? {
                        return Ok(Ending::Fault(fault));
                    }
                }
                return Ok(Ending::TimeUp);
            }
            self.wait(now, end)?;
        }
    }

    /// Computes every physics step whose start time has come.
    fn simulate_until(&mut self, now: Instant) {
        while self.steps_done < self.end_steps {
            let start = self.wall(self.steps_done as f64 * self.step_s);
            if start > now {
                return;
            }
            self.max_step_lateness = self.max_step_lateness.max(now - start);
            let command = self.motion.next_step(self.step_s);
            self.emulation.simulation_mut().set_command(command);
            let Some(samples) = self.emulation.step() else {
                return;
            };
            self.steps_done += 1;
            self.readings.clear();
            self.readings.extend_from_slice(&samples.lidar);
            if let Some(rows) = &mut self.sensors.sonar {
                rows.extend_from_slice(&samples.sonar);
            }
            if let Some(rows) = &mut self.sensors.odometry {
                rows.extend_from_slice(&samples.odometry);
            }
            let Some(lidar) = self.emulation.lidar() else {
                continue;
            };
            let xv11 = self.wire.is_xv11();
            for reading in &self.readings {
                let rpm = if xv11 {
                    lidar.rpm_of_revolution(reading.rev)
                } else {
                    reading.rev_hz * 60.0
                };
                // A revolution is complete when its last reading's period has passed.
                let complete_s = reading.t_s + reading_period_s(rpm);
                if let Some(rows) = &mut self.sensors.lidar {
                    rows.push(reading.to_sample());
                }
                self.wire.take(reading, rpm);
                if !xv11 {
                    self.sensors.lidar_rpm = Some(rpm);
                    continue;
                }
                if let Some(frame) = self.collector.push(reading, rpm) {
                    self.sensors.frames.push_back((complete_s, frame));
                    if self.sensors.frames.len() > 3 {
                        self.sensors.frames.pop_front();
                    }
                }
                self.sensors.lidar_rpm = Some(rpm);
            }
        }
    }

    /// Writes every lidar packet whose time has come (answering the firmware's commands to a
    /// unit that takes them).
    fn send_due_packets(&mut self, now: Instant) -> io::Result<()> {
        self.wire.send_due(self.origin, now)
    }

    /// Reads what the firmware sent and answers it; a flood ends the run.
    fn serve_requests(&mut self, now: Instant) -> io::Result<Option<Fault>> {
        let now_s = now.duration_since(self.origin).as_secs_f64();
        let mut buf = [0u8; 4096];
        let mut taken = 0;
        let mut fresh = Vec::new();
        while taken < READ_PER_PASS {
            let n = match nix::unistd::read(self.robot_fd, &mut buf) {
                Ok(0) | Err(Errno::EAGAIN) => break,
                Ok(n) => n,
                Err(Errno::EINTR) => continue,
                Err(err) => return Err(io::Error::from(err)),
            };
            taken += n;
            fresh.clear();
            let mut view = RobotView {
                now_s,
                sensors: &self.sensors,
                motion: &mut self.motion,
            };
            let answered = self.port.feed(&buf[..n], &mut view, &mut fresh);
            if answered > 0 {
                self.last_request = now;
            }
            if self.replies.len() - self.replies_sent + fresh.len() > REPLY_BACKLOG_LIMIT {
                self.replies_dropped += answered as u64;
            } else {
                self.replies.extend_from_slice(&fresh);
            }
            let (bytes, commands) =
                self.flood
                    .add(now.duration_since(self.origin), n as u64, answered as u64);
            let limits = self.config.flood;
            if bytes > limits.bytes_per_s || commands > limits.commands_per_s {
                return Ok(Some(Fault::Flooded {
                    bytes,
                    commands,
                    limits,
                }));
            }
        }
        Ok(None)
    }

    /// Writes as much of the pending replies as the port takes now.
    fn flush_replies(&mut self) -> io::Result<()> {
        while self.replies_sent < self.replies.len() {
            match nix::unistd::write(self.robot_fd, &self.replies[self.replies_sent..]) {
                Ok(n) => self.replies_sent += n,
                Err(Errno::EAGAIN) => break,
                Err(Errno::EINTR) => {}
                Err(err) => return Err(io::Error::from(err)),
            }
        }
        if self.replies_sent == self.replies.len() {
            self.replies.clear();
            self.replies_sent = 0;
        }
        Ok(())
    }

    /// The bytes of the lidar stream the firmware took so far. The pty moves what was just
    /// written to the client side a moment later (a kernel worker does it), and a packet in
    /// flight is not in the backlog yet: give it a millisecond. Once per run, and at the end.
    fn lidar_bytes_read(&mut self) -> io::Result<u64> {
        thread::sleep(Duration::from_millis(1));
        let backlog = self.wire.backlog()? as u64;
        let stats = self.wire.stats();
        Ok(stats
            .bytes_written
            .saturating_sub(stats.bytes_discarded)
            .saturating_sub(backlog))
    }

    /// Once per run: a fault if the firmware took less than one revolution of the lidar stream
    /// while at least `min_written` bytes were streamed.
    fn check_lidar_read(&mut self, min_written: u64) -> io::Result<Option<Fault>> {
        self.lidar_checked = true;
        if self.sensors.lidar.is_none() {
            return Ok(None);
        }
        if self.wire.waiting_for_start() {
            // A unit the firmware never started sent nothing it could read.
            return Ok(Some(Fault::LidarNeverRead {
                bytes_read: 0,
                bytes_written: 0,
            }));
        }
        let bytes_written = self.wire.stats().bytes_written;
        let bytes_read = self.lidar_bytes_read()?;
        Ok(
            (bytes_written >= min_written && bytes_read < REVOLUTION_LEN as u64).then_some(
                Fault::LidarNeverRead {
                    bytes_read,
                    bytes_written,
                },
            ),
        )
    }

    /// Sleeps until the next thing to do, waking at once for a request (or for room to write
    /// pending replies).
    fn wait(&mut self, now: Instant, end: Instant) -> io::Result<()> {
        let mut next = (now + MAX_WAIT)
            .min(end)
            .min(self.last_request + self.config.watchdog);
        if self.steps_done < self.end_steps {
            next = next.min(self.wall(self.steps_done as f64 * self.step_s));
        }
        if let Some(due_s) = self.wire.next_due_s() {
            next = next.min(self.wall(due_s));
        }
        let timeout = next.saturating_duration_since(Instant::now());
        let mut events = PollFlags::POLLIN;
        if self.replies_sent < self.replies.len() {
            events |= PollFlags::POLLOUT;
        }
        let mut fds = vec![PollFd::new(self.robot_fd, events)];
        if let Some(fd) = self.wire.command_fd() {
            fds.push(PollFd::new(fd, PollFlags::POLLIN));
        }
        match ppoll(&mut fds, Some(TimeSpec::from_duration(timeout)), None) {
            Ok(_) | Err(Errno::EINTR) => Ok(()),
            Err(err) => Err(io::Error::from(err)),
        }
    }

    /// Closes the ports, shuts the firmware down and assembles the report.
    fn finish(mut self, ending: Ending, firmware: Option<Firmware>) -> io::Result<HilReport> {
        let ended_at_s = self.origin.elapsed().as_secs_f64();
        let lidar_bytes_read = match self.sensors.lidar {
            Some(_) => Some(self.lidar_bytes_read()?),
            None => None,
        };
        let stream = self.wire.stats().clone();
        let link_faults = self.wire.fault_counts();
        // The ports close before the firmware is asked to leave: a firmware blocked on one sees
        // it go and can exit by itself.
        drop(self.wire);
        drop(self.robot);
        let (firmware, stderr) = match firmware {
            Some(mut fw) => {
                let exit = fw.shut_down(self.config.firmware_grace)?;
                (Some(exit), fw.stderr_tail())
            }
            None => (None, StderrTail::default()),
        };
        let simulated_s = self.emulation.simulation().time_s();
        let (commands, truth, collisions) = self.emulation.simulation_mut().take_logs();
        let mut lidar = self.sensors.lidar;
        if let Some(rows) = &mut lidar {
            // Whole revolutions only, as `Emulation::run` records them.
            match self.emulation.lidar() {
                Some(l) if l.readings_per_revolution().is_none() => {
                    if !l.revolution_done() {
                        let last = rows.last().map(|r| r.rev);
                        while rows.last().is_some_and(|r| Some(r.rev) == last) {
                            rows.pop();
                        }
                    }
                }
                _ => rows.truncate(rows.len() - rows.len() % READINGS_PER_REVOLUTION),
            }
        }
        Ok(HilReport {
            ending,
            ended_at_s,
            simulated_s,
            run: Run {
                recording: Recording {
                    meta: self.emulation.meta().clone(),
                    commands,
                    odometry: self.sensors.odometry,
                    lidar,
                    sonar: self.sensors.sonar,
                    truth: Some(truth),
                },
                collisions,
            },
            commands: self.port.stats().clone(),
            replies_dropped: self.replies_dropped,
            link_faults,
            stream,
            lidar_bytes_read,
            max_step_lateness: self.max_step_lateness,
            firmware,
            stderr,
        })
    }
}
