//! The self-test's report: one JSON object, or text for a person.

use std::fmt::Write;

use serde_json::{json, Value};

use super::score::median;
use super::trial::{label, verdict_label};
use super::SelfTest;
use crate::{Effect, Verdict};

impl SelfTest {
    /// The whole self-test as one JSON object (`command`: how to reproduce it; `wall_s`: how
    /// long it took).
    #[must_use]
    pub fn to_json(&self, command: &str, wall_s: f64) -> Value {
        let s = &self.score;
        let trials: Vec<_> = self
            .outcomes
            .iter()
            .map(|o| {
                json!({
                    "trial": o.index,
                    "truth": label(o.truth),
                    "drawn": o.drawn.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                    "verdict": verdict_label(&o.verdict),
                    "refusal": o.verdict.as_ref().err(),
                    "fitted": o.fitted.iter().copied().filter(|v| v.is_finite()).collect::<Vec<_>>(),
                    "param_error": o.param_error.filter(|v| v.is_finite()),
                    "heldout_after_over_floor": o.heldout.map(|h| h.0).filter(|v| v.is_finite()),
                    "heldout_before_over_floor": o.heldout.map(|h| h.1).filter(|v| v.is_finite()),
                    "strongest_score": o.strongest.0.is_finite().then_some(o.strongest.0),
                    "threshold": o.strongest.1.is_finite().then_some(o.strongest.1),
                    "seconds": o.seconds,
                })
            })
            .collect();
        let finite = |v: f64| v.is_finite().then_some(v);
        json!({
            "command": command,
            "scenario": self.scenario,
            "trials": trials,
            "confusion": {"rows": s.classes, "columns": s.columns, "counts": s.matrix},
            "correct": s.correct, "with_effect": s.with_effect, "correct_share": finite(s.correct_share()),
            "false_alarms": s.false_alarms, "without_effect": s.without_effect, "false_alarm_share": finite(s.false_alarm_share()),
            "param_within_20pct": s.param_within, "param_scored": s.param_scored, "param_median_error": finite(s.param_median_error),
            "heldout_within_1_2": s.heldout_within, "heldout_scored": s.heldout_scored, "heldout_median_ratio": finite(s.heldout_median_ratio),
            "pass": s.passed(),
            "wall_s": wall_s,
        })
    }

    /// The self-test for a person: the confusion matrix, each goal, the misses.
    #[must_use]
    pub fn to_text(&self, command: &str, wall_s: f64) -> String {
        let mut out = String::new();
        // Writing to a String cannot fail.
        let _ = self.write_text(&mut out, command, wall_s);
        out
    }

    fn write_text(&self, out: &mut String, command: &str, wall_s: f64) -> std::fmt::Result {
        writeln!(
            out,
            "self-test: {} blind trials of `{}`, seed {}, strength {} ({wall_s:.0} s)",
            self.outcomes.len(),
            self.scenario,
            self.seed,
            self.strength
        )?;
        self.write_confusion(out)?;
        self.write_goals(out)?;
        let misses: Vec<String> = self
            .outcomes
            .iter()
            .filter(|o| match (&o.verdict, o.truth) {
                (Ok(Verdict::Effect(v)), Some(t)) => *v != t,
                (Ok(Verdict::None), None) => false,
                _ => true,
            })
            .map(|o| {
                format!(
                    "trial {}: {} → {}",
                    o.index,
                    label(o.truth),
                    match &o.verdict {
                        Ok(v) => v.name().to_string(),
                        Err(e) => format!("refused ({e})"),
                    }
                )
            })
            .collect();
        if !misses.is_empty() {
            writeln!(out, "misses: {}", misses.join("; "))?;
        }
        writeln!(out, "reproduce: {command}")?;
        Ok(())
    }

    fn write_confusion(&self, out: &mut String) -> std::fmt::Result {
        let s = &self.score;
        writeln!(out, "confusion (rows: concealed effect; columns: verdict)")?;
        // Columns by code (E1…E9 the catalogue in order), rows by name.
        let code = |i: usize, c: &str| -> String {
            match c {
                "none" => "none".into(),
                "unexplained" => "unexpl".into(),
                "refused" => "refused".into(),
                _ => format!("E{i}"),
            }
        };
        write!(out, "{:>26}", "")?;
        for (i, c) in s.columns.iter().enumerate() {
            write!(out, " {:>7}", code(i, c))?;
        }
        writeln!(out)?;
        for (r, row) in s.matrix.iter().enumerate() {
            let name = if r == 0 {
                "none".to_string()
            } else {
                format!("E{r} {}", s.classes[r])
            };
            write!(out, "{name:>26}")?;
            for v in row {
                write!(out, " {v:>7}")?;
            }
            writeln!(out)?;
        }
        Ok(())
    }

    fn write_goals(&self, out: &mut String) -> std::fmt::Result {
        let s = &self.score;
        let pct = |v: f64| {
            if v.is_finite() {
                format!("{:.1} %", 100.0 * v)
            } else {
                "—".into()
            }
        };
        let verdict = |i: usize| {
            if !s.measured[i] {
                "not measured (no trial)"
            } else if s.pass[i] {
                "goal met"
            } else {
                "GOAL MISSED"
            }
        };
        writeln!(
            out,
            "named correctly: {}/{} concealed effects ({}; goal ≥ 95 %): {}",
            s.correct,
            s.with_effect,
            pct(s.correct_share()),
            verdict(0)
        )?;
        writeln!(
            out,
            "false alarms: {}/{} recordings without an effect ({}; goal ≤ 5 %): {}",
            s.false_alarms,
            s.without_effect,
            pct(s.false_alarm_share()),
            verdict(1)
        )?;
        writeln!(
            out,
            "parameter recovery: {}/{} within 20 % of the truth (median error {}): {}",
            s.param_within,
            s.param_scored,
            pct(s.param_median_error),
            verdict(2)
        )?;
        for e in Effect::ALL {
            let mut errs: Vec<f64> = self
                .outcomes
                .iter()
                .filter(|o| o.truth == Some(e))
                .filter_map(|o| o.param_error)
                .collect();
            if errs.is_empty() {
                continue;
            }
            let worst = errs.iter().copied().fold(0.0, f64::max);
            let m = median(&mut errs);
            writeln!(
                out,
                "  {:<22} median {:>7}, worst {:>7} over {}",
                e.name(),
                pct(m),
                pct(worst),
                errs.len()
            )?;
        }
        writeln!(
            out,
            "held-out RMSE after the fix / noise floor: {}/{} within 1.2 (median {}): {}",
            s.heldout_within,
            s.heldout_scored,
            if s.heldout_median_ratio.is_finite() {
                format!("{:.3}", s.heldout_median_ratio)
            } else {
                "—".to_string()
            },
            verdict(3)
        )?;
        Ok(())
    }
}
