//! The verdict of a diagnosis: from the best candidate and the nominal evidence, where the
//! mismatch is, which effect (if any) explains it, and the notes on the other sensors.

use crate::catalogue::Sensor;
use crate::explain::CandidateFit;
use crate::locate::{Evidence, TestKind};
use crate::outcome::{Options, SensorSummary, Verdict};
use crate::residuals::Context;

/// What the residuals under the nominal model show.
pub(crate) struct Nominal {
    /// Each sensor's summary.
    pub sensors: Vec<SensorSummary>,
    /// Every test's evidence, strongest first.
    pub evidence: Vec<Evidence>,
    /// The first sensor most of whose readings are outliers to the simulation.
    pub misaligned: Option<Evidence>,
    /// The score a test has to reach.
    pub threshold: f64,
}

/// The declared sonar cone's half angle, degrees (0 when none is declared).
pub(crate) fn declared_cone(ctx: &Context<'_>) -> f64 {
    ctx.physics.declared().sonar_half_angle_deg.unwrap_or(0.0)
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

/// The answer, where it is located, the named effect's fit and the sentence that says it.
pub(crate) struct Conclusion {
    pub verdict: Verdict,
    pub located: Option<Evidence>,
    pub fitted: Option<CandidateFit>,
    pub explanation: String,
}

/// The verdict from the best candidate (if any) and the nominal evidence.
pub(crate) fn conclude(
    ctx: &Context<'_>,
    nominal: &Nominal,
    best: Option<CandidateFit>,
    options: &Options,
) -> Conclusion {
    let threshold = nominal.threshold;
    match (best, nominal.misaligned.clone()) {
        (Some(best), _) => conclude_effect(ctx, nominal, best, options),
        // Most readings far from every prediction and no effect explains them: the recording
        // is not a run of this scenario (or its trajectory is wrong).
        (None, Some(m)) => Conclusion {
            verdict: Verdict::Unexplained,
            explanation: format!(
                "Nothing aligns: {}. No catalogued effect explains it.",
                m.detail
            ),
            located: Some(m),
            fitted: None,
        },
        (None, None) => {
            match place_of(&nominal.evidence, None, threshold).filter(|s| s.score > threshold) {
                Some(s) => Conclusion {
                    verdict: Verdict::Unexplained,
                    explanation: format!(
                    "A mismatch is located in the {} ({}) but no catalogued effect explains it: \
                     none improves the held-out fit by {} nats.",
                    s.sensor, s.place, options.min_gain
                ),
                    located: Some(s),
                    fitted: None,
                },
                None => Conclusion {
                    verdict: Verdict::None,
                    located: None,
                    fitted: None,
                    explanation: "The recording agrees with the simulation within its noise: no \
                              test finds structure in the residuals and no catalogued effect \
                              improves the held-out fit."
                        .to_string(),
                },
            }
        }
    }
}

/// The verdict when `best` is good enough to name: the effect, if it leaves little of the
/// located structure, else "unexplained".
fn conclude_effect(
    ctx: &Context<'_>,
    nominal: &Nominal,
    best: CandidateFit,
    options: &Options,
) -> Conclusion {
    let threshold = nominal.threshold;
    let sensor = best.effect.sensor();
    let left = best.remaining.as_ref().map_or(0.0, |r| r.score);
    // Against an estimated trajectory part of the effect was absorbed into the estimate
    // (which the fit cannot undo), so twice the share may remain.
    let share = if ctx.estimated {
        2.0 * options.max_remaining
    } else {
        options.max_remaining
    };
    let strongest = nominal
        .sensors
        .iter()
        .find(|x| x.sensor == sensor)
        .map_or(0.0, |x| x.strongest);
    let allowed = (threshold + 2.0).max(share * strongest);
    let located = place_of(&nominal.evidence, Some(sensor), threshold);
    if left <= allowed {
        Conclusion {
            verdict: Verdict::Effect(best.effect),
            located,
            explanation: best.effect.explanation(&best.params, declared_cone(ctx)),
            fitted: Some(best),
        }
    } else {
        let explanation = format!(
            "A mismatch is located in the {sensor} but no catalogued effect explains it: \
             the best, {}, leaves structure of {left:.1}σ ({}).",
            best.effect,
            best.remaining
                .as_ref()
                .map_or(String::new(), |r| r.place.clone())
        );
        Conclusion {
            verdict: Verdict::Unexplained,
            located,
            fitted: None,
            explanation,
        }
    }
}

/// A note for each other sensor whose residuals depart from its noise (`significant`), unless
/// the verdict explains it, it is the located one or a note already names it.
pub(crate) fn note_other_sensors(
    notes: &mut Vec<String>,
    significant: &[Evidence],
    verdict: Verdict,
    located: Option<&Evidence>,
) {
    for s in significant {
        let explained = matches!(verdict, Verdict::Effect(e) if e.sensor() == s.sensor);
        let already = located.is_some_and(|l| l.sensor == s.sensor);
        if !explained && !already && !notes.iter().any(|n| n.contains(s.sensor.name())) {
            notes.push(format!(
                "the {} also departs from its noise ({:.1}σ at {})",
                s.sensor, s.score, s.place
            ));
        }
    }
}
