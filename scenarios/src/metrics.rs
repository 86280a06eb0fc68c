//! The metrics a run produces (the catalogue is `hilsim_sim::scenario::metrics::METRICS`) and the
//! check of a scenario's `[[expect]]` assertions against them.

use std::collections::BTreeMap;

use hilsim_hil::hil_run::HilReport;
use hilsim_lidar_emulator::Run;
use hilsim_recording::{
    CommandSample, LidarSample, OdometrySample, Recording, SampleSink, SonarSample, TruthSample,
};
use hilsim_sim::scenario::{self, Expect, ExpectWhen};

/// Metric name → value. Only metrics that could be computed are present.
pub type Metrics = BTreeMap<String, f64>;

/// The metrics of a finished run.
#[must_use]
pub fn of_run(run: &Run) -> Metrics {
    let rec = &run.recording;
    let mut m = RunMetrics::default();
    let Ok(()) = feed(rec, &mut m);
    m.finish(run.collisions.len())
}

/// Hands every sample of `rec` to `sink`, table after table.
fn feed<S: SampleSink>(rec: &Recording, sink: &mut S) -> Result<(), S::Error> {
    for c in &rec.commands {
        sink.command(c)?;
    }
    for o in rec.odometry.iter().flatten() {
        sink.odometry(o)?;
    }
    for r in rec.lidar.iter().flatten() {
        sink.lidar(r)?;
    }
    for p in rec.sonar.iter().flatten() {
        sink.sonar(p)?;
    }
    for p in rec.truth.iter().flatten() {
        sink.truth(p)?;
    }
    Ok(())
}

/// The metrics of a run, taken as its samples arrive (a [`SampleSink`]), so that a run of any
/// length is measured in bounded memory: sums, counts and the last samples, nothing a table
/// long. Sums are taken in the samples' order, so a run measured as it goes and measured from
/// its recording give the same numbers to the bit.
#[derive(Debug, Default)]
pub struct RunMetrics {
    tables: Tables,
    truth: Option<(TruthSample, TruthSample)>,
    /// The true path's length, and its length up to the latest odometry reading (each true
    /// step whose start is before that reading's time), with the steps after it.
    path: Option<f64>,
    path_to_odometry: Option<f64>,
    steps_after_odometry: std::collections::VecDeque<(f64, f64)>,
    last_odometry: Option<OdometrySample>,
    odometry: usize,
    lidar: usize,
    lidar_valid: usize,
    lidar_last: Option<LidarSample>,
    lidar_error: (f64, usize),
    sonar: usize,
    sonar_error: (f64, usize),
}

/// Whether each optional table was seen.
#[derive(Debug, Default)]
struct Tables {
    odometry: bool,
    lidar: bool,
    sonar: bool,
}

impl RunMetrics {
    /// The metrics, with the run's count of `collisions`.
    #[must_use]
    pub fn finish(mut self, collisions: usize) -> Metrics {
        let mut m = Metrics::new();
        let mut put = |name: &str, value: f64| {
            if value.is_finite() {
                m.insert(name.to_string(), value);
            }
        };
        let empty_sum = || std::iter::empty::<f64>().sum::<f64>();
        if let Some((first, last)) = self.truth {
            put("sim.duration_s", last.t_s - first.t_s);
            put("sim.final_x_m", last.x_m);
            put("sim.final_y_m", last.y_m);
            put("sim.final_yaw_deg", last.yaw_rad.to_degrees());
        }
        if self.truth.is_some() || self.path.is_some() {
            put("sim.distance_m", self.path.unwrap_or_else(empty_sum));
        }
        put("sim.collisions", collisions as f64);
        if self.tables.lidar {
            put("lidar.readings", self.lidar as f64);
            let revs = self
                .lidar_last
                .map_or(0, |r| r.rev + u64::from(r.angle_deg == 359.0));
            put("lidar.revolutions", revs as f64);
            if self.lidar > 0 {
                put(
                    "lidar.valid_fraction",
                    self.lidar_valid as f64 / self.lidar as f64,
                );
            }
            put("lidar.rmse_m", rms(self.lidar_error));
        }
        if self.tables.sonar {
            put("sonar.readings", self.sonar as f64);
            put("sonar.rmse_m", rms(self.sonar_error));
        }
        if self.tables.odometry {
            put("odometer.readings", self.odometry as f64);
            if let (Some(last), Some(_)) = (self.last_odometry, self.truth) {
                // True wheel travel is not in the recording; the mean of the wheels' reported
                // travel over the true path length is the scale for straight runs (turns cancel
                // out).
                self.catch_up_to_odometry();
                let reported = (last.left_m.abs() + last.right_m.abs()) / 2.0;
                let true_path = self.path_to_odometry.unwrap_or_else(empty_sum);
                if true_path > 0.01 {
                    put("odometer.scale", reported / true_path);
                }
            }
        }
        m
    }

