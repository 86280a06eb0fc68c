//! A self-test on a log, reported: one JSON object, or text for a person.

use std::fmt::Write;

use serde_json::{json, Value};

use super::conceal::Concealment;
use super::on_log::{
    Answer, LogSelfTest, GOAL_FALSE_ON_LOG, GOAL_NAMED_ON_LOG, GOAL_PARAMS_ON_LOG,
    HALVES_WITHIN_SD, READ_UNNAMED_SD,
};
use super::trial::verdict_label;
use super::GOAL_PARAM_ERROR;

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

fn answer_json(a: &Answer) -> Value {
    json!({
        "verdict": verdict_label(&a.verdict),
        "refusal": a.verdict.as_ref().err(),
        "named": a.named.iter().map(|n| json!({
            "effect": n.effect.label(),
            "params": n.params.iter().copied().map(finite).collect::<Vec<_>>(),
            "size": finite(n.size),
            "size_sd": finite(n.size_sd),
        })).collect::<Vec<_>>(),
        "unexplained": a.unexplained,
    })
}

/// An answer in words: its verdict and each named effect's size ± its standard error.
fn answer_text(a: &Answer) -> String {
    let verdict = match &a.verdict {
        Ok(v) => v.name().to_string(),
        Err(e) => format!("refused ({e})"),
    };
    let named: Vec<String> = a
        .named
        .iter()
        .map(|n| {
            if n.size_sd.is_finite() {
                format!(
                    "{} (size {:.4} ± {:.4})",
                    n.effect.label(),
                    n.size,
                    n.size_sd
                )
            } else {
                format!("{} (size {:.4})", n.effect.label(), n.size)
            }
        })
        .collect();
    let mut text = verdict;
    if !named.is_empty() {
        let _ = write!(text, "; named {}", named.join(", "));
    }
    if a.unexplained > 0 {
        let _ = write!(text, "; {} unexplained", a.unexplained);
    }
    text
}

fn concealed_text(c: &[Concealment]) -> String {
    if c.is_empty() {
        return "none".to_string();
    }
    c.iter()
        .map(|c| {
            let params: Vec<String> = c
                .named_params()
                .iter()
                .map(|(k, v)| format!("{k} = {v:.4}"))
                .collect();
            format!("{} ({})", c.effect().label(), params.join(", "))
        })
        .collect::<Vec<_>>()
        .join(" + ")
}

impl LogSelfTest {
    /// The whole self-test as one JSON object (`command`: how to reproduce it; `wall_s`: how
    /// long it took).
    #[must_use]
    pub fn to_json(&self, command: &str, wall_s: f64) -> Value {
        let s = self.score();
        let b = &self.baseline;
        json!({
            "command": command,
            "world": self.world,
            "concealable": self.concealable.iter().map(|e| e.label()).collect::<Vec<_>>(),
            "not_concealed": self.not_concealed.iter().map(|(e, why)| json!({"effect": e, "why": why})).collect::<Vec<_>>(),
            "encoder_stamp_scatter_s": self.encoder_scatter_s,
            "encoder_leads_over_truth_spans": self.leads_over_truth_spans,
            "untouched": answer_json(&b.whole),
            "halves": b.halves.as_ref().map(|h| h.iter().map(answer_json).collect::<Vec<_>>()),
            "halves_stable": b.stable(),
            "trials": self.outcomes.iter().map(|o| json!({
                "trial": o.index,
                "concealed": o.concealed.iter().map(|c| json!({
                    "effect": c.effect().label(),
                    "params": c.named_params().iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                    "size": c.scored(),
                    "undoes_the_logs_own": self.undoes_own(c),
                })).collect::<Vec<_>>(),
                "answer": answer_json(&o.answer),
                "names_absent": o.names_absent(&b.whole).iter().map(|e| e.label()).collect::<Vec<_>>(),
                "names_absent_read_untouched": o.alarms_read_untouched(&b.whole),
                "param_errors": o.param_errors.iter().map(|(e, v)| (e.label(), json!(finite(*v)))).collect::<serde_json::Map<_, _>>(),
                "seconds": o.seconds,
            })).collect::<Vec<_>>(),
            "per_effect": s.per_effect.iter().map(|(e, c, n)| json!({"effect": e.label(), "concealed": c, "named": n})).collect::<Vec<_>>(),
            "concealed": s.concealed, "named": s.named,
            "false_alarms": s.false_alarms,
            "false_alarms_read_untouched": s.false_alarms_read_untouched,
            "refused": s.refused, "undone": s.undone,
            "param_within_20pct": s.param_within, "param_scored": s.param_scored,
            "pass": self.passed(),
            "wall_s": wall_s,
        })
    }

    /// The self-test for a person: the untouched answer and its halves, each mechanism's
    /// count, each goal, the misses.
    #[must_use]
    pub fn to_text(&self, command: &str, wall_s: f64) -> String {
        let mut out = String::new();
        // Writing to a String cannot fail.
        let _ = self.write_text(&mut out, command, wall_s);
        out
    }

