//! Which effects to name: forward selection on held-out data. Every applicable effect is fitted
//! on its own; in each sensor the best that earns its place is named, the others are fitted
//! again on top of it, and so on while one earns its place; the effects named in one sensor
//! are then refitted jointly and each must still earn its place against the others.
//!
//! An effect earns its place when it improves the held-out log-likelihood by more than
//! [`Options::min_gain`], its BIC gain on the training half is positive, it does not raise its
//! sensor's held-out RMSE in metres and in units of the readings' noise (a likelihood gained on
//! a few readings while the rest fit worse is not the effect: a lidar mount offset shifted a few millimetres gains tens of nats against a
//! periodic range error outside the catalogue while the RMSE rises), its fitted parameter
//! departs from the effect's absence by more than the sensors resolve (`Effect::departs`),
//! and it changes the predicted readings by more than the sensor's practical floor
//! ([`crate::locate::Floors`]) where it changes them most, in metres or in units of their noise: a small difference between the recording and the simulation
//! that some effect can mimic is not that effect. Against a path estimated from the lidar, a
//! delay of the sonar or the encoders must also exceed the path's own timing
//! ([`Options::path_timing_s`]), and a delay or slip of the encoders their stamps' own scatter
//! ([`Options::encoder_timing_s`]). A range bias must leave nothing of its sensor's error
//! clustered by range ([`leaves_range_structure`]).

use rayon::prelude::*;

use crate::catalogue::{Effect, Sensor};
use crate::conclude::{declared_cone, Left};
use crate::explain::{self, CandidateFit, FitRows};
use crate::locate::{Evidence, Floors, TestKind};
use crate::outcome::Options;
use crate::physics::Hypothesis;
use crate::residuals::Covariate;
use crate::residuals::{Context, SensorData};

/// Effects named in one sensor at most (the catalogue's lidar has five; more than three at
/// once in one sensor is past what a recording of a minute separates).
const MAX_PER_SENSOR: usize = 3;

/// The outcome of the selection.
pub(crate) struct Selection {
    /// The effects named, strongest held-out gain first, each scored against the others of
    /// its sensor.
    pub named: Vec<CandidateFit>,
    /// Every applicable effect fitted on its own against the nominal model, best held-out gain
    /// first.
    pub candidates: Vec<CandidateFit>,
}

/// Whether `c` earns its place (see the module's documentation).
pub(crate) fn earns_place(c: &CandidateFit, declared_cone: f64, options: &Options) -> bool {
    c.heldout_gain > options.min_gain
        && c.bic_gain > 0.0
        && !fits_worse(c)
        && c.effect.departs(&c.params, declared_cone)
        && beyond_floor(c, options)
        && !within_path_timing(c, options)
        && !below_mount_floor(c, options)
        && settles_within_run(c)
}

/// Whether `c` raises its sensor's held-out RMSE in metres beyond the RMSE's own sampling error,
/// or within it while it raises the RMSE in units of the readings' noise too. In metres alone a
/// range sensor's RMSE is its far readings', whose noise grows as the square of the range: an
/// effect that explains near readings (an incidence on a post) while the far walls' noise moves
/// the RMSE by a hair would be refused.
fn fits_worse(c: &CandidateFit) -> bool {
    let rises =
        |before: f64, after: f64| after.partial_cmp(&before) == Some(std::cmp::Ordering::Greater);
    let scaled_falls = matches!(
        c.scaled_rmse.1.partial_cmp(&c.scaled_rmse.0),
        Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
    );
    // An RMSE of n readings has a relative standard error of 1/√(2n).
    let sampling = 1.0 / (2.0 * c.heldout_n.max(1) as f64).sqrt();
    rises(c.rmse_before * (1.0 + sampling), c.rmse_after)
        || (rises(c.rmse_before, c.rmse_after) && !scaled_falls)
}