    /// Counts into the path to the latest odometry reading every true step that starts before
    /// it, in order.
    fn catch_up_to_odometry(&mut self) {
        let Some(t) = self.last_odometry.map(|o| o.t_s) else {
            return;
        };
        while let Some(&(start, d)) = self.steps_after_odometry.front() {
            if start >= t {
                break;
            }
            self.steps_after_odometry.pop_front();
            add(&mut self.path_to_odometry, d);
        }
    }
}

/// `sum + d`, the sum starting as an empty sum of floats does.
fn add(sum: &mut Option<f64>, d: f64) {
    let s = sum.get_or_insert_with(|| std::iter::empty::<f64>().sum::<f64>());
    *s += d;
}

impl SampleSink for RunMetrics {
    type Error = std::convert::Infallible;
    fn command(&mut self, _: &CommandSample) -> Result<(), Self::Error> {
        Ok(())
    }
    fn odometry(&mut self, o: &OdometrySample) -> Result<(), Self::Error> {
        self.tables.odometry = true;
        self.odometry += 1;
        self.last_odometry = Some(*o);
        self.catch_up_to_odometry();
        Ok(())
    }
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Self::Error> {
        self.tables.lidar = true;
        self.lidar += 1;
        self.lidar_last = Some(*r);
        if !r.invalid {
            self.lidar_valid += 1;
            if let Some(t) = r.true_range_m {
                let e = r.range_m - t;
                self.lidar_error = (self.lidar_error.0 + e * e, self.lidar_error.1 + 1);
            }
        }
        Ok(())
    }
    fn sonar(&mut self, p: &SonarSample) -> Result<(), Self::Error> {
        self.tables.sonar = true;
        self.sonar += 1;
        if let Some(t) = p.true_range_m {
            let e = p.range_m - t;
            self.sonar_error = (self.sonar_error.0 + e * e, self.sonar_error.1 + 1);
        }
        Ok(())
    }
    fn truth(&mut self, p: &TruthSample) -> Result<(), Self::Error> {
        match &mut self.truth {
            None => self.truth = Some((*p, *p)),
            Some((_, last)) => {
                let d = (p.x_m - last.x_m).hypot(p.y_m - last.y_m);
                let start = last.t_s;
                *last = *p;
                add(&mut self.path, d);
                let before_odometry = self.last_odometry.is_some_and(|o| start < o.t_s);
                if self.steps_after_odometry.is_empty() && before_odometry {
                    add(&mut self.path_to_odometry, d);
                } else {
                    self.steps_after_odometry.push_back((start, d));
                }
            }
        }
        Ok(())
    }
}

