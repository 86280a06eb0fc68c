//! What a run is set up from: the two ports the firmware talks to, the scenario's world driven
//! from outside, and the signals that stop a run at the terminal.

use std::io;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread;

use hilsim_lidar_emulator::{Emulation, ModelError};
use hilsim_sim::{Scenario, Simulation};
use nix::sys::signal::{self, SigHandler, SigSet, Signal};

use crate::firmware::kill_all_running;
use crate::pty::PtyLink;

/// The two ports a firmware talks to: open them, start the firmware with their paths, then
/// [`run`].
pub struct HilPorts {
    pub(super) lidar: PtyLink,
    pub(super) robot: PtyLink,
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

/// The scenario's world and sensors with the wheels left to the firmware: its drive program is
/// not run.
pub struct HilWorld {
    pub(super) emulation: Emulation,
    pub(super) sonar_period_s: Option<f64>,
    pub(super) odometer: bool,
    /// The scenario's `[link]` faults on the lidar's wire.
    pub(super) wire_faults: Option<crate::faults::WireFaults>,
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
            // Validation has checked the table: its faults resolve.
            wire_faults: crate::faults::WireFaults::new(
                &scenario.link.faults().unwrap_or_default(),
                seed,
            ),
        })
    }
}

/// Blocks `SIGINT`, `SIGTERM` and `SIGHUP` in the calling thread and raises `stop` when one
/// arrives, so that a run interrupted at the terminal still shuts its firmware down (the
/// firmware runs in its own process group, out of reach of the terminal's Ctrl-C). A second
/// one, once `stop` is raised, ends the process at once: every running firmware is killed with
/// its group ([`kill_all_running`]), then the process dies of that signal. Call it
/// before any other thread is started: threads inherit the mask (so do child processes;
/// [`Firmware::spawn`](crate::firmware::Firmware::spawn) clears it for the firmware).
///
/// The three signals' dispositions are set to the default first. A process started in the
/// background of a script, or under `nohup`, inherits them *ignored*; an ignored signal is
/// discarded even while blocked, so the wait would never see it, and the firmware would inherit
/// the ignoring too (ignored dispositions survive `exec`) and shrug off the polite `SIGTERM`.
///
/// # Errors
/// The mask cannot be set or the waiting thread started.
pub fn stop_on_signals(stop: Arc<AtomicBool>) -> io::Result<()> {
    let mut signals = SigSet::empty();
    for which in [Signal::SIGINT, Signal::SIGTERM, Signal::SIGHUP] {
        // SAFETY: `SIG_DFL` installs no handler, so nothing runs in signal context; the
        // disposition is process-wide state that this function owns (see above).
        #[allow(unsafe_code)]
        unsafe { signal::signal(which, SigHandler::SigDfl) }.map_err(io::Error::from)?;
        signals.add(which);
    }
    signals.thread_block().map_err(io::Error::from)?;
    thread::Builder::new()
        .name("hil-signals".into())
        .spawn(move || {
            while let Ok(which) = signals.wait() {
                if stop.swap(true, Ordering::Relaxed) {
                    kill_all_running();
                    die_of(which);
                }
            }
        })?;
    Ok(())
}

/// Ends the process as `signal` does by default (the caller's parent sees how it ended): the
/// signal is unblocked in this thread and raised. The dispositions were set to the default.
fn die_of(signal: Signal) -> ! {
    let mut only = SigSet::empty();
    only.add(signal);
    let _ = only.thread_unblock();
    let _ = signal::raise(signal);
    // Not reached unless the disposition was changed since: the shell's code for the signal.
    std::process::exit(128 + signal as i32)
}
