//! One blind trial: record a "real" run with the drawn effects (hilsim's simulator with them
//! switched on, or the independent reality with its nuisances), diagnose it against the nominal
//! scenario without being told, and score the answer.

use std::time::Instant;

use hilsim_lidar_emulator::Emulation;
use hilsim_recording::Recording;
use hilsim_sim::replay::replay_contacts;
use hilsim_sim::Scenario;

use super::draw::{draw_classes, draw_independent, real_scenario, Drawn, Draws};
use super::plan::{Plan, Reality};
use crate::{Diagnosis, Effect, Options, SimPhysics, Verdict};

/// One trial's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    pub index: u64,
    /// The first concealed catalogued effect.
    pub truth: Option<Effect>,
    /// A second one (independent reality).
    pub second: Option<Effect>,
    /// Whether an effect outside the catalogue was concealed.
    pub outside: bool,
    pub drawn: Vec<(String, f64)>,
    /// The concealed effects' forms, where the varied reality drew them.
    pub forms: Vec<String>,
    pub verdict: Result<Verdict, String>,
    /// Every effect named.
    pub named: Vec<Effect>,
    /// Located mismatches no named effect explains.
    pub unexplained: usize,
    /// |fitted − true| / |true| of the scored parameter of the primary concealed effect, when
    /// it is named.
    pub param_error: Option<f64>,
    /// The same for every concealed effect named.
    pub param_errors: Vec<(Effect, f64)>,
    /// For every named effect: whether its held-out RMSE is lower with it than without.
    pub improved: Vec<bool>,
    pub fitted: Vec<f64>,
    /// Held-out RMSE after the fix over the noise floor, and before over the floor.
    pub heldout: Option<(f64, f64)>,
    /// The strongest test's score under the nominal model, and the threshold.
    pub strongest: (f64, f64),
    pub seconds: f64,
    /// Draws discarded before this one because their robot would pass through an obstacle.
    pub redrawn: usize,
}

impl Outcome {
    /// Whether it names an effect that was not concealed.
    #[must_use]
    pub fn names_absent(&self) -> bool {
        self.named
            .iter()
            .any(|e| Some(*e) != self.truth && Some(*e) != self.second)
    }
}

/// Trial `i`'s "real" recording and what it conceals.
pub(crate) fn real_recording(
    nominal: &Scenario,
    plan: Plan,
    i: u64,
) -> (Drawn, Result<Recording, String>) {
    let (drawn, mut recording) = concealing(nominal, plan, i);
    if plan.without_truth {
        if let Ok(r) = &mut recording {
            r.truth = None;
        }
    }
    (drawn, recording)
}

/// Trial `i`'s "real" recording, with its truth, and what it conceals.
fn concealing(nominal: &Scenario, plan: Plan, i: u64) -> (Drawn, Result<Recording, String>) {
    match plan.reality {
        Reality::Hilsim => {
            let (real, drawn) = real_scenario(nominal, plan.seed, i, plan.strength, plan.only);
            let recording = Emulation::new(&real, real.seed)
                .map(|e| e.run().recording)
                .map_err(|e| e.to_string());
            (drawn, recording)
        }
        Reality::Independent | Reality::Varied => {
            let mut d = Draws::new(plan.seed, i);
            let classes = draw_classes(&mut d, nominal, plan.only);
            let varied = plan.reality == Reality::Varied;
            let mut redrawn = 0;
            loop {
                let (mut drawn, nuisances) =
                    draw_independent(&classes, &mut d, plan.strength, nominal, varied);
                let seed = d.next() >> 1;
                let recording = hilsim_reality::record(nominal, &drawn.concealed, nuisances, seed);
                if redrawn < MAX_REDRAWS && drives_through_obstacle(nominal, &recording) {
                    redrawn += 1;
                    continue;
                }
                drawn.redrawn = redrawn;
                return (drawn, Ok(recording));
            }
        }
    }
}

/// Draws discarded at most per trial before one is kept whatever it does.
const MAX_REDRAWS: usize = 8;

/// Whether the independent reality's robot passes through an obstacle in `recording`, where the
/// nominal robot replaying the same commands touches none. That reality has no contacts, so a
/// draw that steers its robot into a wall (two wheels' radii 3 % apart turn it 0.5 rad over the
/// room's 3.9 m run) records a run no robot could make: seen from behind the wall, the room
/// is gone. Such a draw's parameters (and nuisances) are drawn again from the trial's own
/// stream, its effects kept, so the other trials keep theirs. A scenario whose nominal run
/// touches something by design is not checked (the nominal replay, a physics run, is made only
/// for a path that overlaps something).
fn drives_through_obstacle(nominal: &Scenario, recording: &Recording) -> bool {
    let Some(truth) = recording.truth.as_ref() else {
        return false;
    };
    let overlaps = truth
        .iter()
        .any(|s| nominal.robot_overlap([s.x_m, s.y_m]).is_some());
    let end_s = truth.last().map_or(0.0, |s| s.t_s);
    overlaps && replay_contacts(nominal, &recording.commands, end_s).is_empty()
}

impl Outcome {
    /// Trial `i` with what was drawn, before anything was diagnosed.
    fn before_diagnosis(i: u64, drawn: &Drawn) -> Self {
        Self {
            index: i,
            truth: drawn.effect,
            second: drawn.second.map(|s| s.0),
            outside: drawn.outside,
            drawn: drawn.params.clone(),
            forms: drawn.forms.clone(),
            verdict: Err(String::new()),
            named: Vec::new(),
            unexplained: 0,
            param_error: None,
            param_errors: Vec::new(),
            improved: Vec::new(),
            fitted: Vec::new(),
            heldout: None,
            strongest: (f64::NAN, f64::NAN),
            seconds: 0.0,
            redrawn: drawn.redrawn,
        }
    }
}

