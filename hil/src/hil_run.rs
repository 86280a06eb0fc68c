//! Firmware in the loop (`hilsim hil`): the simulation in real time, its lidar streamed on one
//! pty, the robot command port on another, and the firmware under test as a child process
//! driving the wheels.
//!
//! One thread does it all, in a poll loop: each physics step is computed when its start time
//! comes on the wall clock (the model never reads the clock; this loop maps simulation time to
//! wall time), each lidar packet is written when its fourth reading has been taken
//! ([`Streamer::send_packet`]), and between those instants the loop sleeps in `ppoll` on the
//! command port, so a request is answered as soon as its line ends, from the sensor samples
//! taken up to that instant. A `SetMotor` takes effect at the next physics step.
//!
//! The run ends when its time is up, when the firmware exits, or at the first fault:
//! - the firmware **crashed**: it exited with a non-zero status or was killed by a signal;
//! - it **hung**: no request for the watchdog period ([`DEFAULT_WATCHDOG`], from the start and
//!   after every request);
//! - it **flooded** the command port: more than [`FloodLimits`] allow within a second;
//! - it **never read the lidar**: one watchdog period into the run it had taken less than one
//!   revolution of the stream (the streamer discards what a reader leaves behind, so this shows
//!   in its counts).
//!
//! Then the ports close (a firmware blocked on them sees them go), the firmware gets
//! [`HilConfig::firmware_grace`] to exit by itself, then `SIGTERM`, then `SIGKILL`
//! ([`Firmware::shut_down`]).

use std::collections::VecDeque;
use std::fmt;
use std::io;
use std::os::unix::io::{AsRawFd, RawFd};
use std::process::ExitStatus;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread;
use std::time::{Duration, Instant};

use hilsim_lidar_emulator::lidar::reading_period_s;
use hilsim_lidar_emulator::neato_packet::{
    rpm_to_fixed, Packet, Reading, READINGS_PER_PACKET, READINGS_PER_REVOLUTION, REVOLUTION_LEN,
};
use hilsim_lidar_emulator::wire::{to_wire, RevolutionCollector, RevolutionFrame};
use hilsim_lidar_emulator::{Emulation, LidarReading, ModelError, Run};
use hilsim_recording::{LidarSample, OdometrySample, Recording, SonarSample};
use hilsim_sim::{Scenario, Simulation};
use nix::errno::Errno;
use nix::poll::{ppoll, PollFd, PollFlags};
use nix::sys::signal::{SigSet, Signal};
use nix::sys::time::TimeSpec;

use crate::command_port::{CommandPort, CommandStats, Robot, Unavailable};
use crate::firmware::{describe_status, Firmware, FirmwareExit, StderrTail};
use crate::link::SerialLink;
use crate::motion::{MotionController, MotorRequest};
use crate::pty::PtyLink;
use crate::streamer::{Pacing, StreamStats, Streamer};

/// How long a firmware may go without a request before it counts as hung; also the time it has
/// to start reading the lidar.
pub const DEFAULT_WATCHDOG: Duration = Duration::from_secs(5);
/// How long the firmware has to exit by itself once its ports have closed.
pub const DEFAULT_FIRMWARE_GRACE: Duration = Duration::from_secs(1);
/// Replies waiting for a firmware that does not read them are capped at this many bytes; later
/// replies are dropped (and counted).
const REPLY_BACKLOG_LIMIT: usize = 256 * 1024;
/// The loop looks at the firmware and the clock at least this often.
const MAX_WAIT: Duration = Duration::from_millis(10);
/// Command-port bytes taken per pass of the loop, so a flood cannot starve the pacing.
const READ_PER_PASS: usize = 64 * 1024;
/// Resolution of the flood meter: a one-second window in ten slices.
const FLOOD_SLICE: Duration = Duration::from_millis(100);
const FLOOD_SLICES: usize = 10;

