//! Running the self-test: every trial in parallel, or one trial in full.

use std::fmt::Write;

use hilsim_recording::Recording;
use hilsim_sim::Scenario;
use rayon::prelude::*;
use serde_json::{json, Value};

use super::draw::Drawn;
use super::plan::{Plan, Reality};
use super::score::Score;
use super::trial::{real_recording, trial, Outcome};
use crate::{show, Diagnosis, MismatchError, Options, SimPhysics};

/// A finished self-test.
#[derive(Debug, Clone)]
pub struct SelfTest {
    /// The nominal scenario's name.
    pub scenario: String,
    /// The self-test's seed.
    pub seed: u64,
    /// The drawn parameters' scale.
    pub strength: f64,
    /// What made the "real" recordings.
    pub reality: Reality,
    /// Every trial's outcome, in trial order.
    pub outcomes: Vec<Outcome>,
    /// Their score.
    pub score: Score,
}

impl SelfTest {
    /// Whether every goal was met.
    #[must_use]
    pub fn passed(&self) -> bool {
        self.score.passed()
    }
}

/// Runs `plan`'s trials of `nominal` in parallel.
///
/// # Errors
/// [`MismatchError::Input`] when the nominal scenario's sensor models are invalid or more than
/// [`super::MAX_TRIALS`] trials are asked for.
pub fn run(nominal: &Scenario, plan: Plan) -> Result<SelfTest, MismatchError> {
    run_with_progress(nominal, plan, &|| {})
}

/// As [`run`], calling `trial_done` as each trial ends (from the worker threads).
///
/// # Errors
/// As [`run`].
pub fn run_with_progress(
    nominal: &Scenario,
    plan: Plan,
    trial_done: &(dyn Fn() + Sync),
) -> Result<SelfTest, MismatchError> {
    if plan.trials > super::MAX_TRIALS {
        return Err(MismatchError::Input(format!(
            "at most {} trials, asked for {}",
            super::MAX_TRIALS,
            plan.trials
        )));
    }
    SimPhysics::new(nominal)?;
    let outcomes: Vec<Outcome> = (0..plan.trials)
        .into_par_iter()
        .map(|i| {
            let outcome = trial(nominal, plan, i);
            trial_done();
            outcome
        })
        .collect();
    let score = Score::of(&outcomes, plan.reality);
    Ok(SelfTest {
        scenario: nominal.name.clone(),
        seed: plan.seed,
        strength: plan.strength,
        reality: plan.reality,
        outcomes,
        score,
    })
}

/// One trial in full (`--trial I`): what was concealed, the "real" recording and its diagnosis.
#[derive(Debug, Clone)]
pub struct TrialRun {
    /// The trial's index.
    pub index: u64,
    /// The self-test's seed.
    pub seed: u64,
    /// What was concealed.
    pub drawn: Drawn,
    /// The "real" recording.
    pub recording: Recording,
    /// Its diagnosis against the nominal scenario.
    pub diagnosis: Diagnosis,
}

/// Trial `index` of `plan` in full.
///
/// # Errors
/// [`MismatchError`] when the "real" scenario cannot be emulated or the diagnosis refuses it.
pub fn one(nominal: &Scenario, plan: Plan, index: u64) -> Result<TrialRun, MismatchError> {
    let (drawn, recording) = real_recording(nominal, plan, index);
    let recording = recording.map_err(MismatchError::Input)?;
    let physics = SimPhysics::new(nominal)?;
    let diagnosis = crate::diagnose(&physics, &recording, &Options::default())?;
    Ok(TrialRun {
        index,
        seed: plan.seed,
        drawn,
        recording,
        diagnosis,
    })
}

impl TrialRun {
    /// The diagnosis's JSON with the trial's truth under `trial`.
    #[must_use]
    pub fn to_json(&self) -> Value {
        let mut j = show::to_json(&self.diagnosis);
        j["trial"] = json!({
            "index": self.index,
            "truth": self.drawn.label(),
            "drawn": self.drawn.params.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
            "forms": self.drawn.forms,
            "redrawn": self.drawn.redrawn,
        });
        j
    }

    /// What was concealed, the diagnosis's summary and its strongest evidence.
    #[must_use]
    pub fn to_text(&self) -> String {
        let drawn_text: Vec<String> = self
            .drawn
            .params
            .iter()
            .map(|(k, v)| format!("{k} = {v:.4}"))
            .collect();
        let mut out = format!(
            "trial {} (seed {}): concealed {} {}\n",
            self.index,
            self.seed,
            self.drawn.label(),
            drawn_text.join(", ")
        );
        for form in &self.drawn.forms {
            let _ = writeln!(out, "form: {form}");
        }
        if self.drawn.redrawn > 0 {
            let _ = writeln!(
                out,
                "redrawn {} times: the draws before would have driven the robot through an obstacle",
                self.drawn.redrawn
            );
        }
        out.push_str(&show::summary(&self.diagnosis));
        for e in self.diagnosis.evidence.iter().take(8) {
            let _ = writeln!(
                out,
                "evidence: {} {} ({:.1}σ): {}",
                e.sensor, e.place, e.score, e.detail
            );
        }
        let _ = writeln!(out, "threshold: {:.2}σ", self.diagnosis.threshold);
        out
    }
}
