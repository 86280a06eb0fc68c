//! The revolutions of a unit other than the XV-11 as the scans its head takes: a grid unit's
//! steps at fixed angles, or a free-running unit's samples, whose angles and number change from
//! revolution to revolution (a fixed sample rate on a motor whose speed wanders).

use hilsim_lidar_protocols::{Direction, LidarModel, Sampling, UnitSpec};
use hilsim_sim::scan_schedule::Scan;
use hilsim_sim::{rng, scenario};
use rand::Rng as _;
use rand_distr::{Distribution, StandardNormal};

/// Revolutions per period of the rate wobble, as the XV-11's (`lidar.rs`).
const WOBBLE_PERIOD_REVS: f64 = 10.0;

/// A unit's revolutions, generated one at a time as the head reaches them.
#[derive(Debug, Clone)]
pub(crate) struct UnitScans {
    spec: &'static UnitSpec,
    rpm: f64,
    rpm_wobble: f64,
    /// `[link] spin_up_s`: the motor spins up from [`scenario::SPIN_UP_FROM_RPM`] to `rpm`,
    /// linearly in time, over this long (0: it starts at speed).
    spin_up_s: f64,
    wobble_phase: f64,
    motor: rng::Rng,
    /// The revolution being taken.
    current: Scan,
    /// Its rate, Hz.
    current_hz: f64,
    /// When the next revolution's first reading is taken, and (free-running units) its angle
    /// in the unit's convention, degrees in [0, one sample's step).
    next_t_s: f64,
    next_angle_deg: f64,
    /// Where the head is when sampling starts (free-running units).
    first_angle_deg: f64,
}

impl UnitScans {
    /// The revolutions of `model` turning at `rpm` (with a slow sinusoidal wobble of
    /// `rpm_wobble`), its motor's randomness drawn from the run's `lidar.motor` stream.
    pub(crate) fn new(model: LidarModel, rpm: f64, rpm_wobble: f64, seed: u64) -> Self {
        let mut motor = rng::stream(seed, "lidar.motor");
        let wobble_phase = motor.random::<f64>() * std::f64::consts::TAU;
        let first_angle = motor.random::<f64>();
        let mut scans = Self {
            spec: model.spec(),
            rpm,
            rpm_wobble,
            spin_up_s: 0.0,
            wobble_phase,
            motor,
            current: Scan {
                t_s: 0.0,
                rev: 0,
                beams: 1,
                first_deg: 0.0,
                step_deg: 1.0,
                beam_period_s: 0.0,
            },
            current_hz: rpm / 60.0,
            next_t_s: 0.0,
            next_angle_deg: 0.0,
            first_angle_deg: 0.0,
        };
        if matches!(scans.spec.sampling, Sampling::FreeRunning { .. }) {
            // The head is anywhere when sampling starts: the first revolution is partial.
            scans.first_angle_deg = 360.0 * first_angle;
            scans.next_angle_deg = scans.first_angle_deg;
        }
        scans.current = scans.make(0);
        scans
    }

    /// The same revolutions with the motor spinning up over `spin_up_s` after power-on, and
    /// turning with a wobble of `rpm_wobble` (the `[link]` table's), from the start again.
    pub(crate) fn with_link(mut self, spin_up_s: f64, rpm_wobble: f64) -> Self {
        self.spin_up_s = spin_up_s;
        self.rpm_wobble = rpm_wobble;
        self.next_t_s = 0.0;
        self.next_angle_deg = self.first_angle_deg;
        self.current = self.make(0);
        self
    }

    /// The revolution being taken.
    pub(crate) fn current(&self) -> &Scan {
        &self.current
    }

    /// The rate of the revolution being taken, Hz.
    pub(crate) fn current_hz(&self) -> f64 {
        self.current_hz
    }

    /// Moves on to the next revolution.
    pub(crate) fn advance(&mut self) {
        self.current = self.make(self.current.rev + 1);
    }