/// How much a firmware may send per second before it counts as flooding the port.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FloodLimits {
    /// Bytes per second: by default 11,520, all that 115200 baud 8N1 carries: no real serial
    /// line would deliver more.
    pub bytes_per_s: u64,
    /// Requests per second: by default 200 (a real robot answers a `GetMotors` in about
    /// 60 ms at 115200 baud; a firmware polling faster than 200 Hz is broken).
    pub commands_per_s: u64,
}

impl Default for FloodLimits {
    fn default() -> Self {
        Self {
            bytes_per_s: 11_520,
            commands_per_s: 200,
        }
    }
}

impl FloodLimits {
    /// No limits (benchmarks that measure the port flat out).
    pub const NONE: Self = Self {
        bytes_per_s: u64::MAX,
        commands_per_s: u64::MAX,
    };
}

/// How a run goes.
#[derive(Debug, Clone)]
pub struct HilConfig {
    /// The run's length (simulated = wall time).
    pub duration: Duration,
    /// See [`DEFAULT_WATCHDOG`].
    pub watchdog: Duration,
    /// See [`FloodLimits`].
    pub flood: FloodLimits,
    /// See [`DEFAULT_FIRMWARE_GRACE`].
    pub firmware_grace: Duration,
}

impl HilConfig {
    /// A run of `duration` with the default watchdog, flood limits and grace.
    #[must_use]
    pub fn new(duration: Duration) -> Self {
        Self {
            duration,
            watchdog: DEFAULT_WATCHDOG,
            flood: FloodLimits::default(),
            firmware_grace: DEFAULT_FIRMWARE_GRACE,
        }
    }
}

/// The two ports a firmware talks to: open them, start the firmware with their paths, then
/// [`run`].
pub struct HilPorts {
    lidar: PtyLink,
    robot: PtyLink,
}

impl HilPorts {
    /// Opens both pty pairs (close-on-exec, with hilsim's own client-side handles).
    ///
    /// # Errors
    /// No free pty.
    pub fn open() -> io::Result<Self> {
        Ok(Self {
            lidar: PtyLink::open()?,
            robot: PtyLink::open()?,
        })
    }

    /// The lidar port's path (`HILSIM_LIDAR_PORT`).
    #[must_use]
    pub fn lidar_path(&self) -> &str {
        self.lidar.client_path()
    }

    /// The robot command port's path (`HILSIM_ROBOT_PORT`).
    #[must_use]
    pub fn robot_path(&self) -> &str {
        self.robot.client_path()
    }
}

/// A firmware fault: the run failed its check.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Fault {
    /// The firmware exited with a non-zero status or was killed by a signal.
    Crashed(ExitStatus),
    /// No request for the watchdog period.
    Hung {
        /// The watchdog period.
        watchdog: Duration,
    },
    /// Too much sent within a second.
    Flooded {
        /// Bytes received in the last second.
        bytes: u64,
        /// Requests received in the last second.
        commands: u64,
        /// The limits exceeded.
        limits: FloodLimits,
    },
    /// Less than one revolution of the lidar stream read.
    LidarNeverRead {
        /// Bytes the firmware took from the lidar port.
        bytes_read: u64,
        /// Bytes written to it.
        bytes_written: u64,
    },
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Crashed(status) => {
                write!(f, "the firmware crashed: {}", describe_status(*status))
            }
            Self::Hung { watchdog } => write!(
                f,
                "the firmware hung: no request on the robot port for {:.1} s (the watchdog)",
                watchdog.as_secs_f64()
            ),
            Self::Flooded {
                bytes,
                commands,
                limits,
            } => write!(
                f,
                "the firmware flooded the robot port: {bytes} bytes and {commands} requests in \
                 one second (limits: {} bytes/s, the line rate of 115200 8N1, and {} requests/s)",
                limits.bytes_per_s, limits.commands_per_s
            ),
            Self::LidarNeverRead {
                bytes_read,
                bytes_written,
            } => write!(
                f,
                "the firmware never read the lidar port: it took {bytes_read} of the \
                 {bytes_written} bytes streamed (less than one revolution); the rest was discarded"
            ),
        }
    }
}

