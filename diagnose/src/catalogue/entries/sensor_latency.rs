//! `sensor_latency`: a sensor's driver stamps its readings later than it measures them. One
//! catalogue entry, fitted in each sensor where a mismatch is located and reporting that
//! sensor's delay only, since each sensor's driver stamps its own readings.

use hilsim_sim::scenario::Effects;

use super::super::entry::{Entry, Variable};
use super::super::params::{lin, ParamSpec, SelfTestRange as R};
use super::super::sensor::Sensor;

/// `sensor_latency` of one sensor.
pub(crate) struct SensorLatency(pub(crate) Sensor);

/// The lidar's `sensor_latency`.
static LIDAR: SensorLatency = SensorLatency(Sensor::Lidar);
/// The sonar's `sensor_latency`.
static SONAR: SensorLatency = SensorLatency(Sensor::Sonar);
/// The odometer's `sensor_latency`.
static ODOMETER: SensorLatency = SensorLatency(Sensor::Odometer);
/// The drive's, which has none of its own (its commands are stamped when issued).
static DRIVE: SensorLatency = SensorLatency(Sensor::Drive);

impl SensorLatency {
    /// The `sensor_latency` of `sensor`.
    pub(crate) fn of(sensor: Sensor) -> &'static SensorLatency {
        match sensor {
            Sensor::Lidar => &LIDAR,
            Sensor::Sonar => &SONAR,
            Sensor::Odometer => &ODOMETER,
            Sensor::Drive => &DRIVE,
        }
    }
}

impl Entry for SensorLatency {
    fn name(&self) -> &'static str {
        "sensor_latency"
    }

    fn label(&self) -> String {
        format!("{} ({})", self.name(), self.0)
    }

    fn sensor(&self) -> Sensor {
        self.0
    }

    /// The stamps, and how far the robot moves (and, for the lidar's bearings, turns) between
    /// a reading and its stamp.
    fn variables(&self) -> &'static [Variable] {
        match self.0 {
            Sensor::Lidar => &[Variable::Time, Variable::WheelSpeed, Variable::Turn],
            Sensor::Sonar | Sensor::Odometer => &[Variable::Time, Variable::WheelSpeed],
            Sensor::Drive => &[],
        }
    }

    /// A delay of its stamps.
    fn sized_as_a_delay(&self) -> bool {
        true
    }

    /// The lidar's: the matching puts each pose at the scan's late stamp, so the lidar fits and
    /// the sonar and the encoders, judged along a path that runs late, show the delay (the
    /// encoders as a lead proportional to the wheel speed, a slip's signature; the sonar as a
    /// range error proportional to the speed), on any path.
    fn seen_through_path(&self, _: f64) -> bool {
        self.0 == Sensor::Lidar
    }

    /// The self-test draws a latency of [0.02, 0.08] s.
    fn params(&self) -> &'static [ParamSpec] {
        // A delay of up to 0.3 s (a driver buffering a whole revolution of a 5 Hz lidar is
        // 0.2 s) on a 0.02 s grid.
        const LIDAR_LATENCY: [ParamSpec; 1] =
            [lin("lidar_s", "s", (0.0, 0.3), 16, R::uniform(0.02, 0.08)).searched_from_zero()];
        const SONAR_LATENCY: [ParamSpec; 1] =
            [lin("sonar_s", "s", (0.0, 0.3), 16, R::uniform(0.02, 0.08)).searched_from_zero()];
        const ODOMETER_LATENCY: [ParamSpec; 1] =
            [lin("odometer_s", "s", (0.0, 0.3), 16, R::uniform(0.02, 0.08)).searched_from_zero()];
        match self.0 {
            Sensor::Lidar => &LIDAR_LATENCY,
            Sensor::Sonar => &SONAR_LATENCY,
            Sensor::Odometer => &ODOMETER_LATENCY,
            // The drive's commands are stamped when issued: no latency of its own.
            Sensor::Drive => &[],
        }
    }

    /// 5 ms, 1.5 mm of motion at 0.3 m/s.
    fn least_departures(&self) -> &'static [(usize, f64)] {
        &[(0, 0.005)]
    }

    /// Sets its sensor's delay only, keeping the others' in the table.
    fn apply(&self, params: &[f64], effects: &mut Effects) {
        let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
        // A delay is never negative: the fit's range starts at 0.
        let delay = p(0).max(0.0);
        let mut l = effects.sensor_latency.unwrap_or_default();
        match self.0 {
            Sensor::Lidar => l.lidar_s = delay,
            Sensor::Sonar => l.sonar_s = delay,
            Sensor::Odometer => l.odometer_s = delay,
            Sensor::Drive => {}
        }
        effects.sensor_latency = Some(l);
    }

    fn explanation(&self, params: &[f64], _: f64) -> String {
        let p = |i: usize| params.get(i).copied().unwrap_or(f64::NAN);
        let sensor = self.0;
        format!(
            "The simulated {sensor} is stamped when it measures; the real one's timestamps \
             come {:.0} ms later.",
            p(0) * 1000.0
        )
    }
}
