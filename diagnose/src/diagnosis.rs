//! The orchestration of one diagnosis: align, residuals, locate, explain, show.

use rayon::prelude::*;

use hilsim_recording::Recording;

use crate::align::{self, Alignment};
use crate::catalogue::{Effect, Sensor};
use crate::error::MismatchError;
use crate::explain::{self, CandidateFit};
use crate::locate::{self, Evidence, TestKind};
use crate::physics::{Hypothesis, Physics};
use crate::plot::{self, PlotData};
use crate::residuals::{self, Context, SensorData};

/// Rounds (at most) of estimating the trajectory again under a lidar effect's fit and refitting
/// it (against an estimated trajectory only); they stop once the parameter moves by less than
/// [`REALIGN_SETTLED`] of its value.
const REALIGN_ROUNDS: usize = 4;
const REALIGN_SETTLED: f64 = 0.02;

/// Settings of the diagnosis. The defaults are the ones `docs/diagnose.md` derives and the
/// self-test measures.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Family-wise false-alarm level of the locate tests (Bonferroni over all of them).
    pub alpha: f64,
    /// Held-out log-likelihood gain over "none" (nats) an effect needs to be named.
    pub min_gain: f64,
    /// Share of the located structure (in normal-score terms) the fitted effect may leave.
    pub max_remaining: f64,
    /// The effects tried (default: the whole catalogue).
    pub effects: Vec<Effect>,
    /// Training readings per sensor used to fit an effect (evenly thinned beyond this).
    pub max_fit_rows: usize,
    /// Share of a sensor's readings that are outliers to the simulation (the outlier component
    /// explains them better than the prediction) above which the recording "does not align".
    pub misaligned_share: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            alpha: 0.01,
            min_gain: 10.0,
            max_remaining: 0.25,
            effects: Effect::ALL.to_vec(),
            max_fit_rows: 15_000,
            misaligned_share: 0.5,
        }
    }
}

/// The answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The recording agrees with the simulation within its noise.
    None,
    /// A catalogued effect explains the mismatch.
    Effect(Effect),
    /// A mismatch is located but no catalogued effect explains it.
    Unexplained,
}

impl Verdict {
    /// The name in the JSON's `effect` key.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Verdict::None => "none",
            Verdict::Effect(e) => e.name(),
            Verdict::Unexplained => "unexplained",
        }
    }
}

/// One sensor's held-out residuals under the nominal model.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorSummary {
    /// The sensor.
    pub sensor: Sensor,
    /// Readings compared (both halves).
    pub readings: usize,
    /// Held-out RMSE of the nominal residuals, metres.
    pub heldout_rmse_m: f64,
    /// The noise floor there, metres.
    pub noise_floor_m: f64,
    /// The strongest test's normal score.
    pub strongest: f64,
}

/// The diagnosis of one recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnosis {
    /// The answer.
    pub verdict: Verdict,
    /// Where the residuals stop being noise (the strongest evidence), when they do.
    pub located: Option<Evidence>,
    /// One sentence: what physics was left out (or why none or no effect is named).
    pub explanation: String,
    /// The named effect's fit.
    pub fitted: Option<CandidateFit>,
    /// Every candidate tried, best held-out score first.
    pub candidates: Vec<CandidateFit>,
    /// Each sensor compared.
    pub sensors: Vec<SensorSummary>,
    /// The significant evidence under the nominal model, strongest first.
    pub evidence: Vec<Evidence>,
    /// The score a test had to reach.
    pub threshold: f64,
    /// Where the real trajectory came from.
    pub alignment: Alignment,
    /// What else the user should know.
    pub notes: Vec<String>,
    /// Residuals against the located variable, before and after the fix (held-out half).
    pub plots: Vec<PlotData>,
}

impl Diagnosis {
    /// Whether a mismatch was found.
    #[must_use]
    pub fn mismatch(&self) -> bool {
        self.verdict != Verdict::None
    }
}