/// Whether `c` changes its sensor's readings by more than the practical floor, over the readings
/// it changes most in metres or over those it changes most in units of the floor there (whose
/// share of the noise is the readings' own: `Floors`).
fn beyond_floor(c: &CandidateFit, options: &Options) -> bool {
    c.size_m > options.floors.floor_m(c.sensor, c.size_noise_m) || c.floor_multiple > 1.0
}

/// The least share of a recording a warm-up's drift must settle within: its mean settling time
/// (its time constant for one thermal mass) at most the span (for one mass, 63 % of the drift,
/// `1 − e^{−1}`, seen to go; a shorter run names a drift whose τ it barely outlasts, as
/// `a_warmup_of_the_constant_term_is_named_not_a_mount_offset` conceals τ = 15 s in 17 s). A
/// drift that outlasts the run is a constant range error over it, which the warm-up's
/// `(c + k d²) e^{−t/τ}` mimics at τ far beyond the run and a unit's warm-up is not: without
/// truth, a range error of another form than the catalogue's (a reflectivity walk written
/// otherwise) is fitted as a "warm-up" of τ in the hundreds of seconds. The self-test conceals
/// τ of 5–20 s in 60 s runs.
const WARMUP_SETTLED_SHARE: f64 = 1.0;

/// Whether `c`, a lidar warm-up, is seen to settle within the readings it was scored on
/// (anything else is; [`crate::Entry::settles_within`]).
fn settles_within_run(c: &CandidateFit) -> bool {
    c.effect
        .entry()
        .settles_within(&c.params, WARMUP_SETTLED_SHARE * c.seen_until_s)
}

/// Whether `c` is a lidar mount whose position offset is under [`Options::mount_min_m`].
fn below_mount_floor(c: &CandidateFit, options: &Options) -> bool {
    c.effect == Effect::LidarMountOffset && mount_offset_m(&c.params) < options.mount_min_m
}

/// The offset of a lidar mount's position (its parameters yaw, x, y), metres.
pub(crate) fn mount_offset_m(params: &[f64]) -> f64 {
    match params {
        [_yaw, x, y] => x.hypot(*y),
        _ => 0.0,
    }
}

/// Whether `c` is a delay no larger than the trajectory's own timing is known to
/// ([`Options::path_timing_s`]): of a sensor judged along it (the sonar, the encoders), or of the
/// lidar it was estimated from (told only through the other two); or a wheel slip's gain, the
/// mirror of such a delay (encoders leading the path by `g v`, as ones stamped early would;
/// [`crate::Entry::sized_as_a_delay`]). The encoders' are held against their own stamps'
/// scatter too ([`Options::encoder_timing_s`]).
fn within_path_timing(c: &CandidateFit, options: &Options) -> bool {
    let timing_s = if crate::stamps::is_encoder_lead(c.effect) {
        options.path_timing_s.max(options.encoder_timing_s)
    } else {
        options.path_timing_s
    };
    c.effect.entry().sized_as_a_delay() && c.params.first().is_some_and(|d| d.abs() <= timing_s)
}

