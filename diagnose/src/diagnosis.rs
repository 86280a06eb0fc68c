//! The orchestration of one diagnosis, stage by stage: align, gather the sensors' residuals,
//! the nominal evidence, fit the candidates, re-align under a lidar effect, conclude, plot.

use hilsim_recording::Recording;

use crate::align::{self, Aligned, Alignment, Estimates};
use crate::catalogue::{Effect, SearchLimits, Sensor};
use crate::conclude::{conclude, declared_cone, Conclusion, Left, Nominal};
use crate::crab;
use crate::dropout;
use crate::error::MismatchError;
use crate::estimate::DeadReckoning;
use crate::explain::{self, CandidateFit, FitRows, RmseOver};
use crate::health;
use crate::locate::{self, Evidence, TestKind};
use crate::outcome::{
    Diagnosis, Options, SensorSummary, ESTIMATED_MOUNT_MIN_M, ESTIMATED_PATH_TIMING_S,
};
use crate::physics::{Hypothesis, Physics};
use crate::plot;
use crate::residuals::{self, Context, Covariate, SensorData};
use crate::select::{self, hypothesis_of, Selection};
use crate::sparse_truth;
use crate::stamps;
use crate::trajectory::Trajectory;
use crate::wheel_spans::{self, SpanLimits};
use hilsim_report::svg::fmt_sig;

/// Rounds (at most) of estimating the trajectory again under a lidar effect's fit and refitting
/// it (against an estimated trajectory only); they stop once each free parameter moves by less
/// than [`REALIGN_SETTLED`] of its value.
const REALIGN_ROUNDS: usize = 6;
const REALIGN_SETTLED: f64 = 0.02;

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
    diagnose_with_progress(physics, recording, options, &mut |_| {})
}

/// The stages of a diagnosis, as [`diagnose_with_progress`] reports them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Aligning the recording with the simulation (the trajectory: truth, or estimated).
    Aligning,
    /// Predicting every reading from the simulation.
    Gathering,
    /// Looking for where the two disagree.
    Locating,
    /// Fitting each catalogued effect.
    Fitting,
    /// Choosing the verdict and drawing the plots.
    Concluding,
}

impl Stage {
    /// In words.
    #[must_use]
    pub fn describe(self) -> &'static str {
        match self {
            Self::Aligning => "aligning the recording with the simulation",
            Self::Gathering => "predicting every reading from the simulation",
            Self::Locating => "locating where they disagree",
            Self::Fitting => "fitting the catalogued effects",
            Self::Concluding => "concluding",
        }
    }
}

/// As [`diagnose`], telling `progress` as each stage starts (for a long diagnosis's status
/// line; the library itself prints nothing).
///
/// # Errors
/// As [`diagnose`].
pub fn diagnose_with_progress(
    physics: &dyn Physics,
    recording: &Recording,
    options: &Options,
    progress: &mut dyn FnMut(Stage),
) -> Result<Diagnosis, MismatchError> {
    progress(Stage::Aligning);
    let aligned = align::align(physics, recording)?;
    let mut options = options.against(&aligned);
    // Encoders stamped no better than this show no lead of theirs within it (`stamps.rs`).
    if let Some(scatter_s) = recording
        .odometry
        .as_deref()
        .and_then(stamps::encoder_scatter_s)
    {
        options.encoder_timing_s = options.encoder_timing_s.max(scatter_s);
    }
    // A world known only to a map's cells: a lidar departure within them is as likely the
    // map's as the lidar's.
    let world_m = physics
        .declared()
        .lidar
        .map_or(0.0, |l| l.world_uncertainty_m);
    options.floors.lidar_m = options.floors.lidar_m.max(world_m);
    let options = &options;
    // Against an estimate, the drive is judged along a second one that follows the encoders
    // between the lidar's corrections: the first follows the commands, so the drive's residuals
    // along it would be the commands against themselves.
    let along_encoders = match aligned.reckoned {
        Some(DeadReckoning::Commands) => align::along_encoders(physics, recording, &aligned)?,
        // A path that already follows the encoders (a twin's taken over the commands' replay)
        // is the drive's reference itself.
        Some(r) if r.follows_the_encoders() && !recording.commands.is_empty() => {
            Some(aligned.clone())
        }
        _ => None,
    };
    let aligned = Aligned {
        drive_reckoned: along_encoders.as_ref().and_then(|a| a.reckoned),
        ..aligned
    };
    let estimates = Estimates::default();
    let aligned = replayed_under_drive(
        physics,
        recording,
        &estimates,
        aligned,
        along_encoders.as_ref(),
        options,
    )?;
    let ctx = context(physics, recording, &estimates, &aligned, options);
    let mut notes = aligned.notes.clone();
    let drive_ctx = along_encoders.as_ref().map(|a| along(&ctx, a));
    progress(Stage::Gathering);
    let dead = health::dead_or_stuck(&ctx);
    let mut data = gather(&ctx, drive_ctx.as_ref(), &aligned, &mut notes)?;
    progress(Stage::Locating);
    let mut nominal = nominal_evidence(&ctx, &aligned, &data, options);
    progress(Stage::Fitting);
    let Selection {
        named,
        mut candidates,
    } = select::select(&ctx, &data, options);
    progress(Stage::Concluding);
    let (named, realigned) =
        realign_lidar(&ctx, &aligned, named, &mut candidates, &mut data, options)?;
    let realigned_ctx = realigned.as_ref().map(|a| along(&ctx, a));
    let final_ctx = realigned_ctx.as_ref().unwrap_or(&ctx);
    let named = rejudged_along(
        realigned_ctx.as_ref(),
        &aligned,
        named,
        &mut candidates,
        &mut data,
        &mut nominal,
        options,
    )?;
    // Against the scans' own path, a lidar turned on its mount moves the path sideways, which
    // the wheels cannot (`crab.rs`).
    let crabbed = crab_mount(
        final_ctx,
        realigned.as_ref().unwrap_or(&aligned),
        &named,
        &mut candidates,
        options,
    )?;
    let crab_ctx = crabbed.as_ref().map(|(_, a)| along(&ctx, a));
    let final_ctx = crab_ctx.as_ref().unwrap_or(final_ctx);
    let named = match (&crabbed, &crab_ctx) {
        (Some((fit, _)), Some(along)) => {
            let (mut named, again) =
                rejudge_along(along, &aligned, named, &mut candidates, &mut data, options)?;
            nominal = again;
            named.push(fit.clone());
            named.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
            named
        }
        _ => named,
    };
    let path_so_far = crabbed
        .as_ref()
        .map(|(_, a)| a)
        .or(realigned.as_ref())
        .unwrap_or(&aligned);
    // Against the scans' own path, the encoders are judged span by span
    // (`wheel_spans.rs`): a lidar stamped late against them turns late, wheels
    // farther apart than declared count more travel apart for a turn, and wheels of another
    // size another travel.
    let FromSpans {
        delay: lagged,
        wheels,
    } = from_spans(final_ctx, path_so_far, &mut candidates, options);
    let lag_ctx = lagged.as_ref().map(|(_, a)| along(&ctx, a));
    let final_ctx = lag_ctx.as_ref().unwrap_or(final_ctx);
    let mut named = rejudged_along(
        lag_ctx.as_ref(),
        &aligned,
        named,
        &mut candidates,
        &mut data,
        &mut nominal,
        options,
    )?;
    // Against a truth sparser than the encoders, their timing, base and sizes are read span by
    // span between its poses, as against the scans' own path.
    let wheels = if wheels.is_empty() {
        encoders_over_truth(final_ctx, &mut candidates, options)
    } else {
        wheels
    };
    // Along the scans' own path, or a sparse truth, the encoders' effects are their spans'.
    // Judged reading by reading along a path that skids in its turns, the encoders do not tell
    // their base or size (each reading's skid is taken for a shared error of the path), and a
    // lead of theirs on the speed's changes (a delay, a slip) is the lidar's delay seen from
    // their side; against a truth of a pose every few seconds, a lead is told by the speed at
    // each reading, which a scatter of their stamps blurs.
    if !wheels.is_empty() {
        // The encoders' effects fitted to their readings (not a mount read from the path).
        let from_readings =
            |c: &CandidateFit| c.sensor == Sensor::Odometer && !c.rmse_over.of_path_motion();
        named.retain(|c| !from_readings(c));
        candidates.retain(|c| !from_readings(c));
        for (fit, earns) in wheels {
            candidates.retain(|c| c.effect != fit.effect);
            if earns {
                named.push(fit.clone());
            }
            candidates.push(fit);
        }
        candidates.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
    }
    named.extend(lagged.as_ref().map(|(fit, _)| fit.clone()));
    named.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
    let path_so_far = lagged.as_ref().map_or(path_so_far, |(_, a)| a);
    // A lidar mount offset or delay the estimated path took up, seen by the sonar and the
    // encoders: whichever gains more where both are found (a mount of a decimetre and degrees
    // mimics a delay of a fifth of a second on a drive that turns as it speeds up).
    let mut seen_through: Option<(CandidateFit, Aligned)> = None;
    for effect in [
        Effect::LidarMountOffset,
        Effect::SensorLatency(Sensor::Lidar),
    ] {
        let found = through_path(
            effect,
            final_ctx,
            path_so_far,
            &named,
            &mut candidates,
            &data,
            options,
        )?;
        if let Some(found) = found {
            if seen_through
                .as_ref()
                .is_none_or(|(fit, _)| found.0.heldout_gain > fit.heldout_gain)
            {
                seen_through = Some(found);
            }
        }
    }
    let through_effect = seen_through.as_ref().map(|(fit, _)| fit.effect);
    let (through_fit, through_aligned) = seen_through.unzip();
    // The path that took it up and the sensors' data along it, for the plots.
    let through_before = through_fit.is_some().then(|| (final_ctx, data.clone()));
    let through_ctx = through_aligned.as_ref().map(|a| along(&ctx, a));
    let final_ctx = through_ctx.as_ref().unwrap_or(final_ctx);
    let named = match (through_fit, &through_ctx) {
        (Some(fit), Some(along)) => {
            let (mut named, again) =
                rejudge_along(along, &aligned, named, &mut candidates, &mut data, options)?;
            nominal = again;
            named.push(fit);
            named.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
            named
        }
        _ => named,
    };
    let named = if along_encoders.is_some() {
        drive_after_odometer_latency(
            final_ctx,
            &aligned,
            named,
            &mut candidates,
            &mut data,
            options,
        )?
    } else {
        named
    };
    let mut named = named;
    // The lidar's dropout, fitted on its reads and losses apart from the ranges (it moves none).
    if let Some(dropout) = dropout::fitted(final_ctx, options) {
        if dropout::earns_place(&dropout, options) {
            named.push(dropout.clone());
            named.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
        }
        candidates.push(dropout);
        candidates.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
    }
    let mut left = structure_left(final_ctx, &data, &nominal, &named);
    let mut before = named.len();
    let path_recorded = !final_ctx.estimated;
    let mut named = explaining_their_sensor(&nominal, &left, named, path_recorded, options);
    // An effect refused changes what its sensor's others leave: they are judged again without it.
    while named.len() < before {
        left = structure_left(final_ctx, &data, &nominal, &named);
        before = named.len();
        named = explaining_their_sensor(&nominal, &left, named, path_recorded, options);
    }
    let before = named.len();
    named = within_the_search(named, &mut notes);
    if named.len() < before {
        left = structure_left(final_ctx, &data, &nominal, &named);
    }
    nominal_where_none_named(&mut left, &named, &nominal);
    notes.extend(lead_within_the_stamps(&candidates, options));
    if final_ctx.estimated {
        let before = named.len();
        named = within_the_paths_scale(&left, named, nominal.threshold, options, &mut notes);
        if named.len() < before {
            nominal_where_none_named(&mut left, &named, &nominal);
        }
    }
    let Conclusion {
        verdict,
        located,
        effects,
        unexplained,
        world,
        explanation,
    } = conclude(&ctx, &nominal, named, &left, &dead, options);
    let significant: Vec<Evidence> = nominal
        .evidence
        .iter()
        .filter(|e| e.score > nominal.threshold)
        .cloned()
        .collect();
    let fitted = effects.first().map(|e| e.fit.clone());
    // An effect seen through the path is shown as the sensors saw it along the path that took
    // it up (before) and along the one put back by it (after).
    let through_before = through_before
        .as_ref()
        .filter(|_| fitted.as_ref().map(|f| f.effect) == through_effect)
        .map(|(ctx, data)| plot::Before {
            ctx,
            data: data.as_slice(),
        });
    let plots = plot::plots(
        final_ctx,
        &data,
        located.as_ref(),
        fitted.as_ref(),
        through_before,
    );
    let estimated_path =
        (aligned.alignment == Alignment::Estimated).then(|| final_ctx.trajectory.samples());
    Ok(Diagnosis {
        verdict,
        located,
        explanation,
        fitted,
        effects,
        unexplained,
        world,
        candidates,
        sensors: nominal.sensors,
        evidence: significant,
        threshold: nominal.threshold,
        alignment: aligned.alignment,
        notes,
        plots,
        estimated_path,
    })
}

