//! The self-test's report: one JSON object, or text for a person.

use std::fmt::Write;

use serde_json::{json, Value};

use super::draw::OUTSIDE;
use super::plan::Reality;
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
                    "second": o.second.map(Effect::name),
                    "outside": o.outside,
                    "named": o.named.iter().map(|e| e.name()).collect::<Vec<_>>(),
                    "unexplained": o.unexplained,
                    "param_errors": o.param_errors.iter().map(|(e, v)| (e.name().to_string(), json!(v.is_finite().then_some(*v)))).collect::<serde_json::Map<_, _>>(),
                    "drawn": o.drawn.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                    "forms": o.forms,
                    "verdict": verdict_label(&o.verdict),
                    "refusal": o.verdict.as_ref().err(),
                    "fitted": o.fitted.iter().copied().filter(|v| v.is_finite()).collect::<Vec<_>>(),
                    "param_error": o.param_error.filter(|v| v.is_finite()),
                    "heldout_after_over_floor": o.heldout.map(|h| h.0).filter(|v| v.is_finite()),
                    "heldout_before_over_floor": o.heldout.map(|h| h.1).filter(|v| v.is_finite()),
                    "strongest_score": o.strongest.0.is_finite().then_some(o.strongest.0),
                    "threshold": o.strongest.1.is_finite().then_some(o.strongest.1),
                    "seconds": o.seconds,
                    "redrawn": o.redrawn,
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
            "outside_unexplained": s.outside_unexplained, "outside": s.outside,
            "named": s.named, "improved": s.improved, "two": s.two, "two_named": s.two_named,
            "reality": self.reality.name(),
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
            "self-test: {} blind trials of `{}` on the {} reality, seed {}, strength {} ({wall_s:.0} s)",
            self.outcomes.len(),
            self.scenario,
            self.reality.name(),
            self.seed,
            self.strength
        )?;
        let redrawn: Vec<String> = self
            .outcomes
            .iter()
            .filter(|o| o.redrawn > 0)
            .map(|o| format!("{} ({}×)", o.index, o.redrawn))
            .collect();
        if !redrawn.is_empty() {
            writeln!(
                out,
                "redrawn: trials {}: their parameters would have driven the robot through an obstacle",
                redrawn.join(", ")
            )?;
        }
        self.write_confusion(out)?;
        self.write_goals(out)?;
        let misses: Vec<String> = self
            .outcomes
            .iter()
            .filter(|o| {
                let concealed: Vec<Effect> = o.truth.into_iter().chain(o.second).collect();
                let missed = concealed.iter().any(|e| !o.named.contains(e));
                let outside_missed = o.outside && o.unexplained == 0;
                let none_alarm = concealed.is_empty()
                    && !o.outside
                    && self.reality == Reality::Hilsim
                    && !matches!(o.verdict, Ok(Verdict::None));
                missed || outside_missed || none_alarm || o.names_absent() || o.verdict.is_err()
            })
            .map(|o| {
                let mut truth: Vec<&str> = o
                    .truth
                    .into_iter()
                    .chain(o.second)
                    .map(Effect::name)
                    .collect();
                if o.outside {
                    truth.push(OUTSIDE);
                }
                let truth = if truth.is_empty() {
                    "none".to_string()
                } else {
                    truth.join("+")
                };
                let answer = match &o.verdict {
                    Ok(_) if o.named.is_empty() => verdict_label(&o.verdict).to_string(),
                    Ok(_) => o
                        .named
                        .iter()
                        .map(|e| e.name())
                        .collect::<Vec<_>>()
                        .join("+"),
                    Err(e) => format!("refused ({e})"),
                };
                let extra = if o.unexplained > 0 && !o.named.is_empty() {
                    format!(" (+{} unexplained)", o.unexplained)
                } else {
                    String::new()
                };
                let forms = if o.forms.is_empty() {
                    String::new()
                } else {
                    format!(" [{}]", o.forms.join("; "))
                };
                format!("trial {}: {truth}{forms} → {answer}{extra}", o.index)
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
            } else if s.classes[r] == OUTSIDE {
                format!("outside: {OUTSIDE}")
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
            "false alarms: {}/{} {} ({}; goal ≤ 5 %): {}",
            s.false_alarms,
            s.without_effect,
            match self.reality {
                Reality::Hilsim => "recordings without an effect not `none`",
                Reality::Independent | Reality::Varied =>
                    "trials naming an effect that was not there",
            },
            pct(s.false_alarm_share()),
            verdict(1)
        )?;
        if s.two > 0 {
            writeln!(
                out,
                "two effects at once: both named in {}/{} trials",
                s.two_named, s.two
            )?;
        }
        if self.reality.independent() {
            writeln!(
                out,
                "outside the catalogue: {}/{} unexplained ({}; goal ≥ 90 %): {}",
                s.outside_unexplained,
                s.outside,
                pct(if s.outside > 0 {
                    s.outside_unexplained as f64 / s.outside as f64
                } else {
                    f64::NAN
                }),
                verdict(4)
            )?;
        }
        writeln!(
            out,
            "held-out fit improved by every named effect: {}/{}: {}",
            s.improved,
            s.named,
            verdict(5)
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
                .flat_map(|o| o.param_errors.iter())
                .filter(|(x, _)| *x == e)
                .map(|(_, err)| *err)
                .collect();
            if errs.is_empty() {
                continue;
            }
            let worst = errs.iter().copied().fold(0.0, f64::max);
            let m = median(&mut errs);
            writeln!(
                out,
                "  {:<26} median {:>7}, worst {:>7} over {}",
                e.label(),
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
            if self.reality.independent() {
                // `Score::measured`: the independent reality's nuisances are not the declared
                // noise, so its floor is no goal.
                "no goal on the independent reality"
            } else {
                verdict(3)
            }
        )?;
        Ok(())
    }
}