/// Whether `c` is a range bias (the lidar's or the sonar's) whose sensor's error, under the
/// sensor's named effects (`left`), still clusters by range: the residuals' mean still changes
/// with the range by a departure that counts (significant and above the sensor's floor,
/// [`crate::locate::Evidence::counts`]), or their spread does and keeps more than
/// [`MAX_MAIN_SIZE_LEFT`] of its size under the nominal model (`nominal`, the sensor's tests). A
/// range bias is a function of the range alone, so fitted to an error of its own shape it
/// leaves nothing against the range; what it leaves there is an error of another shape (a
/// periodic one, `A sin(2π d/λ)`, outside the catalogue) whose slow part its polynomial took
/// up, and that error is not the unit's calibration. A ripple much shorter than the range's
/// bins averages out in each bin's mean and shows as their spread instead, which a bias moves
/// not at all. A spread left against the range counts only where it is the range's: stronger
/// than the spread left against any other variable. A ripple in d shows against the range
/// first; an excess of the spread everywhere (a noise heavier than declared) shows against
/// every variable a run's path ties to the range (time, speed, bearing) about as strongly.
pub(crate) fn leaves_range_structure(
    c: &CandidateFit,
    nominal: &[Evidence],
    left: &[Left],
    threshold: f64,
    floors: &Floors,
) -> bool {
    let sensor = c.effect.sensor();
    let against_range = |e: &&Evidence, test: TestKind| {
        e.sensor == sensor && e.test == test && e.covariate == Some(Covariate::Range)
    };
    let spread_before = nominal
        .iter()
        .find(|e| against_range(e, TestKind::SpreadAgainst))
        .map_or(f64::INFINITY, |e| e.size_m);
    let counted: Vec<&Evidence> = left
        .iter()
        .filter(|l| l.sensor == sensor)
        .flat_map(|l| l.evidence.iter())
        .filter(|e| e.counts(threshold, floors))
        .collect();
    // The strongest spread left against another variable than the range.
    let spread_elsewhere = counted
        .iter()
        .filter(|e| e.test == TestKind::SpreadAgainst && e.covariate != Some(Covariate::Range))
        .map(|e| e.score)
        .fold(0.0, f64::max);
    c.effect.entry().is_range_calibration()
        && counted.iter().any(|e| {
            against_range(e, TestKind::BiasAgainst)
                || (against_range(e, TestKind::SpreadAgainst)
                    && e.size_m > MAX_MAIN_SIZE_LEFT * spread_before
                    && e.score > spread_elsewhere)
        })
}

/// Share of a sensor's main structure's size (metres) its named effects may leave, and of its
/// spread against the range a range bias may leave ([`leaves_range_structure`]).
pub(crate) const MAX_MAIN_SIZE_LEFT: f64 = 0.5;

/// The hypothesis of the effects `fits` with their parameters.
pub(crate) fn hypothesis_of(fits: &[CandidateFit]) -> Hypothesis {
    on_top_of(&Hypothesis::nominal(), fits)
}

/// `base` with the effects `fits` switched on as well.
fn on_top_of(base: &Hypothesis, fits: &[CandidateFit]) -> Hypothesis {
    fits.iter()
        .fold(base.clone(), |h, c| h.and(c.effect, c.params.clone()))
}

/// The effects named in other sensors than `sensor` that show in it too (the wheels' radius
/// and base, named in the odometer, move the drive): its effects are fitted on top of them.
fn carried_into(named: &[CandidateFit], sensor: Sensor) -> impl Iterator<Item = &CandidateFit> {
    named
        .iter()
        .filter(move |c| c.effect.sensor() != sensor && c.effect.shows_in(sensor))
}

/// Every applicable effect fitted on its own (in parallel: each is independent), best held-out
/// gain first.
fn first_round(ctx: &Context<'_>, data: &[SensorData], options: &Options) -> Vec<CandidateFit> {
    let present: Vec<Sensor> = data.iter().map(|d| d.sensor).collect();
    let tries: Vec<(Effect, &SensorData)> = options
        .effects
        .iter()
        .filter(|e| explain::applicable(**e, ctx, &present))
        .filter_map(|&e| data.iter().find(|d| d.sensor == e.sensor()).map(|d| (e, d)))
        .collect();
    let nominal = Hypothesis::nominal();
    let mut candidates: Vec<CandidateFit> = tries
        .par_iter()
        .map(|(e, d)| explain::fit_candidate(ctx, d, &nominal, *e, FitRows::of(options)))
        .collect();
    candidates.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
    candidates
}