    fn write_text(&self, out: &mut String, command: &str, wall_s: f64) -> std::fmt::Result {
        let s = self.score();
        let b = &self.baseline;
        writeln!(
            out,
            "self-test on a log: {} blind trials, seed {}, strength {}, {} ({wall_s:.0} s)",
            s.trials, self.plan.seed, self.plan.strength, self.world
        )?;
        if let Some(scatter_s) = self.encoder_scatter_s {
            let ms = scatter_s * 1000.0;
            if self.leads_over_truth_spans {
                writeln!(
                    out,
                    "the encoders' stamps scatter by ±{ms:.0} ms; their delay and slip are read over the truth's spans between its poses, where that averages out"
                )?;
            } else {
                writeln!(
                    out,
                    "the encoders' stamps scatter by ±{ms:.0} ms (a delay or slip of theirs within that is not identifiable)"
                )?;
            }
        }
        writeln!(out, "untouched: {}", answer_text(&b.whole))?;
        match &b.halves {
            Some([first, second]) => {
                writeln!(out, "  first half: {}", answer_text(first))?;
                writeln!(out, "  second half: {}", answer_text(second))?;
                writeln!(
                    out,
                    "  the halves {} (each effect named in either half sized alike in the other, named or not: within {HALVES_WITHIN_SD} combined standard errors)",
                    if b.stable() { "agree" } else { "DISAGREE" }
                )?;
            }
            None => writeln!(
                out,
                "  the halves are not diagnosed: the given scenario's run starts where the whole log starts"
            )?,
        }
        writeln!(out, "concealed (exactly, in the log's own data), named:")?;
        for (e, concealed, named) in &s.per_effect {
            writeln!(out, "  {:<30} {named:>3}/{concealed}", e.label())?;
        }
        writeln!(out, "not concealed:")?;
        for (e, why) in &self.not_concealed {
            writeln!(out, "  {e}: {why}")?;
        }
        let pct = |a: usize, n: usize| {
            if n == 0 {
                0.0
            } else {
                100.0 * a as f64 / n as f64
            }
        };
        let mark = |ok: bool| if ok { "ok" } else { "MISSED" };
        writeln!(
            out,
            "named: {}/{} concealed mechanisms ({:.0} %; goal ≥ {:.0} %) {}",
            s.named,
            s.concealed,
            pct(s.named, s.concealed),
            100.0 * GOAL_NAMED_ON_LOG,
            mark(s.concealed == 0 || pct(s.named, s.concealed) >= 100.0 * GOAL_NAMED_ON_LOG)
        )?;
        writeln!(
            out,
            "false alarms: {}/{} trials named a mechanism neither concealed nor named untouched ({:.0} %; goal ≤ {:.0} %) {}",
            s.false_alarms,
            s.trials,
            pct(s.false_alarms, s.trials),
            100.0 * GOAL_FALSE_ON_LOG,
            mark(pct(s.false_alarms, s.trials) <= 100.0 * GOAL_FALSE_ON_LOG)
        )?;
        if s.false_alarms_read_untouched > 0 {
            writeln!(
                out,
                "  of which {} named only what the untouched log fits, the same way, {READ_UNNAMED_SD} or more standard errors from nothing, without naming it: the log's own, at the naming's threshold",
                s.false_alarms_read_untouched,
            )?;
        }
        writeln!(
            out,
            "parameters: {}/{} within {:.0} % ({:.0} %; goal ≥ {:.0} %) {}",
            s.param_within,
            s.param_scored,
            100.0 * GOAL_PARAM_ERROR,
            pct(s.param_within, s.param_scored),
            100.0 * GOAL_PARAMS_ON_LOG,
            mark(
                s.param_scored == 0
                    || pct(s.param_within, s.param_scored) >= 100.0 * GOAL_PARAMS_ON_LOG
            )
        )?;
        if s.undone > 0 {
            writeln!(
                out,
                "undone: {} concealments undid the log's own reading of their mechanism (of opposite sign, summing to within {:.0} % of nothing): scored neither way",
                s.undone,
                100.0 * GOAL_PARAM_ERROR
            )?;
        }
        if s.refused > 0 {
            writeln!(out, "refused: {} trials", s.refused)?;
        }
        for o in &self.outcomes {
            let missed: Vec<String> = o
                .concealed
                .iter()
                .filter(|c| !o.names(c.effect()) && !self.undoes_own(c))
                .map(|c| c.effect().label())
                .collect();
            let absent = o.names_absent(&b.whole);
            let off: Vec<String> = o
                .param_errors
                .iter()
                .filter(|(_, e)| e.is_nan() || *e > GOAL_PARAM_ERROR)
                .map(|(e, err)| format!("{} off by {:.0} %", e.label(), 100.0 * err))
                .collect();
            if missed.is_empty() && absent.is_empty() && off.is_empty() {
                continue;
            }
            writeln!(
                out,
                "  trial {}: concealed {}; got {}",
                o.index,
                concealed_text(&o.concealed),
                answer_text(&o.answer)
            )?;
        }
        writeln!(out, "reproduce: {command}")?;
        writeln!(
            out,
            "{}",
            if self.passed() {
                "self-test passed"
            } else {
                "self-test FAILED"
            }
        )
    }
}

/// One trial on a log in words: what was concealed and the diagnosis's summary.
#[must_use]
pub fn trial_text(index: u64, seed: u64, concealed: &[Concealment], summary: &str) -> String {
    format!(
        "trial {index} (seed {seed}): concealed {}\n{summary}",
        concealed_text(concealed)
    )
}
