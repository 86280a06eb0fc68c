//! The verdict of a diagnosis: from the named effects, the nominal evidence and what each
//! sensor's residuals show under its named effects: where the mismatch is, which effects
//! explain it, and what no named effect explains.

use crate::catalogue::Sensor;
use crate::explain::CandidateFit;
use crate::locate::{Evidence, Floors, TestKind};
use crate::outcome::{NamedEffect, Options, SensorSummary, Verdict};
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
/// given: the strongest test against a variable when one counts (significant and large enough:
/// [`Evidence::counts`]; it says where; a bias there rather than the spread it causes, when the
/// bias test is at least half as strong), with the strongest counting test against a motion
/// variable appended when it is at least half as strong ("… while turn rate …"), else the
/// strongest counting test, else (`or_strongest`) the strongest test.
fn place_of(
    evidence: &[Evidence],
    sensor: Option<Sensor>,
    threshold: f64,
    floors: &Floors,
    or_strongest: bool,
) -> Option<Evidence> {
    let of = |e: &&Evidence| sensor.is_none_or(|s| e.sensor == s);
    let top = evidence
        .iter()
        .filter(of)
        .find(|e| e.counts(threshold, floors))
        .or_else(|| or_strongest.then(|| evidence.iter().find(of)).flatten())?;
    let sensor = top.sensor;
    let against: Vec<&Evidence> = evidence
        .iter()
        .filter(|e| e.sensor == sensor && e.counts(threshold, floors))
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

/// The answer, where it is located, the named effects and what is left unexplained, and the
/// sentence that says it.
pub(crate) struct Conclusion {
    pub verdict: Verdict,
    pub located: Option<Evidence>,
    pub effects: Vec<NamedEffect>,
    pub unexplained: Vec<Evidence>,
    /// Departures the world's own error can make (a map's cells), strongest first.
    pub world: Vec<Evidence>,
    pub explanation: String,
}

/// One sensor's structure left under its named effects: `evidence`, strongest first (the
/// nominal evidence when none is named).
pub(crate) struct Left {
    pub sensor: Sensor,
    pub evidence: Vec<Evidence>,
}

/// The verdict from the effects `named` (strongest first), the nominal evidence and the
/// evidence left in each sensor under its named effects.
pub(crate) fn conclude(
    ctx: &Context<'_>,
    nominal: &Nominal,
    named: Vec<CandidateFit>,
    left: &[Left],
    dead: &[Evidence],
    options: &Options,
) -> Conclusion {
    let threshold = nominal.threshold;
    let floors = &options.floors;
    let effects: Vec<NamedEffect> = named
        .into_iter()
        .map(|fit| NamedEffect {
            located: place_of(&nominal.evidence, Some(fit.sensor), threshold, floors, true),
            fit,
        })
        .collect();
    // A dead or stuck sensor first: no effect explains a sensor that reads nothing.
    let mut unexplained: Vec<Evidence> = dead.to_vec();
    for l in left
        .iter()
        .filter(|l| dead.iter().all(|d| d.sensor != l.sensor))
    {
        // An effect read from the path's own motion against this sensor (the encoders' spans,
        // the crab) judged the sensor by that motion, not reading by reading.
        let explained = effects.iter().any(|e| {
            e.fit.effect.shows_in(l.sensor)
                || (e.fit.sensor == l.sensor && e.fit.rmse_over.of_path_motion())
        });
        // Most readings far from every prediction and no effect of the sensor named: the
        // recording is not a run of this scenario (or its trajectory is wrong).
        if let Some(m) = nominal
            .misaligned
            .as_ref()
            .filter(|m| m.sensor == l.sensor && !explained)
        {
            unexplained.push(m.clone());
        } else if let Some(e) = place_of(&l.evidence, Some(l.sensor), threshold, floors, false) {
            unexplained.push(e);
        }
    }
    unexplained.sort_by(|a, b| b.score.total_cmp(&a.score));
    // What is significant and above the floors, but within the world's reach: the map's error
    // as likely as the sensor's.
    let mut world: Vec<Evidence> = left
        .iter()
        .filter(|l| unexplained.iter().all(|u| u.sensor != l.sensor))
        .filter_map(|l| {
            l.evidence
                .iter()
                .filter(|e| e.within_world(threshold, floors))
                .max_by(|a, b| a.score.total_cmp(&b.score))
                .cloned()
        })
        .collect();
    world.sort_by(|a, b| b.score.total_cmp(&a.score));
    let cone = declared_cone(ctx);
    let mut explanation = effects
        .iter()
        .map(|e| {
            let said = e.fit.effect.explanation(&e.fit.params, cone);
            // A lidar mount or delay the estimated path took up is seen through another sensor.
            if e.fit.effect.sensor() != Sensor::Lidar || e.fit.sensor == Sensor::Lidar {
                said
            } else {
                format!(
                    "{} (Seen through the {}: the path estimated from the lidar takes it up.)",
                    said, e.fit.sensor
                )
            }
        })
        .collect::<Vec<_>>()
        .join(" ");
    let left_words: Vec<String> = unexplained
        .iter()
        .map(|u| {
            let size = if u.size_m.is_finite() {
                format!(", {:.1} mm", u.size_m * 1000.0)
            } else {
                String::new()
            };
            format!("the {} ({}{size})", u.sensor, u.place)
        })
        .collect();
    let world_words: Vec<String> = world
        .iter()
        .map(|w| {
            format!(
                "the {} ({}, {:.1} mm, where the map's cells can move a reading by {:.1} mm)",
                w.sensor,
                w.place,
                w.size_m * 1000.0,
                w.world_m * 1000.0
            )
        })
        .collect();
    let verdict = match (effects.first(), unexplained.first(), world.first()) {
        (Some(e), _, _) => Verdict::Effect(e.fit.effect),
        (None, Some(_), _) => Verdict::Unexplained,
        (None, None, Some(_)) => Verdict::WorldMismatch,
        (None, None, None) => Verdict::None,
    };
    match verdict {
        Verdict::Effect(_) if !left_words.is_empty() => {
            explanation += &format!(
                " Left unexplained (no catalogued effect explains it): {}.",
                left_words.join("; ")
            );
        }
        Verdict::Effect(_) => {}
        Verdict::Unexplained => {
            let first = &unexplained[0];
            // (Compared by sensor and place: a dead sensor's size is NaN, which equals nothing.)
            explanation = if dead
                .iter()
                .any(|d| d.sensor == first.sensor && d.place == first.place)
            {
                format!(
                    "The {} reports nothing the simulation could give: {}. No catalogued \
                     effect explains it.",
                    first.sensor, first.detail
                )
            } else if first.score.is_infinite() {
                format!(
                    "Nothing aligns: {}. No catalogued effect explains it.",
                    first.detail
                )
            } else {
                format!(
                    "A mismatch is located in {} but no catalogued effect explains it: none \
                     improves the held-out fit by {} nats by changing the readings more than \
                     the sensor's floor.",
                    left_words.join("; "),
                    options.min_gain
                )
            };
        }
        Verdict::WorldMismatch => {
            explanation = format!(
                "A mismatch is located in {} within what the world's own error can make: the \
                 map is as likely off there as the sensor, so no sensor physics is named from \
                 this world.",
                world_words.join("; ")
            );
        }
        Verdict::None => {
            explanation = "The recording agrees with the simulation within its noise: no \
                           test finds structure in the residuals larger than the sensors' \
                           floors and no catalogued effect improves the held-out fit."
                .to_string();
        }
    }
    if !matches!(verdict, Verdict::WorldMismatch) && !world_words.is_empty() {
        explanation += &format!(
            " Within the world's own error (the map as likely off as the sensor): {}.",
            world_words.join("; ")
        );
    }
    let located = match effects.first() {
        Some(e) => e.located.clone(),
        None => unexplained.first().or(world.first()).cloned(),
    };
    Conclusion {
        verdict,
        located,
        effects,
        unexplained,
        world,
        explanation,
    }
}