    /// Revolution `rev`, starting at the state left by the one before.
    fn make(&mut self, rev: u64) -> Scan {
        let phase = std::f64::consts::TAU * rev as f64 / WOBBLE_PERIOD_REVS + self.wobble_phase;
        let jitter: f64 = StandardNormal.sample(&mut self.motor);
        // Spinning up: each revolution at the speed of its start.
        let speed = if self.next_t_s < self.spin_up_s && self.rpm > scenario::SPIN_UP_FROM_RPM {
            let from = scenario::SPIN_UP_FROM_RPM;
            from + (self.rpm - from) * self.next_t_s / self.spin_up_s
        } else {
            self.rpm
        };
        let rpm = (speed * (1.0 + self.spec.rev_hz_jitter * jitter)
            + self.rpm_wobble * phase.sin())
        .max(speed * 0.5);
        let hz = rpm / 60.0;
        self.current_hz = hz;
        // Angles in hilsim's frame grow counter-clockwise; a clockwise unit's grow the other way.
        let sign = match self.spec.direction {
            Direction::CounterClockwise => 1.0,
            Direction::Clockwise => -1.0,
        };
        let t_s = self.next_t_s;
        match self.spec.sampling {
            Sampling::Grid {
                steps_per_rev,
                first,
                last,
                zero,
            } => {
                let step_deg = 360.0 / f64::from(steps_per_rev);
                let beam_period_s = 1.0 / (hz * f64::from(steps_per_rev));
                // `next_t_s` is when the head passes step 0; the first step read comes later.
                self.next_t_s = t_s + 1.0 / hz;
                Scan {
                    t_s: t_s + f64::from(first) * beam_period_s,
                    rev,
                    beams: last - first + 1,
                    first_deg: sign * (f64::from(first) - f64::from(zero)) * step_deg,
                    step_deg: sign * step_deg,
                    beam_period_s,
                }
            }
            Sampling::FreeRunning { sample_rate_hz } => {
                let beam_period_s = 1.0 / sample_rate_hz;
                let step_deg = 360.0 * hz * beam_period_s;
                let start = self.next_angle_deg;
                // Every sample whose angle is short of a whole turn belongs to this revolution.
                let beams = ((360.0 - start) / step_deg).ceil().max(1.0);
                self.next_angle_deg = (start + beams * step_deg - 360.0).max(0.0);
                self.next_t_s = t_s + beams * beam_period_s;
                Scan {
                    t_s,
                    rev,
                    beams: beams as u32,
                    first_deg: sign * start,
                    step_deg: sign * step_deg,
                    beam_period_s,
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn revolutions(model: LidarModel, n: usize) -> Vec<(Scan, f64)> {
        let spec = model.spec();
        let mut scans = UnitScans::new(model, spec.rev_hz * 60.0, 0.0, 3);
        (0..n)
            .map(|_| {
                let r = (*scans.current(), scans.current_hz());
                scans.advance();
                r
            })
            .collect()
    }

    #[test]
    fn a_free_running_unit_samples_continuously_and_its_readings_per_revolution_vary() {
        let revs = revolutions(LidarModel::Ld06, 50);
        // 4,500 samples a second at 10 Hz: about 450 a revolution, not always the same.
        let counts: Vec<u32> = revs.iter().skip(1).map(|(s, _)| s.beams).collect();
        assert!(
            counts.iter().all(|&n| (440..=460).contains(&n)),
            "{counts:?}"
        );
        assert!(counts.iter().any(|&n| n != counts[0]), "{counts:?}");
        for pair in revs.windows(2) {
            let (a, b) = (&pair[0].0, &pair[1].0);
            // The next revolution's first sample is one sample period after this one's last.
            let gap = b.t_s - a.beam_time_s(a.beams - 1);
            assert!((gap - 1.0 / 4500.0).abs() < 1e-9, "{gap}");
            // Clockwise: angles fall in hilsim's frame, and the revolution starts just past 0°.
            assert!(b.step_deg < 0.0);
            assert!(b.first_deg <= 0.0 && b.first_deg > b.step_deg, "{b:?}");
        }
    }

    #[test]
    fn a_spinning_up_motor_turns_slowly_first_and_takes_more_readings_a_revolution() {
        let spec = LidarModel::Ld06.spec();
        let mut scans =
            UnitScans::new(LidarModel::Ld06, spec.rev_hz * 60.0, 0.0, 3).with_link(2.0, 0.0);
        let mut first = Vec::new();
        while scans.current().t_s < 3.0 {
            first.push((
                scans.current().t_s,
                scans.current_hz(),
                scans.current().beams,
            ));
            scans.advance();
        }
        // From 50 rpm (0.83 Hz) to 10 Hz within 2 s, each revolution at the speed of its start,
        // then at speed (the jitter is a few tenths of a percent). The first revolution is
        // partial; the first whole one, at about 3 Hz, takes some 1,400 samples, not 450.
        assert!(first[0].1 < 0.84, "{first:?}");
        assert!(first[1].1 < 4.0 && first[1].2 > 1_000, "{first:?}");
        let (t_last, hz_last, beams_last) = *first.last().unwrap();
        assert!(t_last > 2.0 && (hz_last - 10.0).abs() < 0.1, "{first:?}");
        assert!((440..=460).contains(&beams_last));
        assert!(
            first.windows(2).all(|w| w[0].1 <= w[1].1 * 1.01),
            "{first:?}"
        );
    }

    #[test]
    fn a_grid_unit_reads_its_steps_at_fixed_angles() {
        let revs = revolutions(LidarModel::Urg04lx, 3);
        for (k, (scan, hz)) in revs.iter().enumerate() {
            assert_eq!(scan.beams, 682);
            // Step 44 is 340 steps of 360/1024° right of forward; counter-clockwise.
            assert!((scan.first_deg - -119.53125).abs() < 1e-9);
            assert!((scan.beam_deg(340) - 0.0).abs() < 1e-6);
            assert!((hz - 10.0).abs() < 1e-12);
            let rev_start = k as f64 * 0.1;
            assert!((scan.t_s - (rev_start + 44.0 * 0.1 / 1024.0)).abs() < 1e-12);
        }
    }
}
