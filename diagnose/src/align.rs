//! Align: put the real recording on the simulation's clock and in its world. With `truth.csv`
//! (a simulator's, or a motion-capture system's) the real trajectory is known; without it, it is
//! estimated from the recording (`estimate.rs`). Either way the recording must be a run of the
//! scenario: long enough, with a sensor in common, starting where the scenario starts.

use std::sync::Mutex;

use hilsim_recording::{Recording, TruthSample};

use crate::catalogue::{Effect, Sensor};
use crate::error::MismatchError;
use crate::estimate::{estimate_trajectory, DeadReckoning, Estimate};
use crate::physics::{Hypothesis, Physics};
use crate::sparse_truth;
use crate::trajectory::{wrap, Trajectory};

/// The shortest recording diagnosed, seconds: two training and two held-out blocks.
pub const MIN_DURATION_S: f64 = 8.0;
/// How far the recorded start may lie from the scenario's, metres.
pub const START_TOLERANCE_M: f64 = 0.3;
/// How far the recorded start heading may lie from the scenario's, degrees.
pub const START_TOLERANCE_DEG: f64 = 15.0;
/// Position noise assumed for a recorded trajectory (a motion-capture system's ~1 mm), metres.
pub const TRUTH_POSITION_SD_M: f64 = 0.001;

/// Where the real trajectory came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Alignment {
    /// The recording's `truth.csv`.
    Truth,
    /// Estimated from the recording: the replayed commands (or the encoders), corrected by
    /// matching the lidar's scans to the scenario's world.
    Estimated,
}

impl Alignment {
    /// The name used in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Alignment::Truth => "truth.csv",
            Alignment::Estimated => "estimated (scan-to-map matching)",
        }
    }
}

/// The aligned run.
#[derive(Debug, Clone)]
pub(crate) struct Aligned {
    pub trajectory: Trajectory,
    pub alignment: Alignment,
    /// The recording's end, seconds.
    pub end_s: f64,
    /// The standard deviation of the trajectory's positions, metres: a motion-capture system's
    /// ~1 mm for `truth.csv`, the scan matching's own for an estimate.
    pub position_sd_m: f64,
    /// The standard deviation of its headings, radians (0 for `truth.csv`).
    pub yaw_sd_rad: f64,
    /// What an estimate followed between the lidar's corrections (`None` for `truth.csv`).
    pub reckoned: Option<DeadReckoning>,
    /// With [`DeadReckoning::Scans`], the matches smoothed along the encoders between them.
    pub smoothed: Option<Trajectory>,
    /// What an estimate's revolutions were matched along ([`Estimate::matched_along`]; `None`
    /// for `truth.csv`): estimated again, it is matched along the same.
    pub matched_along: Option<DeadReckoning>,
    /// What the path the drive is judged against followed between the lidar's corrections,
    /// when the drive is judged against an estimate (`None` otherwise).
    pub drive_reckoned: Option<DeadReckoning>,
    /// The drive effects an estimate's commands were replayed under (nominal at first).
    pub replayed: Hypothesis,
    /// What the user should know (sensors missing on one side).
    pub notes: Vec<String>,
}