/// A sensor whose effects were all dropped is left with its nominal structure.
fn nominal_where_none_named(left: &mut [Left], named: &[CandidateFit], nominal: &Nominal) {
    for l in left {
        if !named.iter().any(|c| c.effect.shows_in(l.sensor)) {
            l.evidence = nominal
                .evidence
                .iter()
                .filter(|e| e.sensor == l.sensor)
                .cloned()
                .collect();
        }
    }
}

/// The named effects, less those whose fit sits at a limit of its search
/// ([`SearchLimits::at_limit`]): the likelihood still rose there, so the value is a bound, not
/// an estimate, and its standard error (the curvature at a point that is no maximum) means
/// nothing. What the log shows is then something the effect bends towards without taking its
/// shape, a world built wrong, or a path the matches lost; `notes` says which parameter stopped
/// where, and what it would explain is left unexplained.
fn within_the_search(named: Vec<CandidateFit>, notes: &mut Vec<String>) -> Vec<CandidateFit> {
    named
        .into_iter()
        .filter(|c| {
            let Some((spec, value)) = c
                .effect
                .params()
                .iter()
                .zip(&c.params)
                .find(|(spec, &value)| SearchLimits::at_limit(spec, value))
            else {
                return true;
            };
            notes.push(format!(
                "{} is not named: its best fit stops at the edge of its search ({} = {} {}, \
                 searched over {} to {}), so its size is not identifiable from this log",
                c.effect.name(),
                spec.name,
                fmt_sig(*value),
                spec.unit,
                fmt_sig(spec.lo),
                fmt_sig(spec.hi),
            ));
            false
        })
        .collect()
}

/// The named effects, less a wheel radius within what the lidar's error left by range can
/// make of the estimated path's scale. Without truth the encoders are judged against the path
/// matched from the lidar, whose lengths are the lidar's ranges: ranges read a share `s` long
/// at the range where the robot sees its world make every distance it travels about `s` long
/// too, which the encoders show as wheels `1 − s` of their size. While the lidar leaves a
/// counting error by range (its median in a range bin less the overall median, a share of that
/// bin's middle range) at least as large as the wheels' departure, the wheel radius is not
/// identifiable from this log and is not named; `notes` says why. The median, not the mean:
/// a scan matcher follows what most of a scan's readings say, while a mean follows the few
/// readings far off (rays a map built from the log lets through the gaps of its far walls).
fn within_the_paths_scale(
    left: &[Left],
    named: Vec<CandidateFit>,
    threshold: f64,
    options: &Options,
    notes: &mut Vec<String>,
) -> Vec<CandidateFit> {
    let lidar_share = left
        .iter()
        .filter(|l| l.sensor == Sensor::Lidar)
        .flat_map(|l| l.evidence.iter())
        .filter(|e| {
            e.test == TestKind::BiasAgainst
                && e.covariate == Some(Covariate::Range)
                && e.counts(threshold, &options.floors)
        })
        .filter_map(|e| {
            let (lo, hi) = e.range?;
            let middle_m = 0.5 * (lo + hi);
            (middle_m > 0.0).then(|| e.median_m.abs() / middle_m)
        })
        .fold(0.0_f64, f64::max);
    if lidar_share == 0.0 {
        return named;
    }
    named
        .into_iter()
        .filter(|c| {
            if c.effect != Effect::OdometerWheelRadius {
                return true;
            }
            let departure = c.params.iter().map(|s| (s - 1.0).abs()).fold(0.0, f64::max);
            if departure > lidar_share {
                return true;
            }
            notes.push(format!(
                "odometer_wheel_radius (left {:.1} %, right {:.1} % of nominal) is not named: the \
                 path the encoders are judged against is matched from the lidar, whose error left \
                 by range ({:.2} % of the range) scales it by as much, so the wheels' size is not \
                 identifiable from this log",
                100.0 * c.params[0],
                100.0 * c.params[1],
                100.0 * lidar_share
            ));
            false
        })
        .collect()
}

/// Share of the normal score of a sensor's main structure (its strongest counting test under
/// the nominal model) at or above which its named effects are taken to leave it standing: the
/// score of a χ² statistic grows as its cube root, so 0.95 of the score is 86 % of the
/// statistic. A periodic range error outside the catalogue keeps nearly all (0.98 and more) of
/// its main structure's score under the lidar effects that each mimic a part of it, while a
/// real effect beside another simulator's own structure leaves much less (0.8–0.9) standing.
const MAX_MAIN_LEFT: f64 = 0.95;

/// The named effects, less those of a sensor whose main structure they do not explain: the
/// same test (kind and variable) under the sensor's named effects still counts and keeps more
/// than [`MAX_MAIN_LEFT`] of its nominal score. Effects that each explain a part of physics
/// outside the catalogue (a periodic range error is part reflectivity walk, part warm-up, part
/// incidence over a room's ranges) gain on held-out data, but leave its shape standing; the
/// sensor's structure is then unexplained, not theirs. Structure that is not the sensor's main
/// one (a small nuisance beside a large effect) does not count against them, except against
/// a range bias: it must leave nothing clustered by range ([`select::leaves_range_structure`]).
fn explaining_their_sensor(
    nominal: &Nominal,
    left: &[Left],
    named: Vec<CandidateFit>,
    path_recorded: bool,
    options: &Options,
) -> Vec<CandidateFit> {
    let threshold = nominal.threshold;
    let unexplained_sensor = |sensor: Sensor| -> bool {
        let Some(main) = main_structure(nominal, sensor, options) else {
            return false;
        };
        left.iter()
            .filter(|l| l.sensor == sensor)
            .flat_map(|l| l.evidence.iter())
            .find(|e| e.test == main.test && e.covariate == main.covariate)
            .is_some_and(|after| {
                after.counts(threshold, &options.floors)
                    && after.score > MAX_MAIN_LEFT * main.score
                    && after.size_m > select::MAX_MAIN_SIZE_LEFT * main.size_m
            })
    };
    // An effect read from the path's own motion (a mount's crab, the encoders' spans) explains
    // that motion, not its sensor's readings: its held-out gain there is its evidence.
    named
        .into_iter()
        .filter(|c| {
            !c.effect.moves_readings()
                || c.rmse_over.of_path_motion()
                || !unexplained_sensor(c.effect.sensor())
                || (path_recorded && explains_its_own_variable(c, nominal, left, options))
        })
        .filter(|c| {
            !select::leaves_range_structure(c, &nominal.evidence, left, threshold, &options.floors)
        })
        .collect()
}

/// `sensor`'s main structure: its strongest test under the nominal model that counts.
fn main_structure<'a>(
    nominal: &'a Nominal,
    sensor: Sensor,
    options: &Options,
) -> Option<&'a Evidence> {
    nominal
        .evidence
        .iter()
        .find(|e| e.sensor == sensor && e.counts(nominal.threshold, &options.floors))
}

/// Share of the normal score of a structure against one of an effect's own variables at or
/// below which the sensor's named effects are taken to explain it: half the score is an eighth
/// of the χ² statistic (the score grows as its cube root).
const MAX_OWN_LEFT: f64 = 0.5;

