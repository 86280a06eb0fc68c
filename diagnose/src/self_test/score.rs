//! The self-test's score over its trials: the confusion matrix and its goals.

use super::draw::OUTSIDE;
use super::plan::Reality;
use super::trial::{label, verdict_label, Outcome};
use crate::{Effect, Verdict};

/// Share of concealed effects named correctly the self-test needs.
pub const GOAL_CORRECT: f64 = 0.95;
/// Share of recordings without an effect it may raise an alarm on.
pub const GOAL_FALSE_ALARMS: f64 = 0.05;
/// Relative error of a recovered parameter that counts as recovered.
pub const GOAL_PARAM_ERROR: f64 = 0.20;
/// Held-out RMSE after the fix over the noise floor that counts as explained.
pub const GOAL_HELDOUT_RATIO: f64 = 1.2;
/// Share of concealed effects outside the catalogue that must come out unexplained.
pub const GOAL_OUTSIDE: f64 = 0.90;

/// The score of a set of trials.
#[derive(Debug, Clone, PartialEq)]
pub struct Score {
    /// The rows of the confusion matrix: the concealed effect ("none" first, then the
    /// catalogue in order).
    pub classes: Vec<&'static str>,
    /// Its columns: the verdict (the classes, then "unexplained" and "refused").
    pub columns: Vec<&'static str>,
    /// Trials per (concealed, verdict).
    pub matrix: Vec<Vec<usize>>,
    /// Concealed effects named correctly, of `with_effect`.
    pub correct: usize,
    /// Trials with a concealed effect.
    pub with_effect: usize,
    /// Trials without an effect whose verdict was not "none", of `without_effect`.
    pub false_alarms: usize,
    /// Trials without a concealed effect.
    pub without_effect: usize,
    /// Recovered parameters within [`GOAL_PARAM_ERROR`], of `param_scored`.
    pub param_within: usize,
    /// Recovered parameters scored (right verdicts).
    pub param_scored: usize,
    /// Median relative parameter error.
    pub param_median_error: f64,
    /// Held-out ratios within [`GOAL_HELDOUT_RATIO`], of `heldout_scored`.
    pub heldout_within: usize,
    /// Held-out ratios scored.
    pub heldout_scored: usize,
    /// Median held-out ratio.
    pub heldout_median_ratio: f64,
    /// Trials whose effect outside the catalogue came out unexplained (and named nothing
    /// absent), of `outside`.
    pub outside_unexplained: usize,
    /// Trials that concealed an effect outside the catalogue.
    pub outside: usize,
    /// Named effects whose held-out fit improved, of `named`.
    pub improved: usize,
    /// Effects named, over all trials.
    pub named: usize,
    /// Trials that concealed two catalogued effects, and those that named both.
    pub two: usize,
    pub two_named: usize,
    /// Whether each goal (correct, false alarms, parameters, held-out ratio, outside the
    /// catalogue, held-out improvement) had a trial to measure it on.
    pub measured: [bool; 6],
    /// Whether each goal was met (a goal not measured is not missed).
    pub pass: [bool; 6],
}

fn share(a: usize, b: usize) -> f64 {
    if b == 0 {
        f64::NAN
    } else {
        a as f64 / b as f64
    }
}