/// Why the run ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Ending {
    /// The run's time was up.
    TimeUp,
    /// The firmware exited with status 0.
    FirmwareExited,
    /// A firmware fault.
    Fault(Fault),
    /// The caller's stop flag was raised (Ctrl-C).
    Stopped,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct HilReport {
    /// Why it ended.
    pub ending: Ending,
    /// When it ended, seconds from the start.
    pub ended_at_s: f64,
    /// Simulated seconds (the last physics step may end up to one step after `ended_at_s`).
    pub simulated_s: f64,
    /// The recording (truth included; the commands as the motion controller issued them) and
    /// the collisions.
    pub run: Run,
    /// The command port's counts.
    pub commands: CommandStats,
    /// Replies dropped because the firmware did not read the earlier ones.
    pub replies_dropped: u64,
    /// The lidar stream's counts.
    pub stream: StreamStats,
    /// Bytes of the lidar stream the firmware took (`None` without a lidar).
    pub lidar_bytes_read: Option<u64>,
    /// How late the latest physics step was computed after its start time: real-time health.
    pub max_step_lateness: Duration,
    /// How the firmware ended (`None`: the run had none).
    pub firmware: Option<FirmwareExit>,
    /// The end of the firmware's stderr.
    pub stderr: StderrTail,
}

impl HilReport {
    /// The fault, if the run ended on one.
    #[must_use]
    pub fn fault(&self) -> Option<&Fault> {
        match &self.ending {
            Ending::Fault(fault) => Some(fault),
            _ => None,
        }
    }
}

/// Blocks `SIGINT`, `SIGTERM` and `SIGHUP` in the calling thread and raises `stop` whenever one
/// arrives, so that a run interrupted at the terminal still shuts its firmware down (the
/// firmware runs in its own process group, out of reach of the terminal's Ctrl-C). Call it
/// before any other thread is started: threads inherit the mask (child processes do not; the
/// standard library clears it for them).
///
/// # Errors
/// The mask cannot be set or the waiting thread started.
pub fn stop_on_signals(stop: Arc<AtomicBool>) -> io::Result<()> {
    let mut signals = SigSet::empty();
    for signal in [Signal::SIGINT, Signal::SIGTERM, Signal::SIGHUP] {
        signals.add(signal);
    }
    signals.thread_block().map_err(io::Error::from)?;
    thread::Builder::new()
        .name("hil-signals".into())
        .spawn(move || {
            while signals.wait().is_ok() {
                stop.store(true, Ordering::Relaxed);
            }
        })?;
    Ok(())
}

/// The scenario's world and sensors with the wheels left to the firmware: its drive program is
/// not run.
pub struct HilWorld {
    emulation: Emulation,
    sonar_period_s: Option<f64>,
    odometer: bool,
}

impl HilWorld {
    /// The scenario's world with its sensors, every random stream drawn from `seed`, driven
    /// from outside (`Simulation::externally_driven`).
    ///
    /// # Errors
    /// A sensor's range model makes no sense.
    pub fn new(scenario: &Scenario, seed: u64) -> Result<Self, ModelError> {
        let sim = Simulation::externally_driven(scenario);
        Ok(Self {
            emulation: Emulation::with_simulation(scenario, seed, sim)?,
            sonar_period_s: scenario.sensors.sonar.as_ref().map(|s| 1.0 / s.rate_hz),
            odometer: scenario.sensors.odometer.is_some(),
        })
    }
}

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
    let HilPorts { lidar, robot } = ports;
    let mut firmware = firmware;
    let streamer = Streamer::new(lidar, Pacing::Realtime);
    let mut session = Session::new(world, streamer, robot, config);
    let ending = session.run(firmware.as_mut(), stop)?;
    session.finish(ending, firmware)
}