/// Aligns `recording` with the scenario behind `physics`.
///
/// # Errors
/// [`MismatchError::Refused`] when the recording cannot be a run of the scenario (too short,
/// no sensor in common, a different start) or its trajectory cannot be had.
pub(crate) fn align(
    physics: &dyn Physics,
    recording: &Recording,
) -> Result<Aligned, MismatchError> {
    let declared = physics.declared();
    let end_s = recording.duration_s();
    if end_s < MIN_DURATION_S {
        return Err(MismatchError::Refused(format!(
            "the recording lasts {end_s:.1} s: too short to diagnose (at least {MIN_DURATION_S} s, \
             so that both the training and the held-out half hold two blocks)"
        )));
    }
    let mut notes = Vec::new();
    let mut common = Vec::new();
    for (name, sim, real) in [
        ("lidar", declared.lidar.is_some(), recording.lidar.is_some()),
        (
            "sonar",
            declared.sonar_half_angle_deg.is_some(),
            recording.sonar.is_some(),
        ),
        ("odometer", declared.odometer, recording.odometry.is_some()),
    ] {
        match (sim, real) {
            (true, true) => common.push(name),
            (true, false) => notes.push(format!(
                "the scenario has a {name} but the recording has none: not diagnosed"
            )),
            (false, true) => notes.push(format!(
                "the recording has a {name} the scenario lacks: not diagnosed"
            )),
            (false, false) => {}
        }
    }
    if common.is_empty() && recording.truth.is_none() {
        return Err(MismatchError::Refused(
            "the recording and the scenario have no sensor in common and the recording has no \
             truth.csv: nothing to compare"
                .into(),
        ));
    }
    let mut first_smoothed = None;
    let mut matched_along = None;
    let (trajectory, alignment, position_sd_m, yaw_sd_rad, reckoned) = match &recording.truth {
        Some(truth) if !truth.is_empty() => (
            truth_trajectory(truth, recording, declared.wheel_base_m, &mut notes)?,
            Alignment::Truth,
            TRUTH_POSITION_SD_M,
            0.0,
            None,
        ),
        _ => {
            if declared.lidar.is_none() || recording.lidar.is_none() {
                return Err(MismatchError::Refused(
                    "the recording has no truth.csv, and without a lidar its trajectory cannot \
                     be estimated against the scenario's world"
                        .into(),
                ));
            }
            let Estimate {
                trajectory,
                uncertainty: sd,
                reckoned,
                smoothed,
                matched_along: along,
            } = estimate_trajectory(
                physics,
                recording,
                end_s,
                &Hypothesis::nominal(),
                DeadReckoning::Commands,
                None,
            )?;
            first_smoothed = smoothed;
            matched_along = Some(along);
            notes.push(format!(
                "no truth.csv: the trajectory is estimated by matching the lidar to the \
                 scenario's world (position s.d. {:.1} mm, heading {:.2} mrad); every sensor is \
                 judged against it with that uncertainty in its noise and no whiteness test \
                 (the estimate's errors are shared by neighbouring readings; the encoders' \
                 travel, which carries the path's error for tens of seconds, is predicted from \
                 the readings before it), and an effect that shifts every range alike is \
                 partly absorbed into it",
                sd.position_m * 1000.0,
                sd.yaw_rad * 1000.0
            ));
            (
                trajectory,
                Alignment::Estimated,
                sd.position_m,
                sd.yaw_rad,
                Some(reckoned),
            )
        }
    };
    let start = trajectory.pose_at(0.0);
    let off = (start.x - declared.start.x).hypot(start.y - declared.start.y);
    let turned = wrap(start.yaw - declared.start.yaw).abs().to_degrees();
    if off > START_TOLERANCE_M || turned > START_TOLERANCE_DEG {
        return Err(MismatchError::Refused(format!(
            "the recording starts at ({:.2}, {:.2}) m heading {:.0}° but the scenario `{}` at \
             ({:.2}, {:.2}) m heading {:.0}°: not a run of this scenario",
            start.x,
            start.y,
            start.yaw.to_degrees(),
            declared.scenario,
            declared.start.x,
            declared.start.y,
            declared.start.yaw.to_degrees()
        )));
    }
    Ok(Aligned {
        trajectory,
        alignment,
        end_s,
        position_sd_m,
        yaw_sd_rad,
        reckoned,
        smoothed: first_smoothed,
        matched_along,
        drive_reckoned: None,
        replayed: Hypothesis::nominal(),
        notes,
    })
}

/// The trajectory of `truth`: filled between its poses by the encoders when it is sparser
/// than they are (`sparse_truth.rs`), with a note saying so.
fn truth_trajectory(
    truth: &[TruthSample],
    recording: &Recording,
    wheel_base_m: f64,
    notes: &mut Vec<String>,
) -> Result<Trajectory, MismatchError> {
    let Some(odometry) = recording
        .odometry
        .as_deref()
        .filter(|o| sparse_truth::is_sparse(truth, o))
    else {
        return Trajectory::new(truth);
    };
    notes.push(format!(
        "truth.csv holds a pose every {:.2} s, sparser than the encoders: between its poses the \
         path follows the encoders' shape, bent to meet each pose, and the encoders are judged \
         by their travel over spans of its poses",
        (truth[truth.len() - 1].t_s - truth[0].t_s) / (truth.len() - 1).max(1) as f64,
    ));
    Trajectory::new(&sparse_truth::filled_by_encoders(
        truth,
        odometry,
        wheel_base_m,
    ))
}

/// The trajectories a diagnosis has estimated again ([`realign`]), by the effects they were
/// estimated under (in any order) and what they followed: its rounds ask again for a path
/// under effects already tried (the same effects named in another order), and each estimate
/// matches every revolution of the lidar anew. One recording's: a diagnosis holds one.
#[derive(Default)]
pub(crate) struct Estimates(Mutex<Vec<(EstimateKey, Estimate)>>);

