//! One blind trial: record a "real" run with the drawn effect, diagnose it against the nominal
//! scenario without being told, and score the answer.

use std::time::Instant;

use hilsim_lidar_emulator::Emulation;
use hilsim_sim::Scenario;

use super::draw::real_scenario;
use crate::{Effect, Options, SimPhysics, Verdict};

/// One trial's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    pub index: u64,
    pub truth: Option<Effect>,
    pub drawn: Vec<(String, f64)>,
    pub verdict: Result<Verdict, String>,
    /// |fitted − true| / |true| of the scored parameter, when the verdict is right.
    pub param_error: Option<f64>,
    pub fitted: Vec<f64>,
    /// Held-out RMSE after the fix over the noise floor, and before over the floor.
    pub heldout: Option<(f64, f64)>,
    /// The strongest test's score under the nominal model, and the threshold.
    pub strongest: (f64, f64),
    pub seconds: f64,
}

pub(crate) fn trial(
    nominal: &Scenario,
    seed: u64,
    i: u64,
    strength: f64,
    only: Option<usize>,
) -> Outcome {
    let started = Instant::now();
    let (real, drawn) = real_scenario(nominal, seed, i, strength, only);
    let recording = match Emulation::new(&real, real.seed) {
        Ok(e) => e.run().recording,
        Err(err) => {
            return Outcome {
                index: i,
                truth: drawn.effect,
                drawn: drawn.params,
                verdict: Err(err.to_string()),
                param_error: None,
                fitted: Vec::new(),
                heldout: None,
                strongest: (f64::NAN, f64::NAN),
                seconds: started.elapsed().as_secs_f64(),
            }
        }
    };
    // A fresh physics per trial: its beam cache belongs to one trajectory.
    let result = SimPhysics::new(nominal)
        .map_err(|e| format!("{e:#}"))
        .and_then(|physics| {
            crate::diagnose(&physics, &recording, &Options::default()).map_err(|e| e.to_string())
        });
    let mut strongest = (f64::NAN, f64::NAN);
    let (verdict, param_error, fitted, heldout) = match result {
        Err(e) => (Err(e), None, Vec::new(), None),
        Ok(diag) => {
            strongest = (
                diag.sensors
                    .iter()
                    .map(|s| s.strongest)
                    .fold(f64::NEG_INFINITY, f64::max),
                diag.threshold,
            );
            let fit = diag.fitted.as_ref();
            let fitted = fit.map(|f| f.params.clone()).unwrap_or_default();
            let param_error = match (diag.verdict, drawn.effect, drawn.truth, fit) {
                (Verdict::Effect(v), Some(e), Some(t), Some(f)) if v == e => {
                    let got = e.params()[0].self_test.scored(f.params[0]);
                    Some((got - t).abs() / t.abs())
                }
                _ => None,
            };
            let heldout =
                fit.map(|f| (f.rmse_after / f.noise_floor, f.rmse_before / f.noise_floor));
            (Ok(diag.verdict), param_error, fitted, heldout)
        }
    };
    Outcome {
        index: i,
        truth: drawn.effect,
        drawn: drawn.params,
        verdict,
        param_error,
        fitted,
        heldout,
        strongest,
        seconds: started.elapsed().as_secs_f64(),
    }
}

pub(crate) fn label(e: Option<Effect>) -> &'static str {
    e.map_or("none", Effect::name)
}

pub(crate) fn verdict_label(v: &Result<Verdict, String>) -> &'static str {
    match v {
        Ok(v) => v.name(),
        Err(_) => "refused",
    }
}