/// The sensor samples taken so far: the recording's rows and what the command port answers
/// from.
struct Sensors {
    lidar: Option<Vec<LidarSample>>,
    sonar: Option<Vec<SonarSample>>,
    odometry: Option<Vec<OdometrySample>>,
    sonar_period_s: f64,
    /// Recent complete revolutions with the instant each was complete, oldest first.
    frames: VecDeque<(f64, RevolutionFrame)>,
    lidar_rpm: Option<f64>,
}

/// The robot as the command port sees it at `now_s` (simulation seconds).
struct RobotView<'a> {
    now_s: f64,
    sensors: &'a Sensors,
    motion: &'a mut MotionController,
}

impl Robot for RobotView<'_> {
    fn set_motor(&mut self, request: MotorRequest) {
        self.motion.start(request);
    }

    fn stop_motors(&mut self) {
        self.motion.stop();
    }

    fn wheel_positions_mm(&self) -> Option<[i64; 2]> {
        let odometry = self.sensors.odometry.as_ref()?;
        let latest = odometry.iter().rev().find(|s| s.t_s <= self.now_s);
        Some(latest.map_or([0, 0], |s| {
            [
                (s.left_m * 1000.0).round() as i64,
                (s.right_m * 1000.0).round() as i64,
            ]
        }))
    }

    fn lds_rpm(&self) -> Option<f64> {
        self.sensors.lidar_rpm
    }

    fn lds_scan(&self) -> Result<&RevolutionFrame, Unavailable> {
        if self.sensors.lidar.is_none() {
            return Err(Unavailable::NoSensor);
        }
        self.sensors
            .frames
            .iter()
            .rev()
            .find(|(complete_s, _)| *complete_s <= self.now_s)
            .map(|(_, frame)| frame)
            .ok_or(Unavailable::NotYet)
    }

    fn sonar_mm(&self) -> Result<Option<u32>, Unavailable> {
        let sonar = self.sensors.sonar.as_ref().ok_or(Unavailable::NoSensor)?;
        // Pings with no echo leave no sample: the latest ping had an echo only if the latest
        // sample is less than a ping period old.
        Ok(sonar
            .iter()
            .rev()
            .find(|s| s.t_s <= self.now_s)
            .filter(|s| self.now_s - s.t_s < self.sensors.sonar_period_s)
            .map(|s| (s.range_m * 1000.0).round() as u32))
    }
}

/// Four consecutive readings into one packet, as the lidar takes them.
#[derive(Default)]
struct PacketBuilder {
    rev: u64,
    readings: [Reading; READINGS_PER_PACKET],
    filled: usize,
}

impl PacketBuilder {
    fn push(&mut self, reading: &LidarReading, rpm: f64) -> Option<Packet> {
        let slot = usize::from(reading.angle_deg) % READINGS_PER_PACKET;
        if slot == 0 || reading.rev != self.rev {
            self.rev = reading.rev;
            self.filled = 0;
        }
        self.readings[slot] = to_wire(reading);
        self.filled += 1;
        (slot == READINGS_PER_PACKET - 1 && self.filled == READINGS_PER_PACKET).then(|| Packet {
            index: u8::try_from(usize::from(reading.angle_deg) / READINGS_PER_PACKET).unwrap_or(0),
            rpm_fixed: rpm_to_fixed(rpm),
            readings: self.readings,
        })
    }
}

/// Requests and bytes in the last second.
#[derive(Default)]
struct FloodMeter {
    slices: [(u64, u64); FLOOD_SLICES],
    current: u64,
}

impl FloodMeter {
    /// Adds to the slice of `elapsed` and returns the totals of the last second.
    fn add(&mut self, elapsed: Duration, bytes: u64, commands: u64) -> (u64, u64) {
        let slice = (elapsed.as_millis() / FLOOD_SLICE.as_millis()) as u64;
        let stale = slice.saturating_sub(self.current).min(FLOOD_SLICES as u64);
        for k in 1..=stale {
            self.slices[((self.current + k) % FLOOD_SLICES as u64) as usize] = (0, 0);
        }
        self.current = self.current.max(slice);
        let entry = &mut self.slices[(self.current % FLOOD_SLICES as u64) as usize];
        entry.0 += bytes;
        entry.1 += commands;
        self.slices
            .iter()
            .fold((0, 0), |(b, c), (sb, sc)| (b + sb, c + sc))
    }
}