/// Whether `c` explains a structure of its sensor against one of its own variables other than
/// the sensor's main one: the residuals' mean departs against it under the nominal model by a
/// test that counts, and under the named effects keeps at most [`MAX_OWN_LEFT`] of its score.
/// A structure that is only the main one's shadow through a path that ties two variables
/// together (the range and the time, as a room is crossed) cannot be explained while the main
/// one stands; one that is explained so is a mechanism of its own beside it (a warm-up in time
/// beside a map's error at far range on a real log, which it leaves standing whole).
fn explains_its_own_variable(
    c: &CandidateFit,
    nominal: &Nominal,
    left: &[Left],
    options: &Options,
) -> bool {
    let threshold = nominal.threshold;
    let main = main_structure(nominal, c.sensor, options);
    let own: Vec<Covariate> = c
        .effect
        .entry()
        .variables()
        .iter()
        .filter_map(|v| v.covariate())
        .filter(|&v| main.is_none_or(|m| m.covariate != Some(v)))
        .collect();
    nominal
        .evidence
        .iter()
        .filter(|e| e.sensor == c.sensor && e.test == TestKind::BiasAgainst)
        .filter(|e| e.covariate.is_some_and(|v| own.contains(&v)))
        .filter(|e| e.counts(threshold, &options.floors))
        .any(|before| {
            left.iter()
                .filter(|l| l.sensor == c.sensor)
                .flat_map(|l| l.evidence.iter())
                .find(|e| e.test == before.test && e.covariate == before.covariate)
                .is_some_and(|after| after.score <= MAX_OWN_LEFT * before.score)
        })
}

/// Each sensor's tests under its named effects (the nominal evidence where none is named).
fn structure_left(
    ctx: &Context<'_>,
    data: &[SensorData],
    nominal: &Nominal,
    named: &[CandidateFit],
) -> Vec<Left> {
    let names = |id: u32| ctx.physics.object_name(id);
    data.iter()
        .map(|d| {
            let mine: Vec<CandidateFit> = named
                .iter()
                .filter(|c| c.effect.shows_in(d.sensor) && c.effect.moves_readings())
                .cloned()
                .collect();
            let evidence = if mine.is_empty() {
                nominal
                    .evidence
                    .iter()
                    .filter(|e| e.sensor == d.sensor)
                    .cloned()
                    .collect()
            } else {
                let all = d.rows(None);
                let f = residuals::fits(d, &all, &ctx.predict(d, &hypothesis_of(&mine), &all));
                let mut ev = locate::locate(d, &all, &f, &names, !ctx.estimated);
                ev.sort_by(|a, b| b.score.total_cmp(&a.score));
                ev
            };
            Left {
                sensor: d.sensor,
                evidence,
            }
        })
        .collect()
}

impl Options {
    /// These options against the trajectory `aligned`: an estimated one raises the encoders'
    /// floor to its position's standard deviation. The encoders' cumulative travel is compared
    /// with the path's, whose error at any time is the estimate's (correlated over seconds by
    /// the smoother, so a slow departure of that size is the reference's, not the sensor's).
    /// The drive compares 0.1 s increments, in which that error mostly cancels.
    fn against(&self, aligned: &Aligned) -> Self {
        let mut options = self.clone();
        if aligned.alignment == Alignment::Estimated {
            options.floors.odometer_m = options.floors.odometer_m.max(aligned.position_sd_m);
            options.path_timing_s = options.path_timing_s.max(ESTIMATED_PATH_TIMING_S);
            options.mount_min_m = options.mount_min_m.max(ESTIMATED_MOUNT_MIN_M);
        }
        options
    }
}

/// The sonar and the encoders judged again, and their effects chosen again, along `along`: the
/// path estimated under the named lidar effects. Estimated under the nominal lidar, the path
/// took up part of a lidar effect (a warm-up's early ranges are a position error), which the
/// sonar and the encoders would otherwise carry as effects of their own. Returns the named
/// effects and the nominal evidence along the new path (`candidates` and `data` follow it).
fn rejudge_along(
    along: &Context<'_>,
    aligned: &Aligned,
    named: Vec<CandidateFit>,
    candidates: &mut Vec<CandidateFit>,
    data: &mut [SensorData],
    options: &Options,
) -> Result<(Vec<CandidateFit>, Nominal), MismatchError> {
    for d in data.iter_mut() {
        let again = match d.sensor {
            Sensor::Sonar => residuals::sonar(along)?,
            Sensor::Odometer => residuals::odometer(along)?,
            Sensor::Lidar | Sensor::Drive => continue,
        };
        if let Some(mut again) = again {
            again.clusters = Some(residuals::shared_error_clusters(along.trajectory, &again.t));
            *d = again;
        }
    }
    let others: Vec<SensorData> = data
        .iter()
        .filter(|d| d.sensor != Sensor::Lidar)
        .cloned()
        .collect();
    let named = if others.is_empty() {
        named
    } else {
        let again = select::select(along, &others, options);
        replace_effects(named, candidates, again, |s| s != Sensor::Lidar)
    };
    Ok((named, nominal_evidence(along, aligned, data, options)))
}

/// [`rejudge_along`] `along` a new path when there is one (`nominal` then follows it), the
/// named effects as they are otherwise.
fn rejudged_along(
    along: Option<&Context<'_>>,
    aligned: &Aligned,
    named: Vec<CandidateFit>,
    candidates: &mut Vec<CandidateFit>,
    data: &mut [SensorData],
    nominal: &mut Nominal,
    options: &Options,
) -> Result<Vec<CandidateFit>, MismatchError> {
    let Some(along) = along else {
        return Ok(named);
    };
    let (named, again) = rejudge_along(along, aligned, named, candidates, data, options)?;
    *nominal = again;
    Ok(named)
}

/// A note for an encoder delay or wheel slip that gained its place on held-out data but whose
/// lead is within the scatter of the encoders' own stamps ([`Options::encoder_timing_s`]), so
/// was not named: the log cannot tell it.
fn lead_within_the_stamps(candidates: &[CandidateFit], options: &Options) -> Option<String> {
    let within = candidates.iter().find(|c| {
        stamps::is_encoder_lead(c.effect)
            && !c.rmse_over.of_path_motion()
            && c.heldout_gain > options.min_gain
            && c.params.first().is_some_and(|lead| {
                lead.abs() <= options.encoder_timing_s && lead.abs() > options.path_timing_s
            })
    })?;
    Some(format!(
        "the encoders' stamps scatter by ±{:.0} ms about their neighbours' at speed: an encoder          delay or a wheel slip whose lead is within that is not identifiable from this log, so          {} (fitted at {:.0} ms) is not named",
        options.encoder_timing_s * 1000.0,
        within.effect.label(),
        within.params[0] * 1000.0
    ))
}

/// The drive judged again, and its effects chosen again, along a path that follows the
/// encoders at their corrected times when an odometer latency is named: encoders stamped late
/// make the path that follows them lag the commands, which the drive would take for a motor
/// lag. Returns the named effects (`candidates` and `data` follow).
fn drive_after_odometer_latency(
    ctx: &Context<'_>,
    aligned: &Aligned,
    named: Vec<CandidateFit>,
    candidates: &mut Vec<CandidateFit>,
    data: &mut [SensorData],
    options: &Options,
) -> Result<Vec<CandidateFit>, MismatchError> {
    let latency = Effect::SensorLatency(Sensor::Odometer);
    let Some(delay_s) = named
        .iter()
        .find(|c| c.effect == latency)
        .map(|c| c.params[0])
    else {
        return Ok(named);
    };
    let mut recording = ctx.recording.clone();
    if let Some(odometry) = recording.odometry.as_mut() {
        for o in odometry.iter_mut() {
            o.t_s -= delay_s;
        }
        odometry.retain(|o| o.t_s >= 0.0);
    }
    let Some(encoders) = align::along_encoders(ctx.physics, &recording, aligned)? else {
        return Ok(named);
    };
    let Some(drive) = drive_along(&along(ctx, &encoders))? else {
        return Ok(named);
    };
    let Some(at) = data.iter().position(|d| d.sensor == Sensor::Drive) else {
        return Ok(named);
    };
    data[at] = drive;
    let wheels: Vec<SensorData> = data
        .iter()
        .filter(|d| matches!(d.sensor, Sensor::Odometer | Sensor::Drive))
        .cloned()
        .collect();
    let again = select::select(ctx, &wheels, options);
    Ok(replace_effects(named, candidates, again, |s| {
        matches!(s, Sensor::Odometer | Sensor::Drive)
    }))
}

/// `named` and `candidates` with the effects of the sensors `chosen_again` replaced by those of
/// `again` (a selection over those sensors' data judged again), strongest first.
fn replace_effects(
    named: Vec<CandidateFit>,
    candidates: &mut Vec<CandidateFit>,
    again: Selection,
    chosen_again: impl Fn(Sensor) -> bool,
) -> Vec<CandidateFit> {
    let by_gain = |a: &CandidateFit, b: &CandidateFit| b.heldout_gain.total_cmp(&a.heldout_gain);
    let mut named: Vec<CandidateFit> = named
        .into_iter()
        .filter(|c| !chosen_again(c.effect.sensor()))
        .collect();
    named.extend(again.named);
    named.sort_by(by_gain);
    candidates.retain(|c| !chosen_again(c.effect.sensor()));
    candidates.extend(again.candidates);
    candidates.sort_by(by_gain);
    named
}

/// The context of a diagnosis along `aligned`'s trajectory.
fn context<'a>(
    physics: &'a dyn Physics,
    recording: &'a Recording,
    estimates: &'a Estimates,
    aligned: &'a Aligned,
    options: &Options,
) -> Context<'a> {
    Context {
        physics,
        trajectory: &aligned.trajectory,
        recording,
        estimates,
        end_s: aligned.end_s,
        position_sd_m: aligned.position_sd_m,
        yaw_sd_rad: aligned.yaw_sd_rad,
        estimated: aligned.alignment == Alignment::Estimated,
        placed_through: None,
        floors: options.floors,
    }
}

/// `ctx` along another estimate of the same run's trajectory, `path`.
fn along<'a>(ctx: &Context<'a>, path: &'a Aligned) -> Context<'a> {
    Context {
        trajectory: &path.trajectory,
        position_sd_m: path.position_sd_m,
        yaw_sd_rad: path.yaw_sd_rad,
        ..*ctx
    }
}

/// The drive's residual data along `ctx`'s (estimated) trajectory, with the groups of windows
/// that share its errors; `None` with too few windows to test.
fn drive_along(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let Some(mut drive) = residuals::drive(ctx)?.filter(|d| d.len() >= MIN_READINGS) else {
        return Ok(None);
    };
    drive.clusters = Some(residuals::shared_error_clusters(ctx.trajectory, &drive.t));
    Ok(Some(drive))
}