/// Forward selection in one sensor's `data` on top of `base` (the effects named elsewhere that
/// show here), starting from `pool` (its effects fitted on their own on `base`), then the
/// joint refit.
fn select_in(
    ctx: &Context<'_>,
    data: &SensorData,
    mut pool: Vec<CandidateFit>,
    base: &Hypothesis,
    options: &Options,
) -> Vec<CandidateFit> {
    let cone = declared_cone(ctx);
    let alone = pool.clone();
    let mut chosen: Vec<CandidateFit> = Vec::new();
    while chosen.len() < MAX_PER_SENSOR {
        let Some(k) = pool
            .iter()
            .enumerate()
            .filter(|(_, c)| earns_place(c, cone, options))
            .max_by(|a, b| a.1.heldout_gain.total_cmp(&b.1.heldout_gain))
            .map(|(k, _)| k)
        else {
            break;
        };
        chosen.push(pool.swap_remove(k));
        // Only an effect that gains on its own is tried on top of the others: one that does
        // not explains nothing the others leave (the gains of effects of one sensor add up to
        // about their joint gain unless they mimic each other, and then the second gains less,
        // not more), and each refit costs a whole fit.
        pool.retain(|c| c.heldout_gain > options.min_gain);
        if pool.is_empty() || chosen.len() == MAX_PER_SENSOR {
            break;
        }
        pool = on_top_of_chosen(ctx, data, base, &chosen, &pool, options);
        if pool.iter().any(|c| earns_place(c, cone, options)) {
            continue;
        }
        // Not against a path estimated from the lidar: it took up part of each lidar effect,
        // which the named effect's rounds give back, and its own error shows in every sensor
        // judged along it, which two effects that trade would share out between them (wheels
        // that slip at every change of speed and a radius a percent short).
        if ctx.estimated {
            break;
        }
        // None gains on top of those chosen, their parameters held. Where two effects'
        // parameters trade (a sonar's offset and its scale over a room's ranges), the first
        // named took up part of the other, which then still gains on top of it, but too
        // little to earn its place: each such candidate that earned its place on its own is
        // refitted jointly with those chosen, and taken when every effect of the joint fit
        // earns its place against the others. (One that gains nothing at all on top of them
        // mimics them and is not tried: each joint refit costs several fits.)
        let Some(joint) = pool
            .par_iter()
            .filter(|c| c.heldout_gain > 0.0)
            .filter_map(|c| {
                let own = alone.iter().find(|a| a.effect == c.effect)?;
                if !earns_place(own, cone, options) {
                    return None;
                }
                // From its fit on top of them: its own fit took up the others' part too.
                let trial: Vec<CandidateFit> = chosen.iter().cloned().chain([c.clone()]).collect();
                let joint = explain::refit_jointly(ctx, data, &trial, base, options.max_fit_rows);
                joint
                    .iter()
                    .all(|j| earns_place(j, cone, options))
                    .then_some(joint)
            })
            .max_by(|a, b| {
                let last =
                    |j: &[CandidateFit]| j.last().map_or(f64::NEG_INFINITY, |c| c.heldout_gain);
                last(a).total_cmp(&last(b))
            })
        else {
            break;
        };
        let added = joint.last().map(|c| c.effect);
        pool.retain(|c| Some(c.effect) != added);
        chosen = joint;
        if pool.is_empty() {
            break;
        }
        pool = on_top_of_chosen(ctx, data, base, &chosen, &pool, options);
    }
    // Jointly; an effect the others make redundant is dropped and the rest refitted.
    while chosen.len() >= 2 {
        let joint = explain::refit_jointly(ctx, data, &chosen, base, options.max_fit_rows);
        let kept: Vec<CandidateFit> = joint
            .iter()
            .filter(|c| earns_place(c, cone, options))
            .cloned()
            .collect();
        if kept.len() == joint.len() {
            return joint;
        }
        if kept.len() == 1 {
            // Alone again: scored against the base, as in the first round.
            let alone =
                explain::fit_candidate(ctx, data, base, kept[0].effect, FitRows::of(options));
            return if earns_place(&alone, cone, options) {
                vec![alone]
            } else {
                Vec::new()
            };
        }
        chosen = kept;
    }
    chosen
}

/// Each of `pool` fitted again on top of `base` and the effects `chosen`.
fn on_top_of_chosen(
    ctx: &Context<'_>,
    data: &SensorData,
    base: &Hypothesis,
    chosen: &[CandidateFit],
    pool: &[CandidateFit],
    options: &Options,
) -> Vec<CandidateFit> {
    let under = on_top_of(base, chosen);
    pool.par_iter()
        .map(|c| explain::fit_candidate(ctx, data, &under, c.effect, FitRows::of(options)))
        .collect()
}