/// The evidence to report as the location among `evidence` (strongest first), of `sensor` when
/// given: the strongest test against a variable when one is significant (it says where; a bias
/// there rather than the spread it causes, when the bias test is at least half as strong), with
/// the strongest significant test against a motion variable appended when it is at least half
/// as strong ("… while turn rate …"), else the strongest test.
fn place_of(evidence: &[Evidence], sensor: Option<Sensor>, threshold: f64) -> Option<Evidence> {
    let of = |e: &&Evidence| sensor.is_none_or(|s| e.sensor == s);
    let top = evidence.iter().find(of)?;
    let sensor = top.sensor;
    let against: Vec<&Evidence> = evidence
        .iter()
        .filter(|e| e.sensor == sensor && e.score > threshold)
        .filter(|e| matches!(e.test, TestKind::BiasAgainst | TestKind::SpreadAgainst))
        .collect();
    let Some(&first) = against.first() else {
        return Some(top.clone());
    };
    let chosen = match first.test {
        TestKind::SpreadAgainst => against
            .iter()
            .find(|e| {
                e.test == TestKind::BiasAgainst
                    && e.covariate == first.covariate
                    && e.place == first.place
                    && e.score >= 0.5 * first.score
            })
            .copied()
            .unwrap_or(first),
        _ => first,
    };
    let mut located = chosen.clone();
    // The motion it comes with, when that is nearly as strong (not merely when the robot
    // happened to move at one speed while it saw the place).
    let motion = against.iter().find(|e| {
        e.covariate.is_some_and(|c| c.is_motion())
            && e.covariate != chosen.covariate
            && e.score >= 0.5 * chosen.score
    });
    if let (Some(m), false) = (motion, chosen.covariate.is_some_and(|c| c.is_motion())) {
        located.place = format!("{} while {}", located.place, m.place);
        located.detail = format!("{}; and {}", located.detail, m.detail);
    }
    Some(located)
}