/// `aligned` (an estimate that follows the commands between the lidar's corrections)
/// estimated again with the commands replayed under the drive's own effects (motor lag) when
/// the drive, judged along the encoders (`along`), names one: the robot lagged its commands
/// and a path that follows them did not, so every sensor judged along it would carry the lag
/// (the encoders as a wrong wheel radius).
fn replayed_under_drive(
    physics: &dyn Physics,
    recording: &Recording,
    estimates: &Estimates,
    aligned: Aligned,
    along: Option<&Aligned>,
    options: &Options,
) -> Result<Aligned, MismatchError> {
    let Some(along) = along else {
        return Ok(aligned);
    };
    let ctx = context(physics, recording, estimates, along, options);
    let Some(drive) = drive_along(&ctx)? else {
        return Ok(aligned);
    };
    let own: Vec<CandidateFit> = select::select(&ctx, &[drive], options)
        .named
        .into_iter()
        .filter(|c| c.effect.sensor() == Sensor::Drive)
        .collect();
    if own.is_empty() {
        return Ok(aligned);
    }
    align::realign(
        physics,
        recording,
        estimates,
        &aligned,
        &hypothesis_of(&own),
    )
}

/// Readings a sensor needs to be tested.
const MIN_READINGS: usize = 60;

/// What `sensor`'s readings are judged against, aligned by `aligned`.
fn reference_of(sensor: Sensor, aligned: &Aligned) -> &'static str {
    match (aligned.reckoned, sensor) {
        (None, Sensor::Drive) => "commands against truth.csv",
        (None, _) => "truth.csv",
        (Some(_), Sensor::Drive) => match aligned.drive_reckoned {
            Some(DeadReckoning::DeclaredPath) => {
                "commands against the lidar-estimated path (the scenario's path between scans)"
            }
            _ => "commands against the lidar-estimated path (encoders between scans)",
        },
        (Some(r), _) => r.describe(),
    }
}