pub(crate) fn trial(nominal: &Scenario, plan: Plan, i: u64) -> Outcome {
    let started = Instant::now();
    let (drawn, recording) = real_recording(nominal, plan, i);
    let recording = match recording {
        Ok(r) => r,
        Err(err) => {
            return Outcome {
                verdict: Err(err),
                seconds: started.elapsed().as_secs_f64(),
                ..Outcome::before_diagnosis(i, &drawn)
            }
        }
    };
    // A fresh physics per trial: its beam cache belongs to one trajectory.
    let result = SimPhysics::new(nominal)
        .map_err(|e| format!("{e:#}"))
        .and_then(|physics| {
            crate::diagnose(&physics, &recording, &Options::default()).map_err(|e| e.to_string())
        });
    let mut outcome = Outcome::before_diagnosis(i, &drawn);
    match result {
        Err(e) => outcome.verdict = Err(e),
        Ok(diag) => score_diagnosis(&mut outcome, &drawn, &diag),
    }
    outcome.seconds = started.elapsed().as_secs_f64();
    outcome
}

/// Fills `o` from the diagnosis `diag` of a recording that concealed `drawn`.
fn score_diagnosis(o: &mut Outcome, drawn: &Drawn, diag: &Diagnosis) {
    o.strongest = (
        diag.sensors
            .iter()
            .map(|s| s.strongest)
            .fold(f64::NEG_INFINITY, f64::max),
        diag.threshold,
    );
    o.verdict = Ok(diag.verdict);
    o.named = diag.effects.iter().map(|e| e.fit.effect).collect();
    o.unexplained = diag.unexplained.len();
    o.improved = diag
        .effects
        .iter()
        .map(|e| e.fit.rmse_after < e.fit.rmse_before && e.fit.heldout_gain > 0.0)
        .collect();
    for (effect, truth) in drawn.catalogued() {
        if let Some(named) = diag.effects.iter().find(|e| e.fit.effect == effect) {
            let got = effect.scored(&named.fit.params);
            o.param_errors
                .push((effect, (got - truth).abs() / truth.abs()));
        }
    }
    let fit = diag.fitted.as_ref();
    o.fitted = fit.map(|f| f.params.clone()).unwrap_or_default();
    o.param_error = match (diag.verdict, drawn.effect) {
        (Verdict::Effect(v), Some(e)) if v == e => o
            .param_errors
            .iter()
            .find(|(x, _)| *x == e)
            .map(|(_, err)| *err),
        _ => None,
    };
    o.heldout = fit.map(|f| (f.rmse_after / f.noise_floor, f.rmse_before / f.noise_floor));
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

#[cfg(test)]
mod tests {
    use std::path::Path;

    use hilsim_fixtures::rooms::ROOM_4X3;
    use hilsim_recording::{CommandSample, TruthSample};

    use super::*;

    /// A 4 m × 3 m room, the robot starting at (1, 1) facing +x.
    fn room() -> Scenario {
        let robot = "[robot]\nstart = { x = 1.0, y = 1.0 }\nwheel_base_m = 0.23\n";
        Scenario::from_toml(
            &format!("name = \"through-a-wall\"\nduration_s = 4.0\n{ROOM_4X3}{robot}"),
            Path::new("through-a-wall.toml"),
        )
        .expect("the test's scenario")
    }

    /// A recording of commands `(left, right)` in force from t = 0 whose truth runs along
    /// `path` (one pose a second).
    fn recording(command: (f64, f64), path: &[(f64, f64)]) -> Recording {
        Recording {
            commands: vec![CommandSample {
                t_s: 0.0,
                left_mps: command.0,
                right_mps: command.1,
            }],
            truth: Some(
                path.iter()
                    .enumerate()
                    .map(|(i, &(x, y))| TruthSample {
                        t_s: i as f64,
                        x_m: x,
                        y_m: y,
                        yaw_rad: 0.0,
                    })
                    .collect(),
            ),
            ..Recording::default()
        }
    }

    #[test]
    fn a_run_through_a_wall_is_told_from_one_that_touches_by_design() {
        let room = room();
        // Commanded 0.5 m/s east for 4 s: the nominal robot stays clear (to x = 3).
        let clear = [(1.0, 1.0), (1.5, 1.0), (2.0, 1.0), (2.5, 1.0), (3.0, 1.0)];
        assert!(!drives_through_obstacle(
            &room,
            &recording((0.5, 0.5), &clear)
        ));
        // The same commands, but the real robot veered south through the wall.
        let veered = [(1.0, 1.0), (1.5, 0.7), (2.0, 0.3), (2.5, -0.1), (3.0, -0.5)];
        assert!(drives_through_obstacle(
            &room,
            &recording((0.5, 0.5), &veered)
        ));
        // Commanded at 1 m/s east, the nominal robot itself reaches the east wall: touching is
        // the scenario's doing, and nothing is redrawn.
        let into_the_wall = [(1.0, 1.0), (2.0, 1.0), (3.0, 1.0), (3.8, 1.0), (3.9, 1.0)];
        assert!(!drives_through_obstacle(
            &room,
            &recording((1.0, 1.0), &into_the_wall)
        ));
        // Without truth there is nothing to check.
        let mut blind = recording((0.5, 0.5), &veered);
        blind.truth = None;
        assert!(!drives_through_obstacle(&room, &blind));
    }
}
