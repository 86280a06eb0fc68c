//! A run's report for people (the summary `hilsim run` prints) and as `results.json`.

use std::fmt::Write;

use crate::Report;

impl Report {
    /// The short human summary: what was simulated, samples per sensor, the calibrations, the
    /// checks.
    #[must_use]
    pub fn summary(&self) -> String {
        let mut out = String::new();
        // Writing to a String cannot fail.
        let _ = self.write_summary(&mut out);
        out
    }

    fn write_summary(&self, out: &mut String) -> std::fmt::Result {
        let m = &self.metrics;
        let get = |k: &str| m.get(k).copied().unwrap_or(0.0);
        // A metric that could not be computed (e.g. no truth on the serial path) reads "n/a".
        let rms = |k: &str| {
            m.get(k)
                .map_or_else(|| "n/a".to_string(), |v| format!("{v:.4} m"))
        };
        let rec = &self.run.recording;
        writeln!(
            out,
            "scenario {} (seed {}): {:.2} s simulated, robot travelled {:.3} m, {} collision(s)",
            hilsim_recording::printable(&self.scenario.name),
            self.scenario.seed,
            get("sim.duration_s"),
            get("sim.distance_m"),
            self.run.collisions.len()
        )?;
        for c in &self.run.collisions {
            writeln!(out, "  {c}")?;
        }
        if rec.lidar.is_some() {
            writeln!(
                out,
                "  lidar     {:>8} readings in {} revolutions, {:.1}% valid, range error RMS {}",
                get("lidar.readings"),
                get("lidar.revolutions"),
                100.0 * get("lidar.valid_fraction"),
                rms("lidar.rmse_m")
            )?;
        }
        if rec.sonar.is_some() {
            writeln!(
                out,
                "  sonar     {:>8} pings, range error RMS {}",
                get("sonar.readings"),
                rms("sonar.rmse_m")
            )?;
        }
        if rec.odometry.is_some() {
            writeln!(
                out,
                "  odometer  {:>8} readings, reported/true travel {}",
                get("odometer.readings"),
                m.get("odometer.scale")
                    .map_or_else(|| "n/a".to_string(), |v| format!("{v:.4}"))
            )?;
        }
        if self.calibrations.is_empty() {
            writeln!(out, "  calibration: none requested by the scenario")?;
        } else if !self.thinning.is_whole() {
            writeln!(
                out,
                "  calibrated from {} (the run is longer than a run holds in memory; the \
                 figures above count every sample)",
                self.thinning.describe()
            )?;
        }
        for calibration in &self.calibrations {
            for line in calibration.describe().lines() {
                writeln!(out, "  {line}")?;
            }
        }
        for o in &self.outcomes {
            writeln!(out, "  {}", o.describe())?;
        }
        Ok(())
    }

    /// `results.json`: the scenario, its metrics, calibrations and assertions, pretty-printed.
    #[must_use]
    pub fn results_json(&self) -> String {
        let value = serde_json::json!({
            "scenario": self.scenario.name,
            "seed": self.scenario.seed,
            "metrics": self.metrics,
            "calibrations": self.calibrations.iter().map(hilsim_calibrator::Calibration::to_json).collect::<Vec<_>>(),
            "expectations": self.outcomes,
            "passed": self.passed(),
        });
        let mut text = serde_json::to_string_pretty(&value).unwrap_or_default();
        text.push('\n');
        text
    }
}