/// The sensors' residual data with enough readings to test (a note for each with too few, or
/// with no reference independent of it). `drive_ctx`: against an estimate, the context whose
/// trajectory follows the encoders.
fn gather(
    ctx: &Context<'_>,
    drive_ctx: Option<&Context<'_>>,
    aligned: &Aligned,
    notes: &mut Vec<String>,
) -> Result<Vec<SensorData>, MismatchError> {
    let mut data: Vec<SensorData> = Vec::new();
    let has_odometry = ctx
        .recording
        .odometry
        .as_ref()
        .is_some_and(|o| !o.is_empty())
        && ctx.physics.declared().odometer;
    // The encoders judged against a path that follows them would be judged against themselves.
    let odometer = if aligned
        .reckoned
        .is_some_and(DeadReckoning::follows_the_encoders)
    {
        if has_odometry {
            notes.push(
                "the odometer is not diagnosed: without truth.csv or commands, the only path \
                 to judge it against is the one estimated from the encoders themselves"
                    .into(),
            );
        }
        None
    } else {
        residuals::odometer(ctx)?
    };
    let drive = match (ctx.estimated, drive_ctx) {
        (false, _) => residuals::drive(ctx)?,
        (true, Some(along)) => residuals::drive(along)?,
        (true, None) => {
            if !ctx.recording.commands.is_empty() {
                notes.push(
                    "the drive is not diagnosed: without truth.csv or encoders, the only path \
                     to judge the commands against is estimated from the commands themselves"
                        .into(),
                );
            }
            None
        }
    };
    for d in [
        residuals::lidar(ctx)?,
        residuals::sonar(ctx)?,
        odometer,
        drive,
    ]
    .into_iter()
    .flatten()
    {
        if d.len() >= MIN_READINGS {
            let mut d = d;
            if ctx.estimated {
                let along = match (d.sensor, drive_ctx) {
                    (Sensor::Drive, Some(along)) => along.trajectory,
                    _ => ctx.trajectory,
                };
                d.clusters = Some(residuals::shared_error_clusters(along, &d.t));
            }
            data.push(d);
        } else {
            // Never left out quietly: a sensor whose readings all fell out says so.
            notes.push(format!(
                "only {} {} readings could be compared: too few to test",
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
    // The drive alone is the commands against the trajectory: with no sensor in common the
    // recording says nothing about the sensors, so "agrees within its noise" would be false.
    if data.iter().all(|d| d.sensor == Sensor::Drive) {
        return Err(MismatchError::Refused(
            "no sensor in common with the scenario (lidar, sonar or odometer with enough \
             readings): only the drive could be compared"
                .into(),
        ));
    }
    Ok(data)
}

/// The residuals under the nominal model, and where they stop being noise.
fn nominal_evidence(
    ctx: &Context<'_>,
    aligned: &Aligned,
    data: &[SensorData],
    options: &Options,
) -> Nominal {
    let names = |id: u32| ctx.physics.object_name(id);
    let nominal = Hypothesis::nominal();
    let mut evidence = Vec::new();
    let mut sensors = Vec::new();
    let mut misaligned = None;
    for d in data {
        let all = d.rows(None);
        let f = residuals::fits(d, &all, &ctx.predict(d, &nominal, &all));
        let ev = locate::locate(d, &all, &f, &names, !ctx.estimated);
        let held: Vec<bool> = all.iter().map(|&i| d.heldout[i]).collect();
        let (r, floor, _) = residuals::rmse(&f, |k| held[k] && !f[k].outlier);
        let wild = f.iter().filter(|x| x.outlier).count() as f64 / f.len() as f64;
        if wild > options.misaligned_share && misaligned.is_none() {
            misaligned = Some(misaligned_evidence(d.sensor, wild));
        }
        sensors.push(SensorSummary {
            sensor: d.sensor,
            readings: d.len(),
            heldout_rmse_m: r,
            noise_floor_m: floor,
            strongest: ev.iter().map(|e| e.score).fold(f64::NEG_INFINITY, f64::max),
            reference: reference_of(d.sensor, aligned),
        });
        evidence.extend(ev);
    }
    let threshold = locate::threshold(options.alpha, evidence.len());
    evidence.sort_by(|a, b| b.score.total_cmp(&a.score));
    Nominal {
        sensors,
        evidence,
        misaligned,
        threshold,
    }
}

/// The evidence that `sensor`'s readings do not align: a share `wild` of them are outliers.
fn misaligned_evidence(sensor: Sensor, wild: f64) -> Evidence {
    Evidence {
        sensor,
        test: TestKind::Spread,
        covariate: None,
        score: f64::INFINITY,
        place: format!("all {sensor} readings"),
        detail: format!(
            "{:.0} % of the {} readings are nowhere near the simulation's (outliers to \
             it): the recording does not align with the scenario",
            100.0 * wild,
            sensor
        ),
        range: None,
        size_m: f64::NAN,
        median_m: f64::NAN,
        noise_m: f64::NAN,
        world_m: 0.0,
        beyond_world_m: f64::NAN,
    }
}

/// The next parameter to estimate the trajectory under, from the rounds so far (the parameter
/// each was estimated under, and the refit against that estimate): the root of the refit's
/// change `h(s) = refit(s) − s` by the secant through the last two rounds — by regula falsi
/// within the last pair that brackets it, once one does. Plain iteration `s ← refit(s)`
/// converges only as fast as the scan matching gives the effect back (for motion skew, a fifth
/// to a third of the remaining gap a round); `None` (iterate) until two rounds differ.
fn fixed_point_step(rounds: &[(f64, f64)]) -> Option<f64> {
    let h = |(s, refit): (f64, f64)| (s, refit - s);
    let (b, hb) = h(*rounds.last()?);
    // The latest earlier round on the other side of the root, else the one before the last.
    let (a, ha) = rounds[..rounds.len() - 1]
        .iter()
        .rev()
        .map(|r| h(*r))
        .find(|(_, ha)| ha.signum() != hb.signum())
        .or_else(|| rounds.len().checked_sub(2).map(|i| h(rounds[i])))?;
    let slope = (hb - ha) / (b - a);
    if !slope.is_finite() || slope == 0.0 {
        return None;
    }
    let next = b - hb / slope;
    // Without a bracket, a secant through a flattening h overshoots: at most three times the
    // last round's own step beyond it.
    let bracketed = ha.signum() != hb.signum();
    Some(if bracketed {
        next
    } else {
        next.clamp(b - 3.0 * hb.abs(), b + 3.0 * hb.abs())
    })
}

/// Against a path estimated from the lidar, a lidar mount offset goes into the path: scan
/// matching places the lidar, and the robot is inferred from it through the declared mount, so
/// the lidar fits and the error shows in the sensors that look from the robot (the sonar's
/// origin and axis; the encoders, as the inferred robot point swings about the real one while
/// the robot turns). The mount is fitted there: each hypothesis's robot path is the estimate
/// put through the hypothesised mount (`Trajectory::under_mount`), and the sonar's and the
/// encoders' training log-likelihood along it is maximised. It is named when it gains on their
/// held-out readings more than the effects named in them gain together (it explains what they
/// were named for), it earns its place in the sensor it gains most in, and it moves the robot
/// by at least [`Options::mount_min_m`]; a run that does not turn enough
/// ([`crate::Entry::seen_through_path`]) is not tried. Returns it (scored
/// there) with the path estimated again under it and the named lidar effects; the caller
/// judges the sonar and the encoders again along that path.
///
/// A lidar delay (`sensor_latency` of the lidar) goes into the path the same way: the matching
/// puts each pose at the scan's late stamp, so the lidar fits and the sonar and the encoders,
/// judged along a path that runs late, show the delay (the encoders as a lead proportional to
/// the wheel speed, a slip's signature; the sonar as a range error proportional to the speed).
/// It is fitted and named through them by the same rule (`effect`), the path then put back by
/// the delay.
fn through_path(
    effect: Effect,
    ctx: &Context<'_>,
    aligned: &Aligned,
    named: &[CandidateFit],
    candidates: &mut [CandidateFit],
    data: &[SensorData],
    options: &Options,
) -> Result<Option<(CandidateFit, Aligned)>, MismatchError> {
    let Some(declared) = ctx.physics.declared().lidar.map(|l| l.mount) else {
        return Ok(None);
    };
    let seen_through_path = effect
        .entry()
        .seen_through_path(ctx.trajectory.heading_span_rad());
    let looking_from_robot = |s: Sensor| matches!(s, Sensor::Sonar | Sensor::Odometer);
    let others: Vec<&SensorData> = data
        .iter()
        .filter(|d| looking_from_robot(d.sensor))
        .collect();
    // Against the scans' own path the lidar's delay is read from its turns (`from_turns`) and
    // its mount's yaw from the path's sideways motion (`crab_mount`); the encoders' travel
    // along a path that skids in its turns does not tell a mount's position.
    if !ctx.estimated
        || aligned.reckoned == Some(DeadReckoning::Scans)
        || !seen_through_path
        || !options.effects.contains(&effect)
        || others.is_empty()
        || named.iter().any(|c| c.effect == effect)
    {
        return Ok(None);
    }
    let through = Context {
        placed_through: Some(declared),
        ..*ctx
    };
    // Fitted on top of `base` to the sonar and the encoders at once: its gain on their held-out
    // readings and its fit in the sensor it gains most in.
    let fitted_on = |base: &Hypothesis| -> Option<(f64, CandidateFit)> {
        let (params, param_sd) =
            explain::fit_across(&through, &others, base, effect, FitRows::of(options));
        let fits: Vec<CandidateFit> = others
            .iter()
            .map(|d| {
                let train = explain::fit_rows(d, options.max_fit_rows);
                explain::score(&through, d, base, effect, params.clone(), &train)
            })
            .collect();
        let gain: f64 = fits.iter().map(|f| f.heldout_gain).sum();
        let mut best = fits
            .into_iter()
            .max_by(|a, b| a.heldout_gain.total_cmp(&b.heldout_gain))?;
        // Estimated from every sensor that sees it (the encoders see a mount's position as the
        // robot turns, the sonar its yaw too).
        best.param_sd = param_sd;
        Some((gain, best))
    };
    // The sonar's and the encoders' own effects (a lidar mount read from the path's sideways
    // motion was scored there, but is the lidar's).
    let beside: Vec<CandidateFit> = named
        .iter()
        .filter(|c| looking_from_robot(c.sensor) && looking_from_robot(c.effect.sensor()))
        .cloned()
        .collect();
    let explained: f64 = beside.iter().map(|c| c.heldout_gain).sum();
    // Its place earned includes the mount's least offset against an estimated path.
    let earns = |best: &CandidateFit| select::earns_place(best, declared_cone(ctx), options);
    // Alone, it must explain what the sonar's and the encoders' effects were named for (they
    // are judged again along the path it puts back, and dropped if it took their place) …
    let alone = fitted_on(&Hypothesis::nominal())
        .filter(|(gain, best)| *gain > explained + options.min_gain && earns(best));
    // … or, beside them, gain on top of what they explain: a mount of a few degrees beside
    // wheels' radii a few percent off gains less alone than the radii do, and would be lost.
    let found = match alone {
        Some(found) => Some(found),
        None if !beside.is_empty() => fitted_on(&hypothesis_of(&beside))
            .filter(|(gain, best)| *gain > options.min_gain && earns(best)),
        None => None,
    };
    let Some((_, best)) = found else {
        return Ok(None);
    };
    // A fit stopped at its search's edge is not this effect's size (it is not named).
    if effect
        .params()
        .iter()
        .zip(&best.params)
        .any(|(spec, &value)| SearchLimits::at_limit(spec, value))
    {
        return Ok(None);
    }
    let again = match (effect, best.params.as_slice()) {
        // The path the delay was fitted along: the estimate put back by it.
        (Effect::SensorLatency(Sensor::Lidar), &[delay_s]) => Aligned {
            trajectory: aligned.trajectory.delayed(delay_s),
            ..aligned.clone()
        },
        _ => estimated_under(ctx, aligned, named, effect, &best.params)?,
    };
    if let Some(c) = candidates.iter_mut().find(|c| c.effect == effect) {
        *c = best.clone();
    }
    Ok(Some((best, again)))
}

/// The range a mount's yaw is sized at, metres: the catalogue's reference range for the
/// lidar's errors (a range bias's `at_2m_m`).
const CRAB_SIZE_RANGE_M: f64 = 2.0;
/// How many standard errors from the declared mount a yaw read from the path's sideways motion
/// must lie: 3, as the halves of a log are compared.
const CRAB_MIN_SD: f64 = 3.0;

/// An effect read from the path's own motion (its steps or its spans against the encoders),
/// not from a sensor's readings, and what it explains there.
struct PathRead {
    effect: Effect,
    params: Vec<f64>,
    param_sd: Vec<f64>,
    train_gain: f64,
    heldout_gain: f64,
    /// Its free parameters, for the BIC.
    free: usize,
    train_n: usize,
    heldout_n: usize,
    rmse_before_m: f64,
    rmse_after_m: f64,
    noise_m: f64,
    rmse_over: RmseOver,
    size_m: f64,
    /// The floor its size is measured against, metres.
    floor_m: f64,
}

impl PathRead {
    /// Its fit, scored in the encoders (the path they are judged against is what it was read
    /// from), put in `candidates` in place of any other fit of its effect.
    fn candidate(self, seen_until_s: f64, candidates: &mut Vec<CandidateFit>) -> CandidateFit {
        let per_noise = |v: f64| v / self.noise_m.max(f64::MIN_POSITIVE);
        let fit = CandidateFit {
            effect: self.effect,
            sensor: Sensor::Odometer,
            train_gain: self.train_gain,
            heldout_gain: self.heldout_gain,
            bic_gain: 2.0 * self.train_gain - self.free as f64 * (self.train_n as f64).ln(),
            rmse_before: self.rmse_before_m,
            rmse_after: self.rmse_after_m,
            noise_floor: self.noise_m,
            heldout_n: self.heldout_n,
            rmse_over: self.rmse_over,
            heldout_ll_per_reading: self.heldout_gain / self.heldout_n.max(1) as f64,
            size_m: self.size_m,
            size_noise_m: self.floor_m,
            floor_multiple: self.size_m / self.floor_m.max(f64::MIN_POSITIVE),
            scaled_rmse: (per_noise(self.rmse_before_m), per_noise(self.rmse_after_m)),
            seen_until_s,
            params: self.params,
            param_sd: self.param_sd,
        };
        match candidates.iter_mut().find(|x| x.effect == fit.effect) {
            Some(x) => *x = fit.clone(),
            None => candidates.push(fit.clone()),
        }
        fit
    }
}

/// What the spans of the scans' own path name: the lidar's delay against the encoders, with
/// the path put back by it, and the wheels' base and sizes (each fit, and whether it is named).
struct FromSpans {
    delay: Option<(CandidateFit, Aligned)>,
    wheels: Vec<(CandidateFit, bool)>,
}

/// The lidar's delay against the encoders, the wheels' effective base and their sizes, against
/// a path that is the lidar's own matches ([`DeadReckoning::Scans`]: a log with encoders and no
/// commands), read from its spans ([`wheel_spans`]). Each is a candidate, and named
/// when it gains on the held-out spans by [`Options::min_gain`], lies three standard errors
/// from its absence (`Reading::departs`) and beyond its entry's least departure, and stops
/// inside its search. The delay comes with the path put back by it (the matched pose at stamp t is the
/// robot's at t − delay).
fn from_spans(
    ctx: &Context<'_>,
    aligned: &Aligned,
    candidates: &mut Vec<CandidateFit>,
    options: &Options,
) -> FromSpans {
    let none = FromSpans {
        delay: None,
        wheels: Vec::new(),
    };
    let delay = Effect::SensorLatency(Sensor::Lidar);
    let (Some(odometry), Some(&delays)) =
        (ctx.recording.odometry.as_deref(), delay.params().first())
    else {
        return none;
    };
    if aligned.reckoned != Some(DeadReckoning::Scans) {
        return none;
    }
    let Some(spans) = wheel_spans::fit(
        &aligned.trajectory,
        ctx.physics.declared().wheel_base_m,
        odometry,
        (delays.lo, delays.hi),
        SpanLimits::SCANS,
    ) else {
        return none;
    };
    let mut judged = |effect: Effect, reading: &wheel_spans::Reading| {
        judged_on_spans(
            effect,
            reading,
            &spans,
            RmseOver::PathSpans,
            aligned.end_s,
            candidates,
            options,
        )
    };
    let (delay_fit, late) = judged(delay, &spans.delay_s);
    let delay = late.then(|| {
        let again = Aligned {
            trajectory: aligned.trajectory.delayed(delay_fit.params[0]),
            ..aligned.clone()
        };
        (delay_fit, again)
    });
    let wheels = vec![
        judged(Effect::DriveWheelBase, &spans.base_scale),
        judged(Effect::OdometerWheelRadius, &spans.radius_scales),
    ];
    candidates.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
    FromSpans { delay, wheels }
}

/// `reading` of `spans` as `effect`'s candidate (put in `candidates`), and whether it is named:
/// it gains on the held-out spans by [`Options::min_gain`] and by the BIC, lies three standard
/// errors from its absence (`Reading::departs`) and beyond its entry's least departure, and
/// stops inside its search.
fn judged_on_spans(
    effect: Effect,
    reading: &wheel_spans::Reading,
    spans: &wheel_spans::Spans,
    rmse_over: RmseOver,
    seen_until_s: f64,
    candidates: &mut Vec<CandidateFit>,
    options: &Options,
) -> (CandidateFit, bool) {
    // Sized as how much it changes the held-out spans' residual (their turn as travel apart,
    // or their travel).
    let size_m = reading.change_m;
    let fit = PathRead {
        effect,
        params: reading.value.clone(),
        param_sd: reading.sd.clone(),
        train_gain: reading.train_gain,
        heldout_gain: reading.heldout_gain,
        free: reading.value.len(),
        train_n: spans.train_n,
        heldout_n: spans.heldout_n,
        rmse_before_m: reading.rmse_before_m,
        rmse_after_m: reading.rmse_after_m,
        noise_m: reading.noise_m,
        rmse_over,
        size_m,
        floor_m: options.floors.odometer_m,
    }
    .candidate(seen_until_s, candidates);
    let absent = effect.absent(0.0);
    let inside = effect
        .params()
        .iter()
        .zip(&reading.value)
        .all(|(spec, &v)| !SearchLimits::at_limit(spec, v));
    let beyond_least = effect
        .entry()
        .least_departures()
        .iter()
        .any(|&(i, least)| (reading.value[i] - absent[i]).abs() > least);
    let earns = reading.heldout_gain > options.min_gain
        && fit.bic_gain > 0.0
        && inside
        && beyond_least
        && reading.departs;
    (fit, earns)
}

/// How the encoders' lead on a sparse truth is named ([`split_lead`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum LeadSplit {
    /// Encoders stamped late by this many seconds.
    Late(f64),
    /// A slip of this gain and braking share (1: braking gives back all it led).
    Slip { gain_s: f64, share: f64 },
    /// Encoders late by `late_s` beside a slip of gain `gain_s` that braking gives none of back.
    LateBesideSlip { late_s: f64, gain_s: f64 },
}

/// The encoders' lead `L v + h F` on a sparse truth (`lead_s` = `L`; `F` the speed's falls
/// summed, `h` ≤ 0 when read) as the catalogue names it. It is a gain `L` on every rise of the
/// speed and `L + h` on every fall: a slip of gain `L` and braking share `1 + h / L` when `L` is
/// a lead and the share is at least `least_share` (the slip entry's family); otherwise,
/// with `h`, encoders late by `−(L + h)` beside a slip of gain `−h` that braking gives none of
/// back, which is the same lead; without `h`, a delay or an even slip by the sign of `L`.
fn split_lead(lead_s: f64, h_s: Option<f64>, least_share: f64) -> LeadSplit {
    match h_s {
        Some(h) if lead_s > 0.0 && 1.0 + h / lead_s >= least_share => LeadSplit::Slip {
            gain_s: lead_s,
            share: (1.0 + h / lead_s).min(1.0),
        },
        Some(h) => LeadSplit::LateBesideSlip {
            late_s: -(lead_s + h),
            gain_s: -h,
        },
        None if lead_s < 0.0 => LeadSplit::Late(-lead_s),
        None => LeadSplit::Slip {
            gain_s: lead_s,
            share: 1.0,
        },
    }
}

/// The encoders against a truth sparser than they are (a logger's scan-matched pose every few
/// seconds), read span by span between its poses ([`wheel_spans`]): their timing, the wheels'
/// effective base and their sizes, each a candidate and whether it is named
/// ([`judged_on_spans`]). Encoders stamped late against the truth are the odometer's
/// `sensor_latency`, encoders that lead it on the speed's changes a wheel slip (its mirror,
/// [`crate::Entry::sized_as_a_delay`], read as an even slip: the spans tell a lead, not when
/// it was gained). Judged reading by reading, a lead is told by the speed at each reading,
/// measured through the same stamps, so a logger's scatter of its stamps hides it
/// (`stamps.rs`); over the spans only the travel at the truth's stamps counts, and the scatter
/// averages out. The turn that follows the travel is the wheels' sizes apart, not their base
/// (a robot that drives its loops one way turns with the distance driven). Empty when the
/// truth is not sparse, or the spans are too few.
fn encoders_over_truth(
    ctx: &Context<'_>,
    candidates: &mut Vec<CandidateFit>,
    options: &Options,
) -> Vec<(CandidateFit, bool)> {
    let (Some(truth), Some(odometry)) = (
        ctx.recording.truth.as_deref(),
        ctx.recording.odometry.as_deref(),
    ) else {
        return Vec::new();
    };
    if ctx.estimated || !sparse_truth::reads_encoder_leads(ctx.recording) {
        return Vec::new();
    }
    let latency = Effect::SensorLatency(Sensor::Odometer);
    // Encoders late by up to the latency's bound, or leading by up to a slip gain's.
    let (Some(late), Some(lead), Ok(path)) = (
        latency.params().first().map(|p| p.hi),
        Effect::OdometerWheelSlip.params().first().map(|p| p.hi),
        Trajectory::new(truth),
    ) else {
        return Vec::new();
    };
    let Some(spans) = wheel_spans::fit(
        &path,
        ctx.physics.declared().wheel_base_m,
        odometry,
        (-late, lead),
        SpanLimits::SPARSE_TRUTH,
    ) else {
        return Vec::new();
    };
    let slip = Effect::OdometerWheelSlip;
    // A slip that braking gives back less of than it gained (`h` < 0), when it earns its place
    // on the held-out spans: the lead and the wheels are then read under it.
    let braking = spans.braking.as_ref().filter(|b| {
        let h = &b.lead_per_fall_s;
        h.value[0] < 0.0 && h.departs && h.heldout_gain > options.min_gain
    });
    let lead = braking.map_or(&spans.delay_s, |b| &b.delay_s);
    let h = braking.map(|b| &b.lead_per_fall_s);
    let least_share = slip.params().get(1).map_or(-1.0, |spec| spec.lo);
    let split = split_lead(lead.value[0], h.map(|h| h.value[0]), least_share);
    let h_sd = h.map_or(0.0, |h| h.sd[0]);
    let (effect, value, sd) = match split {
        LeadSplit::Late(late_s) => (latency, vec![late_s], vec![lead.sd[0]]),
        LeadSplit::LateBesideSlip { late_s, .. } => {
            (latency, vec![late_s], vec![lead.sd[0].hypot(h_sd)])
        }
        LeadSplit::Slip { gain_s, share } => {
            let mut value = slip.absent(0.0);
            let mut sd = vec![0.0; value.len()];
            value[0] = gain_s;
            sd[0] = lead.sd[0];
            // The braking share; held at its absence without one.
            if let (Some(read), Some(_)) = (value.get_mut(1), h) {
                *read = share;
                sd[1] = h_sd / gain_s;
            }
            (slip, value, sd)
        }
    };
    // Late by more than its error, when read beside a slip braking gives none of back.
    let departs = match split {
        LeadSplit::LateBesideSlip { .. } => value[0].abs() > wheel_spans::MIN_SD * sd[0],
        _ => lead.departs,
    };
    // Scored on the turn (the lead) and, with a braking share, the travel too.
    let timing = match braking {
        Some(b) if effect == slip => {
            let h = &b.lead_per_fall_s;
            wheel_spans::Reading {
                value,
                sd,
                train_gain: spans.delay_s.train_gain + h.train_gain,
                heldout_gain: spans.delay_s.heldout_gain + h.heldout_gain,
                departs: lead.departs || h.departs,
                ..spans.delay_s.clone()
            }
        }
        _ => wheel_spans::Reading {
            value,
            sd,
            departs,
            ..spans.delay_s.clone()
        },
    };
    let mut judged = |effect: Effect, reading: &wheel_spans::Reading| {
        judged_on_spans(
            effect,
            reading,
            &spans,
            RmseOver::TruthSpans,
            ctx.end_s,
            candidates,
            options,
        )
    };
    let (base, radii) = braking.map_or((&spans.base_scale, &spans.radius_scales), |b| {
        (&b.base_scale, &b.radius_scales)
    });
    let mut read = vec![
        judged(effect, &timing),
        judged(Effect::DriveWheelBase, base),
        judged(Effect::OdometerWheelRadius, radii),
    ];
    // Encoders late on the truth that also gain on every start and give less back on every
    // stop: the slip apart, as one that braking gives none of back (`g = −h`).
    if let (Some(h), LeadSplit::LateBesideSlip { gain_s, .. }) = (h, split) {
        let mut value = slip.absent(0.0);
        let mut sd = vec![0.0; value.len()];
        value[0] = gain_s;
        sd[0] = h.sd[0];
        if let Some(share) = value.get_mut(1) {
            *share = 0.0;
        }
        read.push(judged(
            slip,
            &wheel_spans::Reading {
                value,
                sd,
                ..h.clone()
            },
        ));
    }
    read
}

/// The yaw of a lidar turned on its mount, against a path that is the lidar's own matches
/// ([`DeadReckoning::Scans`]: a log with encoders and no commands), read from the path moving
/// sideways ([`crab`]). It is named when it gains on the held-out steps by
/// [`Options::min_gain`], lies [`CRAB_MIN_SD`] standard errors from the declared mount, and
/// turns a reading at [`CRAB_SIZE_RANGE_M`] by more than the lidar's practical floor. Returns
/// it with the path estimated again under it and the named lidar effects.
fn crab_mount(
    ctx: &Context<'_>,
    aligned: &Aligned,
    named: &[CandidateFit],
    candidates: &mut Vec<CandidateFit>,
    options: &Options,
) -> Result<Option<(CandidateFit, Aligned)>, MismatchError> {
    let effect = Effect::LidarMountOffset;
    if aligned.reckoned != Some(DeadReckoning::Scans)
        || !options.effects.contains(&effect)
        || named.iter().any(|c| c.effect == effect)
    {
        return Ok(None);
    }
    let Some(c) = crab::fit(aligned.smoothed.as_ref().unwrap_or(&aligned.trajectory)) else {
        return Ok(None);
    };
    let size_m = CRAB_SIZE_RANGE_M * c.yaw_rad.tan().abs();
    let floor_m = options.floors.lidar_m;
    let fit = PathRead {
        effect,
        params: vec![c.yaw_rad.to_degrees(), 0.0, 0.0],
        param_sd: vec![c.yaw_sd_rad.to_degrees(), f64::NAN, f64::NAN],
        train_gain: c.train_gain,
        heldout_gain: c.heldout_gain,
        free: 1,
        train_n: c.train_n,
        heldout_n: c.heldout_n,
        rmse_before_m: c.rmse_before_m,
        rmse_after_m: c.rmse_after_m,
        noise_m: c.noise_m,
        rmse_over: RmseOver::PathSteps,
        size_m,
        floor_m,
    }
    .candidate(aligned.end_s, candidates);
    candidates.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
    let earns = fit.heldout_gain > options.min_gain
        && fit.bic_gain > 0.0
        && c.yaw_rad.abs() > CRAB_MIN_SD * c.yaw_sd_rad
        && size_m > floor_m;
    if !earns {
        return Ok(None);
    }
    let again = estimated_under(ctx, aligned, named, effect, &fit.params)?;
    Ok(Some((fit, again)))
}

/// `aligned` (an estimate) estimated again under the named lidar effects and `effect` at
/// `params`.
fn estimated_under(
    ctx: &Context<'_>,
    aligned: &Aligned,
    named: &[CandidateFit],
    effect: Effect,
    params: &[f64],
) -> Result<Aligned, MismatchError> {
    let lidar_named: Vec<CandidateFit> = named
        .iter()
        .filter(|c| c.effect.sensor() == Sensor::Lidar)
        .cloned()
        .collect();
    let hypothesis = hypothesis_of(&lidar_named).and(effect, params.to_vec());
    align::realign(
        ctx.physics,
        ctx.recording,
        ctx.estimates,
        aligned,
        &hypothesis,
    )
}

/// Against an estimated trajectory a lidar effect was partly absorbed into the scan matching
/// (fitted with the nominal model): the trajectory is estimated again under the named lidar
/// effects' fitted model and each is refitted against it in turn, strongest first, the others
/// held at their fits (a second effect's part stays in the path otherwise: a warm-up beside a
/// motion skew leaves its settling in the path, which the encoders show as a wheel radius and a
/// delay). Returns the named effects and, when one was refitted, the
/// trajectory the last rests on (`candidates` and the lidar's `data` then follow it).
fn realign_lidar(
    ctx: &Context<'_>,
    aligned: &Aligned,
    mut named: Vec<CandidateFit>,
    candidates: &mut [CandidateFit],
    data: &mut [SensorData],
    options: &Options,
) -> Result<(Vec<CandidateFit>, Option<Aligned>), MismatchError> {
    if !ctx.estimated {
        return Ok((named, None));
    }
    let lidar_effects: Vec<usize> = (0..named.len())
        .filter(|&i| named[i].effect.sensor() == Sensor::Lidar)
        .collect();
    let mut realigned = None;
    for (nth, at) in lidar_effects.into_iter().enumerate() {
        let first = named[at].clone();
        let others: Vec<CandidateFit> = named
            .iter()
            .filter(|c| c.effect.sensor() == Sensor::Lidar && c.effect != first.effect)
            .cloned()
            .collect();
        let base = hypothesis_of(&others);
        // The strongest effect's rivals are settled too: the first path took up part of each
        // lidar effect, and not the same part (a warm-up's early shift goes into the path, a
        // constant bias mostly stays in the ranges), so the ranking before realigning is not
        // the ranking along each one's own path.
        let rivals: Vec<CandidateFit> = if nth == 0 {
            lidar_rivals(&first, &named, candidates)
        } else {
            Vec::new()
        };
        let contenders: Vec<&CandidateFit> = std::iter::once(&first).chain(&rivals).collect();
        let Some(Settled { fit, lidar, path }) =
            best_settled(ctx, aligned, &base, &contenders, options)?
        else {
            continue;
        };
        // The plots show the data against the trajectory the verdict rests on.
        if let Some(d) = data.iter_mut().find(|d| d.sensor == Sensor::Lidar) {
            *d = lidar;
        }
        if let Some(c) = candidates.iter_mut().find(|c| c.effect == fit.effect) {
            *c = fit.clone();
        }
        named[at] = fit;
        realigned = Some(path);
    }
    Ok((named, realigned))
}

/// The lidar effects not named whose held-out gain on the first path comes within
/// [`RIVAL_SHARE`] of `first`'s, the [`MAX_RIVALS`] strongest: settled along their own paths
/// beside it ([`realign_lidar`]).
fn lidar_rivals(
    first: &CandidateFit,
    named: &[CandidateFit],
    candidates: &[CandidateFit],
) -> Vec<CandidateFit> {
    let mut rivals: Vec<CandidateFit> = candidates
        .iter()
        .filter(|c| {
            c.effect.sensor() == Sensor::Lidar
                && c.effect.moves_readings()
                && !named.iter().any(|n| n.effect == c.effect)
                && c.heldout_gain >= RIVAL_SHARE * first.heldout_gain
        })
        .cloned()
        .collect();
    rivals.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
    rivals.truncate(MAX_RIVALS);
    rivals
}

/// Share of the strongest lidar effect's held-out gain on the first estimated path a rival
/// needs to be settled beside it. Measured on a warm-up of 30 mm settling in 19 s over a 42 s
/// run without truth: the path took up most of its early shift, leaving it 17 % of a range
/// bias's gain, while along its own path it explains the readings better.
const RIVAL_SHARE: f64 = 0.1;

/// How many rivals are settled: each costs a path estimate a round.
const MAX_RIVALS: usize = 2;

/// Each of `contenders` settled along its own path ([`settle`]), the one the lidar's held-out
/// readings favour kept (the first on a tie). The shapes of an effect that settles them
/// apart ([`crate::Entry::shapes_settled_apart`]: a warm-up's two terms) are settled each from
/// the first fit's size.
fn best_settled(
    ctx: &Context<'_>,
    aligned: &Aligned,
    base: &Hypothesis,
    contenders: &[&CandidateFit],
    options: &Options,
) -> Result<Option<Settled>, MismatchError> {
    let mut best: Option<Settled> = None;
    for &contender in contenders {
        let effect = contender.effect;
        let apart: Vec<&[&[usize]]> = if effect.entry().shapes_settled_apart() {
            effect.shapes().iter().map(std::slice::from_ref).collect()
        } else {
            vec![effect.shapes()]
        };
        for shapes in apart {
            let Some(settled) = settle(ctx, aligned, base, contender, shapes, options)? else {
                continue;
            };
            if best
                .as_ref()
                .is_none_or(|b| settled.fit.heldout_ll_per_reading > b.fit.heldout_ll_per_reading)
            {
                best = Some(settled);
            }
        }
    }
    Ok(best)
}

/// What one lidar effect's rounds settled on: its fit, the lidar's data along the path
/// estimated under it, and that path. Rounds of different shapes are compared by the fit's
/// held-out log-likelihood a reading (the same readings, each along its own path).
struct Settled {
    fit: CandidateFit,
    lidar: SensorData,
    path: Aligned,
}

/// Rounds of estimating the path under `first` (on top of `base`) and refitting it in `shapes`
/// of its own, its size followed to the fixed point; `None` when no round earned its place.
fn settle(
    ctx: &Context<'_>,
    aligned: &Aligned,
    base: &Hypothesis,
    first: &CandidateFit,
    shapes: &[&[usize]],
    options: &Options,
) -> Result<Option<Settled>, MismatchError> {
    let effect = first.effect;
    let cone = declared_cone(ctx);
    // One shape of several: its free parameters, and its start the first fit's size put in
    // its own size term.
    let (only, mut proposal) = match shapes {
        [shape] if effect.shapes().len() > 1 => {
            let mut only: Vec<usize> = shape.to_vec();
            only.sort_unstable();
            let mut start = effect.absent(cone);
            for &i in &only {
                start[i] = first.params[i];
            }
            if let Some(&(i, weight)) = effect.size_terms().iter().find(|(i, _)| only.contains(i)) {
                start[i] = effect.scored(&first.params) / weight;
            }
            (Some(only), start)
        }
        _ => (None, first.params.clone()),
    };
    let mut current: Option<(CandidateFit, SensorData, Aligned)> = None;
    // The size term followed to its fixed point (see below) and each round's (value it was
    // estimated under, refit).
    let mut followed: Option<usize> = None;
    let mut rounds: Vec<(f64, f64)> = Vec::new();
    let mut last_gain = first.heldout_gain;
    for _ in 0..REALIGN_ROUNDS {
        let hypothesis = base.and(effect, proposal.clone());
        let again = align::realign(
            ctx.physics,
            ctx.recording,
            ctx.estimates,
            aligned,
            &hypothesis,
        )?;
        let ctx2 = along(ctx, &again);
        let Some(mut lidar) = residuals::lidar(&ctx2)? else {
            break;
        };
        lidar.clusters = Some(residuals::shared_error_clusters(ctx2.trajectory, &lidar.t));
        let refit =
            explain::fit_candidate_in(&ctx2, &lidar, base, effect, shapes, FitRows::of(options));
        // A refit short of its place ends the rounds unless it explains more than the last
        // (the path still settling under it: a warm-up's constant term grows round by round
        // from the part the first estimate left in the ranges); the rounds go on from it, and
        // the verdict keeps the last round that earned its place.
        let earns = select::earns_place(&refit, cone, options);
        if !earns && refit.heldout_gain <= last_gain {
            break;
        }
        last_gain = refit.heldout_gain;
        // Settled when every parameter the refit chose freely (of a two-shape effect, the
        // shape it took) moved by less than `REALIGN_SETTLED` of its value.
        let free = only.clone().unwrap_or_else(|| effect.free(&refit.params));
        let settled = free.iter().all(|&i| {
            (refit.params[i] - proposal[i]).abs() <= REALIGN_SETTLED * refit.params[i].abs()
        });
        // Followed when one size term (`Effect::size_terms`) is all the refit chose freely, but
        // for the parameters of its form (`Effect::form_params`), which the path does not take
        // up; a mount's yaw and position are iterated plainly.
        let settles_alone = free
            .iter()
            .filter(|i| effect.form_params().contains(i))
            .count();
        let size = effect
            .size_terms()
            .iter()
            .map(|&(i, _)| i)
            .filter(|i| free.contains(i))
            .collect::<Vec<usize>>();
        let single = match size[..] {
            [i] if 1 + settles_alone == free.len() => Some(i),
            _ => None,
        };
        if single != followed {
            rounds.clear();
            followed = single;
        }
        if let Some(i) = single {
            rounds.push((proposal[i], refit.params[i]));
        }
        proposal = refit.params.clone();
        if earns {
            current = Some((refit, lidar, again));
        }
        if settled {
            break;
        }
        if let Some((i, next)) = single.zip(fixed_point_step(&rounds)) {
            let spec = effect.params()[i];
            proposal[i] = next.clamp(spec.lo, spec.hi);
        }
    }
    Ok(current.map(|(fit, lidar, path)| Settled { fit, lidar, path }))
}

#[cfg(test)]
mod tests {
    use super::{
        explaining_their_sensor, fixed_point_step, split_lead, within_the_paths_scale,
        within_the_search, LeadSplit, REALIGN_ROUNDS, REALIGN_SETTLED,
    };
    use crate::catalogue::{Effect, Sensor};
    use crate::conclude::{Left, Nominal};
    use crate::explain::CandidateFit;
    use crate::locate::{Evidence, TestKind};
    use crate::outcome::Options;
    use crate::residuals::Covariate;

    /// The lidar's mean at 4–5 m `size_m` below its overall mean, far beyond its floor.
    fn lidar_left_by_range(size_m: f64) -> Left {
        Left {
            sensor: Sensor::Lidar,
            evidence: vec![Evidence {
                sensor: Sensor::Lidar,
                test: TestKind::BiasAgainst,
                covariate: Some(Covariate::Range),
                score: 12.0,
                place: "range 4.0–5.0 m".into(),
                detail: String::new(),
                range: Some((4.0, 5.0)),
                size_m,
                median_m: size_m,
                noise_m: 0.01,
                world_m: 0.0,
                beyond_world_m: size_m,
            }],
        }
    }

    fn wheels(left: f64, right: f64) -> CandidateFit {
        CandidateFit {
            effect: Effect::OdometerWheelRadius,
            sensor: Sensor::Odometer,
            params: vec![left, right],
            param_sd: vec![0.0005; 2],
            train_gain: 150.0,
            heldout_gain: 130.0,
            bic_gain: 120.0,
            rmse_before: 0.003,
            rmse_after: 0.0025,
            noise_floor: 0.0025,
            heldout_n: 1000,
            rmse_over: crate::RmseOver::ReadingsGivenPast,
            heldout_ll_per_reading: 4.0,
            size_m: 0.05,
            size_noise_m: 0.002,
            floor_multiple: 4.0,
            scaled_rmse: (1.2, 1.0),
            seen_until_s: 60.0,
        }
    }

    #[test]
    fn a_wheel_radius_within_the_lidars_scale_error_is_not_named() {
        let options = Options::default();
        // 30 mm at 4.5 m: the path may be 0.67 % long or short.
        let left = [lidar_left_by_range(0.03)];
        let mut notes = Vec::new();
        let kept =
            within_the_paths_scale(&left, vec![wheels(0.994, 0.995)], 3.0, &options, &mut notes);
        assert!(kept.is_empty());
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].contains("not identifiable"), "{notes:?}");
        // Wheels 2 % small are beyond it; a lidar with nothing left by range scales nothing.
        let mut notes = Vec::new();
        let kept =
            within_the_paths_scale(&left, vec![wheels(0.98, 0.995)], 3.0, &options, &mut notes);
        assert_eq!(kept.len(), 1);
        let quiet = [lidar_left_by_range(0.0001)];
        let kept = within_the_paths_scale(
            &quiet,
            vec![wheels(0.994, 0.995)],
            3.0,
            &options,
            &mut notes,
        );
        assert_eq!(kept.len(), 1);
        assert!(notes.is_empty(), "{notes:?}");
        // A far bin whose mean is 400 mm short from a few readings far off, while its median
        // is 10 mm: the path's scale follows the median, 0.22 %, and 2 % wheels are named.
        let mut gaps = lidar_left_by_range(0.4);
        gaps.evidence[0].median_m = 0.01;
        let kept = within_the_paths_scale(
            &[gaps],
            vec![wheels(0.98, 0.995)],
            3.0,
            &options,
            &mut notes,
        );
        assert_eq!(kept.len(), 1);
        assert!(notes.is_empty(), "{notes:?}");
    }

    /// The lidar's mean departing against `covariate` by `size_m` with `score`.
    fn lidar_bias_against(covariate: Covariate, score: f64, size_m: f64) -> Evidence {
        Evidence {
            covariate: Some(covariate),
            score,
            ..lidar_left_by_range(size_m).evidence.remove(0)
        }
    }

    #[test]
    fn a_warmup_is_named_beside_a_far_error_it_leaves_when_it_explains_the_lidar_in_time() {
        let options = Options::default();
        // A built map's error at far range (the main structure, left whole) and a warm-up's
        // 24 mm in time; the warm-up's fit takes the time structure's score from 31 to `left`.
        let nominal = Nominal {
            sensors: Vec::new(),
            evidence: vec![
                lidar_bias_against(Covariate::Range, 41.0, 0.4),
                lidar_bias_against(Covariate::Time, 31.0, 0.024),
            ],
            misaligned: None,
            threshold: 3.0,
        };
        let left = |time_score: f64| {
            [Left {
                sensor: Sensor::Lidar,
                evidence: vec![
                    lidar_bias_against(Covariate::Range, 41.5, 0.4),
                    lidar_bias_against(Covariate::Time, time_score, 0.012),
                ],
            }]
        };
        let warmup = CandidateFit {
            effect: Effect::LidarWarmupDrift,
            sensor: Sensor::Lidar,
            params: vec![0.0, 400.0, -0.02, 1.0],
            ..wheels(1.0, 1.0)
        };
        let kept = |time_score: f64, path_recorded: bool| {
            explaining_their_sensor(
                &nominal,
                &left(time_score),
                vec![warmup.clone()],
                path_recorded,
                &options,
            )
            .len()
        };
        assert_eq!(kept(12.0, true), 1);
        // Half its time structure standing: it explains neither.
        assert_eq!(kept(20.0, true), 0);
        // Along a path matched from the scans, whose own error changes in time.
        assert_eq!(kept(12.0, false), 0);
        // A mount offset acts through no variable tested in time: it explains the far error
        // or nothing.
        let mount = CandidateFit {
            effect: Effect::LidarMountOffset,
            params: vec![1.0, 0.0, 0.0],
            ..warmup.clone()
        };
        assert!(
            explaining_their_sensor(&nominal, &left(12.0), vec![mount], true, &options).is_empty()
        );
    }

    #[test]
    fn a_fit_stopped_at_its_searchs_edge_is_not_named_and_a_form_at_its_end_is() {
        let mount = |yaw_deg: f64, y_m: f64| CandidateFit {
            effect: Effect::LidarMountOffset,
            sensor: Sensor::Lidar,
            params: vec![yaw_deg, 0.03, y_m],
            ..wheels(1.0, 1.0)
        };
        let slip = |braking_share: f64| CandidateFit {
            effect: Effect::OdometerWheelSlip,
            params: vec![0.05, braking_share],
            ..wheels(1.0, 1.0)
        };
        let mut notes = Vec::new();
        let kept = within_the_search(
            vec![mount(-7.98, 0.0), mount(-5.6, -0.1), mount(2.5, 0.02)],
            &mut notes,
        );
        assert_eq!(kept.len(), 1);
        assert!((kept[0].params[0] - 2.5).abs() < 1e-12);
        assert_eq!(notes.len(), 2, "{notes:?}");
        assert!(notes[0].contains("yaw_deg = -7.98 deg"), "{notes:?}");
        assert!(notes[1].contains("y_m = -0.100 m"), "{notes:?}");
        assert!(notes[1].contains("not identifiable"), "{notes:?}");
        // A braking share of −1 is a form of slip (a lead gained at every change of speed),
        // not a limit: named.
        let mut notes = Vec::new();
        assert_eq!(within_the_search(vec![slip(-1.0)], &mut notes).len(), 1);
        assert!(notes.is_empty(), "{notes:?}");
    }

    /// The realignment's rounds as `realign_lidar` runs them, against a refit that gives back
    /// `share(s)` of the remaining gap to `truth` (the scan matching absorbing the rest).
    fn rounds_to_settle(truth: f64, start: f64, share: impl Fn(f64) -> f64) -> Option<f64> {
        let mut rounds = Vec::new();
        let mut under = start;
        for _ in 0..REALIGN_ROUNDS {
            let after = under + share(under) * (truth - under);
            rounds.push((under, after));
            if (after - under).abs() <= REALIGN_SETTLED * after.abs() {
                return Some(after);
            }
            under = fixed_point_step(&rounds).unwrap_or(after);
        }
        None
    }

    #[test]
    fn the_realignment_reaches_a_slowly_given_back_effect_within_its_rounds() {
        // Motion skew of 0.2 s seen from 0.048 s, given back a fifth to a third a round, as the
        // scan matching gives it back: plain iteration is still 20 % short after six rounds; the
        // secant settles within 2 % of the truth.
        let share = |s: f64| 0.2 + 0.6 * s;
        let settled = rounds_to_settle(0.2, 0.048, share).expect("settles");
        assert!((settled - 0.2).abs() < 0.02 * 0.2, "{settled}");
        let mut plain = 0.048;
        for _ in 0..REALIGN_ROUNDS {
            plain += share(plain) * (0.2 - plain);
        }
        assert!(plain < 0.19, "plain iteration would have done: {plain}");
    }

    #[test]
    fn the_realignment_step_does_not_run_away_unbracketed() {
        // Two rounds that barely move (a flat h): the secant's root is far off; the step is
        // at most three times the last round's own change beyond it.
        let rounds = [(0.1, 0.11), (0.11, 0.1195)];
        let next = fixed_point_step(&rounds).expect("a step");
        assert!(
            next > 0.1195 && next <= 0.11 + 3.0 * 0.0095 + 1e-12,
            "{next}"
        );
        // Bracketed: regula falsi stays between the two sides.
        let rounds = [(0.1, 0.13), (0.25, 0.22)];
        let next = fixed_point_step(&rounds).expect("a step");
        assert!(next > 0.1 && next < 0.25, "{next}");
        assert_eq!(fixed_point_step(&[(0.1, 0.12)]), None);
    }

    /// A lead and what braking keeps of it, named as the catalogue's entries have them: each
    /// reading's gain on a rise (`L`) and on a fall (`L + h`) is kept.
    #[test]
    fn a_lead_is_split_into_the_entries_that_give_it() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        // Encoders 60 ms late whose wheels slip 80 ms on a rise and give none back on a fall:
        // 20 ms ahead on a rise, 60 ms behind on a fall. A slip alone would need a share of −3.
        match split_lead(0.02, Some(-0.08), -1.0) {
            LeadSplit::LateBesideSlip { late_s, gain_s } => {
                assert!(
                    close(late_s, 0.06) && close(gain_s, 0.08),
                    "{late_s} {gain_s}"
                );
            }
            other => panic!("{other:?}"),
        }
        // Late encoders and braking that keeps a lead: late by the fall's lag.
        match split_lead(-0.03, Some(-0.05), -1.0) {
            LeadSplit::LateBesideSlip { late_s, gain_s } => {
                assert!(
                    close(late_s, 0.08) && close(gain_s, 0.05),
                    "{late_s} {gain_s}"
                );
            }
            other => panic!("{other:?}"),
        }
        // A lead of 50 ms whose braking gives back 60 % of it: a slip of that share.
        match split_lead(0.05, Some(-0.02), -1.0) {
            LeadSplit::Slip { gain_s, share } => {
                assert!(close(gain_s, 0.05) && close(share, 0.6), "{gain_s} {share}");
            }
            other => panic!("{other:?}"),
        }
        // Without braking read: the lead's sign.
        assert_eq!(split_lead(-0.04, None, -1.0), LeadSplit::Late(0.04));
        assert_eq!(
            split_lead(0.04, None, -1.0),
            LeadSplit::Slip {
                gain_s: 0.04,
                share: 1.0
            }
        );
    }
}