impl Score {
    /// The score of `outcomes` of a self-test on `reality`. A false alarm is, on hilsim's
    /// reality, a verdict other than `none` on a recording without an effect; on the
    /// independent one, whose nuisances are real mismatches, a trial that names an effect that
    /// was not concealed, over all trials.
    #[must_use]
    pub fn of(outcomes: &[Outcome], reality: Reality) -> Self {
        // Confusion matrix of the trials with one concealed class: rows the truth, columns the
        // verdict.
        let classes: Vec<&'static str> = std::iter::once("none")
            .chain(Effect::entries())
            .chain((reality.independent()).then_some(OUTSIDE))
            .collect();
        let columns: Vec<&'static str> = std::iter::once("none")
            .chain(Effect::entries())
            .chain(["unexplained", "refused"])
            .collect();
        let mut matrix = vec![vec![0usize; columns.len()]; classes.len()];
        for o in outcomes.iter().filter(|o| o.second.is_none()) {
            let row = if o.outside { OUTSIDE } else { label(o.truth) };
            let r = classes.iter().position(|c| *c == row).unwrap_or(0);
            let c = columns
                .iter()
                .position(|c| *c == verdict_label(&o.verdict))
                .unwrap_or(columns.len() - 1);
            matrix[r][c] += 1;
        }
        let concealed: Vec<(Effect, &Outcome)> = outcomes
            .iter()
            .flat_map(|o| o.truth.into_iter().chain(o.second).map(move |e| (e, o)))
            .collect();
        let correct = concealed
            .iter()
            .filter(|(e, o)| o.named.contains(e))
            .count();
        let (false_alarms, without_effect) = match reality {
            Reality::Hilsim => {
                let without: Vec<&Outcome> = outcomes
                    .iter()
                    .filter(|o| o.truth.is_none() && !o.outside)
                    .collect();
                let alarms = without
                    .iter()
                    .filter(|o| !matches!(o.verdict, Ok(Verdict::None)))
                    .count();
                (alarms, without.len())
            }
            Reality::Independent | Reality::Varied => (
                outcomes.iter().filter(|o| o.names_absent()).count(),
                outcomes.len(),
            ),
        };
        let outside: Vec<&Outcome> = outcomes.iter().filter(|o| o.outside).collect();
        let outside_unexplained = outside
            .iter()
            .filter(|o| o.unexplained > 0 && !o.names_absent())
            .count();
        let mut errors: Vec<f64> = outcomes
            .iter()
            .flat_map(|o| o.param_errors.iter().map(|(_, e)| *e))
            .collect();
        let param_within = errors.iter().filter(|e| **e <= GOAL_PARAM_ERROR).count();
        let mut ratios: Vec<f64> = outcomes
            .iter()
            .filter(|o| o.param_error.is_some())
            .filter_map(|o| o.heldout.map(|h| h.0))
            .collect();
        let heldout_within = ratios.iter().filter(|r| **r <= GOAL_HELDOUT_RATIO).count();
        let named = outcomes.iter().map(|o| o.improved.len()).sum();
        let improved = outcomes
            .iter()
            .map(|o| o.improved.iter().filter(|i| **i).count())
            .sum();
        let two: Vec<&Outcome> = outcomes.iter().filter(|o| o.second.is_some()).collect();
        let two_named = two
            .iter()
            .filter(|o| {
                o.truth.is_some_and(|e| o.named.contains(&e))
                    && o.second.is_some_and(|e| o.named.contains(&e))
            })
            .count();
        let mut score = Self {
            classes,
            columns,
            matrix,
            correct,
            with_effect: concealed.len(),
            false_alarms,
            without_effect,
            param_within,
            param_scored: errors.len(),
            param_median_error: median(&mut errors),
            heldout_within,
            heldout_scored: ratios.len(),
            heldout_median_ratio: median(&mut ratios),
            outside_unexplained,
            outside: outside.len(),
            improved,
            named,
            two: two.len(),
            two_named,
            measured: [false; 6],
            pass: [false; 6],
        };
        // A goal with no trial to measure it on (e.g. `--only none`) is not missed. The
        // held-out ratio to the noise floor is a goal on hilsim's reality only: under the
        // independent one's nuisances the floor is not the declared noise's.
        score.measured = [
            score.with_effect > 0,
            score.without_effect > 0,
            score.param_scored > 0,
            score.heldout_scored > 0 && reality == Reality::Hilsim,
            score.outside > 0,
            score.named > 0,
        ];
        score.pass = [
            !score.measured[0] || score.correct_share() >= GOAL_CORRECT,
            !score.measured[1] || score.false_alarm_share() <= GOAL_FALSE_ALARMS,
            !score.measured[2] || score.param_share() >= 0.95,
            !score.measured[3] || score.heldout_share() >= 0.95,
            !score.measured[4] || share(score.outside_unexplained, score.outside) >= GOAL_OUTSIDE,
            !score.measured[5] || score.improved == score.named,
        ];
        score
    }

    /// Whether every goal was met.
    #[must_use]
    pub fn passed(&self) -> bool {
        self.pass.iter().all(|p| *p)
    }

    /// Share of concealed effects named correctly.
    #[must_use]
    pub fn correct_share(&self) -> f64 {
        share(self.correct, self.with_effect)
    }

    /// Share of recordings without an effect that raised an alarm.
    #[must_use]
    pub fn false_alarm_share(&self) -> f64 {
        share(self.false_alarms, self.without_effect)
    }

    /// Share of scored parameters recovered within [`GOAL_PARAM_ERROR`].
    #[must_use]
    pub fn param_share(&self) -> f64 {
        share(self.param_within, self.param_scored)
    }

    /// Share of scored held-out ratios within [`GOAL_HELDOUT_RATIO`].
    #[must_use]
    pub fn heldout_share(&self) -> f64 {
        share(self.heldout_within, self.heldout_scored)
    }
}

/// The median of `v` (sorted in place); NaN when empty.
pub(crate) fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