/// Diagnoses `recording` against the scenario behind `physics`.
///
/// # Errors
/// [`MismatchError::Refused`] when the recording cannot be a run of the scenario (the reason
/// says why), [`MismatchError::Input`] for malformed input.
pub fn diagnose(
    physics: &dyn Physics,
    recording: &Recording,
    options: &Options,
) -> Result<Diagnosis, MismatchError> {
    let aligned = align::align(physics, recording)?;
    let ctx = Context {
        physics,
        trajectory: &aligned.trajectory,
        recording,
        end_s: aligned.end_s,
        position_sd_m: aligned.position_sd_m,
        yaw_sd_rad: aligned.yaw_sd_rad,
        estimated: aligned.alignment == Alignment::Estimated,
    };
    let mut notes = aligned.notes.clone();
    let mut data: Vec<SensorData> = Vec::new();
    // Against an estimated trajectory only the ranges are diagnosed: the encoders and the drive
    // would be judged against the estimate's own errors (see `estimate.rs`).
    let proprioceptive = !ctx.estimated;
    for d in [
        residuals::lidar(&ctx)?,
        residuals::sonar(&ctx)?,
        proprioceptive
            .then(|| residuals::odometer(&ctx))
            .transpose()?
            .flatten(),
        proprioceptive
            .then(|| residuals::drive(&ctx))
            .transpose()?
            .flatten(),
    ]
    .into_iter()
    .flatten()
    {
        if d.len() >= 60 {
            let mut d = d;
            if ctx.estimated {
                d.clusters = Some(residuals::shared_error_clusters(ctx.trajectory, &d.t));
            }
            data.push(d);
        } else if !d.y.is_empty() {
            notes.push(format!(
                "only {} {} readings: too few to test",
                d.len(),
                d.sensor
            ));
        }
    }
    if data.is_empty() {
        return Err(MismatchError::Refused(
            "no sensor has enough readings to compare".into(),
        ));
    }
    let names = |id: u32| physics.object_name(id);
    // Residuals under the nominal model, and where they stop being noise.
    let nominal = Hypothesis::nominal();
    let mut evidence = Vec::new();
    let mut sensors = Vec::new();
    let mut misaligned = None;
    for d in &data {
        let all = d.rows(None);
        let f = residuals::fits(d, &all, &ctx.predict(d, &nominal, &all));
        let ev = locate::locate(d, &all, &f, &names, !ctx.estimated);
        let held: Vec<bool> = all.iter().map(|&i| d.heldout[i]).collect();
        let (r, floor, _) = residuals::rmse(&f, |k| held[k] && !f[k].outlier);
        let wild = f.iter().filter(|x| x.outlier).count() as f64 / f.len() as f64;
        if wild > options.misaligned_share && misaligned.is_none() {
            misaligned = Some(Evidence {
                sensor: d.sensor,
                test: TestKind::Spread,
                covariate: None,
                score: f64::INFINITY,
                place: format!("all {} readings", d.sensor),
                detail: format!(
                    "{:.0} % of the {} readings are nowhere near the simulation's (outliers to \
                     it): the recording does not align with the scenario",
                    100.0 * wild,
                    d.sensor
                ),
                range: None,
            });
        }
        sensors.push(SensorSummary {
            sensor: d.sensor,
            readings: d.len(),
            heldout_rmse_m: r,
            noise_floor_m: floor,
            strongest: ev.iter().map(|e| e.score).fold(f64::NEG_INFINITY, f64::max),
        });
        evidence.extend(ev);
    }
    let threshold = locate::threshold(options.alpha, evidence.len());
    evidence.sort_by(|a, b| b.score.total_cmp(&a.score));
    let strongest = place_of(&evidence, None, threshold);
    let significant: Vec<Evidence> = evidence
        .iter()
        .filter(|e| e.score > threshold)
        .cloned()
        .collect();

    // Fit every applicable effect (in parallel: each is independent).
    let present: Vec<Sensor> = data.iter().map(|d| d.sensor).collect();
    let tries: Vec<(Effect, &SensorData)> = options
        .effects
        .iter()
        .filter(|e| explain::applicable(**e, &ctx, &present))
        .filter_map(|&e| data.iter().find(|d| d.sensor == e.sensor()).map(|d| (e, d)))
        .collect();
    let mut candidates: Vec<CandidateFit> = tries
        .par_iter()
        .map(|(e, d)| explain::fit_candidate(&ctx, d, *e, options.max_fit_rows, &names))
        .collect();
    candidates.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));

    let strongest_of = |s: Sensor| {
        sensors
            .iter()
            .find(|x| x.sensor == s)
            .map_or(0.0, |x| x.strongest)
    };
    // An effect fitted to (next to) its own absence is the nominal model: what it gains is
    // noise the fit chased, not physics.
    let declared_cone = physics.declared().sonar_half_angle_deg.unwrap_or(0.0);
    let mut best = candidates
        .iter()
        .find(|c| {
            c.heldout_gain > options.min_gain
                && c.bic_gain > 0.0
                && c.effect.departs(&c.params, declared_cone)
        })
        .cloned();
    // Against an estimated trajectory a lidar effect was partly absorbed into the scan
    // matching (fitted with the nominal model): the trajectory is estimated again under the
    // effect's fitted model and the effect refitted against it.
    let mut realigned: Option<align::Aligned> = None;
    if let Some(mut current) = best
        .clone()
        .filter(|b| ctx.estimated && b.effect.sensor() == Sensor::Lidar)
    {
        for _ in 0..REALIGN_ROUNDS {
            let hypothesis = Hypothesis::with(current.effect, current.params.clone());
            let again = align::realign(physics, recording, &aligned, &hypothesis)?;
            let ctx2 = Context {
                trajectory: &again.trajectory,
                position_sd_m: again.position_sd_m,
                yaw_sd_rad: again.yaw_sd_rad,
                ..ctx
            };
            let Some(mut lidar) = residuals::lidar(&ctx2)? else {
                break;
            };
            lidar.clusters = Some(residuals::shared_error_clusters(ctx2.trajectory, &lidar.t));
            let refit =
                explain::fit_candidate(&ctx2, &lidar, current.effect, options.max_fit_rows, &names);
            if !(refit.heldout_gain > options.min_gain
                && refit.effect.departs(&refit.params, declared_cone))
            {
                break;
            }
            let (before, after) = (current.params[0], refit.params[0]);
            current = refit;
            // The plots show the data against the trajectory the verdict rests on.
            if let Some(d) = data.iter_mut().find(|d| d.sensor == Sensor::Lidar) {
                *d = lidar;
            }
            realigned = Some(again);
            if (after - before).abs() <= REALIGN_SETTLED * after.abs() {
                break;
            }
        }
        if realigned.is_some() {
            if let Some(c) = candidates.iter_mut().find(|c| c.effect == current.effect) {
                *c = current.clone();
            }
            best = Some(current);
        }
    }
    let realigned_ctx = realigned.as_ref().map(|a| Context {
        trajectory: &a.trajectory,
        position_sd_m: a.position_sd_m,
        yaw_sd_rad: a.yaw_sd_rad,
        ..ctx
    });
    let plot_ctx = realigned_ctx.as_ref().unwrap_or(&ctx);
    let (verdict, located, fitted, explanation) = match (best, misaligned) {
        (Some(best), _) => {
            let sensor = best.effect.sensor();
            let left = best.remaining.as_ref().map_or(0.0, |r| r.score);
            // Against an estimated trajectory part of the effect was absorbed into the estimate
            // (which the fit cannot undo), so twice the share may remain.
            let share = if ctx.estimated {
                2.0 * options.max_remaining
            } else {
                options.max_remaining
            };
            let allowed = (threshold + 2.0).max(share * strongest_of(sensor));
            let located = place_of(&evidence, Some(sensor), threshold);
            if left <= allowed {
                let explanation = best.effect.explanation(&best.params, declared_cone);
                (
                    Verdict::Effect(best.effect),
                    located,
                    Some(best),
                    explanation,
                )
            } else {
                let explanation = format!(
                    "A mismatch is located in the {sensor} but no catalogued effect explains it: \
                     the best, {}, leaves structure of {left:.1}σ ({}).",
                    best.effect,
                    best.remaining
                        .as_ref()
                        .map_or(String::new(), |r| r.place.clone())
                );
                (Verdict::Unexplained, located, None, explanation)
            }
        }
        // Most readings far from every prediction and no effect explains them: the recording
        // is not a run of this scenario (or its trajectory is wrong).
        (None, Some(m)) => {
            let explanation = format!(
                "Nothing aligns: {}. No catalogued effect explains it.",
                m.detail
            );
            (Verdict::Unexplained, Some(m), None, explanation)
        }
        (None, None) => match strongest.filter(|s| s.score > threshold) {
            Some(s) => {
                let explanation = format!(
                    "A mismatch is located in the {} ({}) but no catalogued effect explains it: \
                     none improves the held-out fit by {} nats.",
                    s.sensor, s.place, options.min_gain
                );
                (Verdict::Unexplained, Some(s), None, explanation)
            }
            None => (
                Verdict::None,
                None,
                None,
                "The recording agrees with the simulation within its noise: no test finds \
                 structure in the residuals and no catalogued effect improves the held-out fit."
                    .to_string(),
            ),
        },
    };
    for s in &significant {
        let explained = matches!(verdict, Verdict::Effect(e) if e.sensor() == s.sensor);
        let already = located.as_ref().is_some_and(|l| l.sensor == s.sensor);
        if !explained && !already && !notes.iter().any(|n| n.contains(s.sensor.name())) {
            notes.push(format!(
                "the {} also departs from its noise ({:.1}σ at {})",
                s.sensor, s.score, s.place
            ));
        }
    }
    let plots = plot::plots(plot_ctx, &data, located.as_ref(), fitted.as_ref());
    Ok(Diagnosis {
        verdict,
        located,
        explanation,
        fitted,
        candidates,
        sensors,
        evidence: significant,
        threshold,
        alignment: aligned.alignment,
        notes,
        plots,
    })
}