/// The metrics of one calibration: `<method>.lidar.mse_ratio` and friends (see the catalogue).
#[must_use]
pub fn of_calibration(c: &hilsim_calibrator::Calibration) -> Metrics {
    let mut m = Metrics::new();
    let method = c.method.name();
    let mut put = |name: &str, value: f64| {
        if value.is_finite() {
            m.insert(format!("{method}.{name}"), value);
        }
    };
    put("iterations", c.iterations as f64);
    put("converged", f64::from(u8::from(c.converged)));
    if let Some(order) = c.order {
        put("order", order as f64);
    }
    put("checks_failed", c.failed_checks().count() as f64);
    if let Some(o) = &c.odometry {
        put("left_wheel_radius_m", o.left_wheel_radius_m);
        put("right_wheel_radius_m", o.right_wheel_radius_m);
        put("wheel_base_m", o.wheel_base_m);
        put("lidar_x_m", o.lidar_x_m);
        put("lidar_y_m", o.lidar_y_m);
        put("lidar_yaw_deg", o.lidar_yaw_rad.to_degrees());
    }
    if let Some(metrics) = c.metrics {
        put("lidar.mse_raw", metrics.mse_raw);
        put("lidar.mse_calibrated", metrics.mse_calibrated);
        put("lidar.mse_ratio", metrics.mse_ratio());
        put("lidar.nmse_raw", metrics.nmse_raw);
        put("lidar.nmse_calibrated", metrics.nmse_calibrated);
        if let Some(l) = metrics.lidar_model {
            put("lidar_model.mse_raw", l.mse_raw);
            put("lidar_model.mse_calibrated", l.mse_calibrated);
            put("lidar_model.mse_ratio", l.mse_ratio);
        }
    }
    m
}

/// The root mean square of errors summed as (sum of squares, count); NaN for none.
fn rms((sum, n): (f64, usize)) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        (sum / n as f64).sqrt()
    }
}

/// The outcome of one assertion.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Outcome {
    /// The metric asserted on.
    pub metric: String,
    /// Its value, when it could be computed.
    pub value: Option<f64>,
    /// The assertion's lower bound.
    pub at_least: Option<f64>,
    /// The assertion's upper bound.
    pub at_most: Option<f64>,
    /// Whether the value was computed and within the bounds (true when skipped).
    pub passed: bool,
    /// Why the assertion was not checked in this kind of run, when it was not: a metric of
    /// another kind (a firmware's session under `run`, a calibration under `hil`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skipped: Option<&'static str>,
}

impl Outcome {
    /// One line for people: `PASS lidar.readings = 72000 (expected ≥ 1000)`, with the value's
    /// unit.
    #[must_use]
    pub fn describe(&self) -> String {
        let bounds: Vec<String> = [
            self.at_least.map(|v| format!("≥ {v}")),
            self.at_most.map(|v| format!("≤ {v}")),
        ]
        .into_iter()
        .flatten()
        .collect();
        if let Some(why) = self.skipped {
            return format!(
                "SKIP {} (expected {}): {why}",
                self.metric,
                bounds.join(" and ")
            );
        }
        let value = self.value.map_or_else(
            || "not computed".to_string(),
            |v| format!("{}{}", readable(v), unit(&self.metric)),
        );
        format!(
            "{} {} = {value} (expected {})",
            if self.passed { "PASS" } else { "FAIL" },
            self.metric,
            bounds.join(" and ")
        )
    }
}

/// The kind of run an assertion is checked in: each skips the metrics of the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunKind {
    /// `hilsim run` and `scenario test`: the drive program, then the calibrations.
    Scripted,
    /// `hilsim hil`: a firmware drives; there is no calibration.
    FirmwareInTheLoop,
}

impl RunKind {
    /// Why the assertion `e` is not checked in this kind of run, if it is not.
    fn skips(self, e: &Expect) -> Option<&'static str> {
        let metric = e.metric.as_str();
        match (self, e.when) {
            (Self::Scripted, ExpectWhen::Hil) => {
                return Some("`when = \"hil\"`: checked under `hilsim hil`")
            }
            (Self::FirmwareInTheLoop, ExpectWhen::Run) => {
                return Some("`when = \"run\"`: checked under `hilsim run` and `scenario test`")
            }
            _ => {}
        }
        match self {
            Self::Scripted if scenario::metrics::is_hil(metric) => {
                Some("a firmware's session metric; checked under `hilsim hil`")
            }
            Self::FirmwareInTheLoop if scenario::metrics::is_calibration(metric) => {
                Some("a calibration metric; `hilsim hil` runs no calibration")
            }
            _ => None,
        }
    }
}