/// The loop's state.
struct Session<'c> {
    emulation: Emulation,
    streamer: Streamer<PtyLink>,
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
    packets: PacketBuilder,
    collector: RevolutionCollector,
    /// Packets waiting for their time, with the simulation instant each is due.
    due_packets: VecDeque<(f64, Packet)>,
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
    fn new(
        world: HilWorld,
        streamer: Streamer<PtyLink>,
        mut robot: PtyLink,
        config: &'c HilConfig,
    ) -> Self {
        let HilWorld {
            emulation,
            sonar_period_s,
            odometer,
        } = world;
        let step_s = emulation.simulation().step_s();
        let sensors = Sensors {
            lidar: emulation.lidar().map(|_| Vec::new()),
            sonar: sonar_period_s.map(|_| Vec::new()),
            odometry: odometer.then(Vec::new),
            sonar_period_s: sonar_period_s.unwrap_or(1.0),
            frames: VecDeque::new(),
            lidar_rpm: emulation.lidar().map(|l| l.rpm_of_revolution(0)),
        };
        let robot_fd = robot.master().as_raw_fd();
        let now = Instant::now();
        Self {
            end_steps: (config.duration.as_secs_f64() / step_s).round() as u64,
            emulation,
            streamer,
            robot,
            robot_fd,
            config,
            origin: now,
            step_s,
            steps_done: 0,
            motion: MotionController::new(),
            port: CommandPort::new(),
            sensors,
            packets: PacketBuilder::default(),
            collector: RevolutionCollector::default(),
            due_packets: VecDeque::new(),
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
    ) -> io::Result<Ending> {
        self.origin = Instant::now();
        self.last_request = self.origin;
        loop {
            let now = Instant::now();
            self.simulate_until(now);
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
            for reading in &self.readings {
                let rpm = lidar.rpm_of_revolution(reading.rev);
                // A packet leaves, and a revolution is complete, when its last reading's
                // period has passed (as `Streamer::send` paces them).
                let complete_s = reading.t_s + reading_period_s(rpm);
                if let Some(rows) = &mut self.sensors.lidar {
                    rows.push(reading.to_sample());
                }
                if let Some(packet) = self.packets.push(reading, rpm) {
                    self.due_packets.push_back((complete_s, packet));
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

    /// Writes every lidar packet whose time has come.
    fn send_due_packets(&mut self, now: Instant) -> io::Result<()> {
        while let Some(&(due_s, packet)) = self.due_packets.front() {
            let due = self.wall(due_s);
            if due > now {
                break;
            }
            self.due_packets.pop_front();
            self.streamer.send_packet(&packet, due)?;
        }
        Ok(())
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
        let backlog = self.streamer.link().backlog()? as u64;
        let stats = self.streamer.stats();
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
        let bytes_written = self.streamer.stats().bytes_written;
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
        if let Some(&(due_s, _)) = self.due_packets.front() {
            next = next.min(self.wall(due_s));
        }
        let timeout = next.saturating_duration_since(Instant::now());
        let mut events = PollFlags::POLLIN;
        if self.replies_sent < self.replies.len() {
            events |= PollFlags::POLLOUT;
        }
        let mut fds = [PollFd::new(self.robot_fd, events)];
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
        let stream = self.streamer.stats().clone();
        // The ports close before the firmware is asked to leave: a firmware blocked on one sees
        // it go and can exit by itself.
        drop(self.streamer);
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
            rows.truncate(rows.len() - rows.len() % READINGS_PER_REVOLUTION);
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
            stream,
            lidar_bytes_read,
            max_step_lateness: self.max_step_lateness,
            firmware,
            stderr,
        })
    }
}