/// The effects to name in `data`, with every candidate fitted on its own.
pub(crate) fn select(ctx: &Context<'_>, data: &[SensorData], options: &Options) -> Selection {
    let candidates = first_round(ctx, data, options);
    let mut named: Vec<CandidateFit> = Vec::new();
    // In the data's order (lidar, sonar, odometer, drive): an effect named in the odometer
    // that moves the drive too is in place before the drive's are fitted.
    for d in data {
        let carried: Vec<CandidateFit> = carried_into(&named, d.sensor).cloned().collect();
        let base = hypothesis_of(&carried);
        let mut pool: Vec<CandidateFit> = candidates
            .iter()
            .filter(|c| c.effect.sensor() == d.sensor)
            .cloned()
            .collect();
        if !base.is_nominal() {
            pool = pool
                .par_iter()
                .map(|c| explain::fit_candidate(ctx, d, &base, c.effect, FitRows::of(options)))
                .collect();
        }
        named.extend(select_in(ctx, d, pool, &base, options));
    }
    named.sort_by(|a, b| b.heldout_gain.total_cmp(&a.heldout_gain));
    Selection { named, candidates }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fit of `effect` that earns its place on every count but the ones under test.
    fn fitted(effect: Effect, params: Vec<f64>) -> CandidateFit {
        CandidateFit {
            effect,
            sensor: Sensor::Lidar,
            param_sd: vec![0.001; params.len()],
            params,
            train_gain: 500.0,
            heldout_gain: 400.0,
            bic_gain: 300.0,
            rmse_before: 0.03,
            rmse_after: 0.02,
            noise_floor: 0.02,
            heldout_n: 10_000,
            rmse_over: crate::explain::RmseOver::Readings,
            heldout_ll_per_reading: 2.0,
            size_m: 0.02,
            size_noise_m: 0.01,
            floor_multiple: 4.0,
            scaled_rmse: (1.5, 1.0),
            seen_until_s: 60.0,
        }
    }

    /// Against an estimated path (as `Options::against` sets it).
    fn estimated() -> Options {
        Options {
            mount_min_m: crate::outcome::ESTIMATED_MOUNT_MIN_M,
            path_timing_s: crate::outcome::ESTIMATED_PATH_TIMING_S,
            ..Options::default()
        }
    }

    /// A lidar mount fitted 7 mm off earns its place against truth (its own 5 mm departure) but
    /// not against an estimated path, whose floor is 1 cm; one 2 cm off earns it against both.
    #[test]
    fn a_small_mount_is_not_named_against_an_estimated_path() {
        let mount = |x_m: f64| fitted(Effect::LidarMountOffset, vec![1.0, x_m, 0.0]);
        let truth = Options::default();
        assert!(earns_place(&mount(0.007), 15.0, &truth));
        assert!(!earns_place(&mount(0.007), 15.0, &estimated()));
        assert!(earns_place(&mount(0.02), 15.0, &estimated()));
        assert_eq!(mount_offset_m(&[2.0, 0.003, -0.004]), 0.005);
    }

    /// A delay of any sensor, and a wheel slip's gain (a delay's mirror), within the estimated
    /// path's timing is not named against it; against truth it is.
    #[test]
    fn delays_and_slips_within_the_paths_timing_are_not_named() {
        let truth = Options::default();
        for effect in [
            Effect::SensorLatency(Sensor::Lidar),
            Effect::SensorLatency(Sensor::Odometer),
            Effect::OdometerWheelSlip,
        ] {
            let short = fitted(effect, vec![0.010]);
            assert!(earns_place(&short, 15.0, &truth), "{effect:?}");
            assert!(!earns_place(&short, 15.0, &estimated()), "{effect:?}");
            assert!(earns_place(&fitted(effect, vec![0.03]), 15.0, &estimated()));
        }
    }

    /// Encoders whose stamps scatter by 60 ms do not show a delay or a slip's lead of 50 ms
    /// (against truth too); the lidar's delay is not theirs.
    #[test]
    fn the_encoders_lead_within_their_stamps_scatter_is_not_named() {
        let scattered = Options {
            encoder_timing_s: 0.06,
            ..Options::default()
        };
        for effect in [
            Effect::SensorLatency(Sensor::Odometer),
            Effect::OdometerWheelSlip,
        ] {
            assert!(!earns_place(&fitted(effect, vec![0.05]), 15.0, &scattered));
            assert!(earns_place(&fitted(effect, vec![0.08]), 15.0, &scattered));
        }
        let lidar = fitted(Effect::SensorLatency(Sensor::Lidar), vec![0.05]);
        assert!(earns_place(&lidar, 15.0, &scattered));
    }

    /// A test of the lidar's residuals against `covariate`, of `size_m`, scored 50 (beyond any
    /// threshold).
    fn left_against(test: TestKind, covariate: Covariate, size_m: f64) -> Left {
        let evidence = crate::locate::Evidence {
            sensor: Sensor::Lidar,
            test,
            covariate: Some(covariate),
            score: 50.0,
            place: String::new(),
            detail: String::new(),
            range: None,
            size_m,
            median_m: size_m,
            noise_m: 0.01,
            world_m: 0.0,
            beyond_world_m: size_m,
        };
        Left {
            sensor: Sensor::Lidar,
            evidence: vec![evidence],
        }
    }

    /// A range bias that leaves the lidar's mean clustered by range (beyond the floor), or its
    /// spread by range at more than half its nominal size, is a range error of another shape
    /// whose slow part it took up: refused. One that leaves them within the floor, the spread
    /// at half its nominal size, or structure against another variable, is not refused for it;
    /// nor is an effect other than a range bias.
    #[test]
    fn a_range_bias_leaving_the_error_clustered_by_range_is_refused() {
        let floors = Floors::default();
        let bias = fitted(Effect::LidarRangeBias, vec![0.0, 0.01, 0.0]);
        // Under the nominal model the spread by range is 20 mm.
        let nominal = left_against(TestKind::SpreadAgainst, Covariate::Range, 0.02).evidence;
        let refused = |c: &CandidateFit, left: Left| {
            leaves_range_structure(c, &nominal, &[left], 3.6, &floors)
        };
        assert!(refused(
            &bias,
            left_against(TestKind::BiasAgainst, Covariate::Range, 0.013)
        ));
        assert!(!refused(
            &bias,
            left_against(TestKind::BiasAgainst, Covariate::Range, 0.003)
        ));
        assert!(refused(
            &bias,
            left_against(TestKind::SpreadAgainst, Covariate::Range, 0.013)
        ));
        assert!(!refused(
            &bias,
            left_against(TestKind::SpreadAgainst, Covariate::Range, 0.009)
        ));
        assert!(!refused(
            &bias,
            left_against(TestKind::BiasAgainst, Covariate::Incidence, 0.013)
        ));
        let warmup = fitted(Effect::LidarWarmupDrift, vec![-0.002, 15.0, 0.0]);
        assert!(!refused(
            &warmup,
            left_against(TestKind::BiasAgainst, Covariate::Range, 0.013)
        ));
    }

    /// A warm-up whose time constant outlasts the 60 s it was seen over is a constant range
    /// error there, not named (as fitted beside a reflectivity of another form: τ ≈ 990 s);
    /// one that settles within it is.
    #[test]
    fn a_warmup_that_does_not_settle_within_the_run_is_not_named() {
        let warmup = |tau_s: f64| fitted(Effect::LidarWarmupDrift, vec![-0.002, tau_s, 0.0]);
        for options in [Options::default(), estimated()] {
            assert!(earns_place(&warmup(15.0), 15.0, &options));
            assert!(earns_place(&warmup(60.0), 15.0, &options));
            assert!(!earns_place(&warmup(61.0), 15.0, &options));
            assert!(!earns_place(&warmup(990.0), 15.0, &options));
        }
    }
}