/// The effects (sorted, parameters bit for bit), the dead reckoning followed and what the
/// revolutions were matched along.
type EstimateKey = (
    Vec<(Effect, Vec<u64>)>,
    DeadReckoning,
    Option<DeadReckoning>,
);

/// Estimates kept at most (each a trajectory of the recording's length).
const MAX_ESTIMATES: usize = 16;

impl Estimates {
    /// [`estimate_trajectory`] of `recording` (the one this cache is for), made once.
    fn get_or_estimate(
        &self,
        physics: &dyn Physics,
        recording: &Recording,
        end_s: f64,
        hypothesis: &Hypothesis,
        preferred: DeadReckoning,
        matched_along: Option<DeadReckoning>,
    ) -> Result<Estimate, MismatchError> {
        let mut effects: Vec<(Effect, Vec<u64>)> = hypothesis
            .effects
            .iter()
            .map(|(e, p)| (*e, p.iter().map(|v| v.to_bits()).collect()))
            .collect();
        effects.sort();
        let key = (effects, preferred, matched_along);
        let found = self
            .0
            .lock()
            .ok()
            .and_then(|done| done.iter().find(|(k, _)| *k == key).map(|(_, e)| e.clone()));
        if let Some(estimate) = found {
            return Ok(estimate);
        }
        let estimate = estimate_trajectory(
            physics,
            recording,
            end_s,
            hypothesis,
            preferred,
            matched_along,
        )?;
        if let Ok(mut done) = self.0.lock() {
            if done.len() >= MAX_ESTIMATES {
                done.remove(0);
            }
            done.push((key, estimate.clone()));
        }
        Ok(estimate)
    }
}

/// `aligned` (an estimated trajectory) estimated again with the lidar predicted and the
/// commands replayed under `hypothesis` (and the drive effects `aligned` was replayed under): a
/// lidar effect that the nominal model cannot take is partly absorbed into the scan matching's
/// corrections, so an effect's fit is refined against the trajectory its own model gives (one
/// step of alternating the alignment and the fit); a drive effect (motor lag) moves the path
/// between the lidar's corrections.
///
/// # Errors
/// As [`align`].
pub(crate) fn realign(
    physics: &dyn Physics,
    recording: &Recording,
    estimates: &Estimates,
    aligned: &Aligned,
    hypothesis: &Hypothesis,
) -> Result<Aligned, MismatchError> {
    let full = aligned
        .replayed
        .effects
        .iter()
        .filter(|(e, _)| hypothesis.param_of(*e, 0).is_none())
        .fold(hypothesis.clone(), |h, (e, p)| h.and(*e, p.clone()));
    let replayed = full
        .effects
        .iter()
        .filter(|(e, _)| e.sensor() == Sensor::Drive)
        .fold(Hypothesis::nominal(), |h, (e, p)| h.and(*e, p.clone()));
    let preferred = aligned.reckoned.unwrap_or(DeadReckoning::Commands);
    let estimate = estimates.get_or_estimate(
        physics,
        recording,
        aligned.end_s,
        &full,
        preferred,
        aligned.matched_along,
    )?;
    Ok(aligned.estimated_again(estimate, replayed))
}

impl Aligned {
    /// This run aligned by another estimate of its trajectory.
    fn estimated_again(&self, estimate: Estimate, replayed: Hypothesis) -> Self {
        Self {
            trajectory: estimate.trajectory,
            alignment: self.alignment,
            end_s: self.end_s,
            position_sd_m: estimate.uncertainty.position_m,
            yaw_sd_rad: estimate.uncertainty.yaw_rad,
            reckoned: Some(estimate.reckoned),
            smoothed: estimate.smoothed,
            matched_along: Some(estimate.matched_along),
            drive_reckoned: self.drive_reckoned,
            replayed,
            notes: self.notes.clone(),
        }
    }
}

/// The trajectory of `aligned` (an estimated one) estimated again following the encoders
/// between the lidar's corrections, for judging the drive independently of the commands;
/// `None` when the recording has no encoders to follow.
///
/// # Errors
/// As [`align`].
pub(crate) fn along_encoders(
    physics: &dyn Physics,
    recording: &Recording,
    aligned: &Aligned,
) -> Result<Option<Aligned>, MismatchError> {
    if recording.odometry.as_ref().is_none_or(|o| o.len() < 2) {
        return Ok(None);
    }
    let estimate = estimate_trajectory(
        physics,
        recording,
        aligned.end_s,
        &Hypothesis::nominal(),
        DeadReckoning::Encoders,
        None,
    )?;
    Ok(estimate
        .reckoned
        .follows_the_encoders()
        .then(|| aligned.estimated_again(estimate, Hypothesis::nominal())))
}