/// A value for people: a count as a whole number, anything else to six significant digits
/// without trailing zeros (`150`, `0.0123457`, `4.12409`).
fn readable(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        return format!("{v:.0}");
    }
    let magnitude = if v == 0.0 {
        0
    } else {
        v.abs().log10().floor() as i32
    };
    let decimals = usize::try_from((5 - magnitude).max(0)).unwrap_or(0);
    let text = format!("{v:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// The unit a metric's name says it is in (the catalogue's convention: `_m`, `_s`, `_deg`, MSEs
/// in m²), with a leading space; none for counts and ratios.
fn unit(metric: &str) -> &'static str {
    if metric.ends_with("mse_raw") || metric.ends_with("mse_calibrated") {
        " m²"
    } else if metric.ends_with("_m") {
        " m"
    } else if metric.ends_with("_s") {
        " s"
    } else if metric.ends_with("_deg") {
        "°"
    } else {
        ""
    }
}

/// Checks every assertion; a metric that was not computed fails its assertion, unless it
/// belongs to another kind of run (then the assertion is skipped, and says so).
#[must_use]
pub fn check(expects: &[Expect], metrics: &Metrics, kind: RunKind) -> Vec<Outcome> {
    expects
        .iter()
        .map(|e| {
            let skipped = kind.skips(e);
            let value = metrics.get(&e.metric).copied();
            let passed = skipped.is_some()
                || value.is_some_and(|v| {
                    e.at_least.is_none_or(|lo| v >= lo) && e.at_most.is_none_or(|hi| v <= hi)
                });
            Outcome {
                metric: e.metric.clone(),
                value,
                at_least: e.at_least,
                at_most: e.at_most,
                passed,
                skipped,
            }
        })
        .collect()
}

/// Bytes of one revolution on the wire: 90 packets of 22 bytes (docs/formats/neato-xv11.md).
const REVOLUTION_BYTES: u64 = 90 * 22;

/// The metrics of a firmware-in-the-loop run: the run's own ([`of_run`]; its recording is the
/// truth and what the sensors took) and the firmware's session ([`scenario::metrics::HIL_METRICS`]).
#[must_use]
pub fn of_hil(report: &HilReport) -> Metrics {
    let mut m = of_run(&report.run);
    let mut put = |name: &str, value: f64| {
        if value.is_finite() {
            m.insert(name.to_string(), value);
        }
    };
    if let Some(read) = report.lidar_bytes_read {
        put(
            "hil.lidar_revolutions_read",
            (read / REVOLUTION_BYTES) as f64,
        );
        put(
            "hil.lidar_revolutions_dropped",
            report.stream.revolutions_dropped as f64,
        );
    }
    let c = &report.commands;
    put("hil.requests", c.requests as f64);
    put("hil.command_errors", c.errors as f64);
    put("hil.set_motor", c.set_motor as f64);
    put("hil.fault", f64::from(u8::from(report.fault().is_some())));
    if let Some(code) = report.firmware.as_ref().and_then(|f| f.status.code()) {
        put("hil.firmware_exit_code", f64::from(code));
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_read_as_counts_or_six_significant_digits_with_their_unit() {
        assert_eq!(readable(0.0), "0");
        assert_eq!(readable(150.0), "150");
        assert_eq!(readable(4.124_093_2), "4.12409");
        assert_eq!(readable(0.012_345_678), "0.0123457");
        assert_eq!(readable(-179.999_991), "-180");
        assert_eq!(readable(2.5), "2.5");
        assert_eq!(unit("sim.final_x_m"), " m");
        assert_eq!(unit("em.lidar.mse_raw"), " m²");
        assert_eq!(unit("em.lidar.mse_ratio"), "");
        assert_eq!(unit("sim.final_yaw_deg"), "°");
    }
}
