//! Explain: fit each catalogued effect's parameters by maximum likelihood on the training half,
//! then compare it with "none" (and with the others) on the held-out half: the held-out
//! log-likelihood gain is the score, the Bayesian information criterion on the training half a
//! second opinion. Effects are fitted on top of a base (those already named in the sensor),
//! and the effects named in one sensor are refitted jointly.

use crate::catalogue::{Effect, ParamSpec, Sensor};
use crate::optimize::{maximize_shapes, refine, standard_errors, Objective};
use crate::physics::Hypothesis;
use crate::residuals::{fits, log_likelihood, rmse, Context, Fit, Predictive, SensorData};
use crate::Options;

/// One candidate effect, fitted and scored against a base model (the nominal one, or the
/// effects already named in its sensor).
#[derive(Debug, Clone, PartialEq)]
pub struct CandidateFit {
    /// The effect.
    pub effect: Effect,
    /// The sensor whose readings scored it: the effect's own, but for a lidar mount offset
    /// seen, against a path estimated from the lidar, through the sensors that look from the
    /// robot.
    pub sensor: Sensor,
    /// Maximum-likelihood parameters (training half).
    pub params: Vec<f64>,
    /// Their standard errors (inverse observed information); NaN where the likelihood is flat.
    pub param_sd: Vec<f64>,
    /// Log-likelihood gain over the base on the training half.
    pub train_gain: f64,
    /// Log-likelihood gain over the base on the held-out half: the score.
    pub heldout_gain: f64,
    /// BIC gain over the base: `2 · train_gain − k ln n` (positive favours the effect).
    pub bic_gain: f64,
    /// Held-out RMSE of the sensor's residuals before (the base) and after the fit, metres.
    pub rmse_before: f64,
    /// See `rmse_before`.
    pub rmse_after: f64,
    /// The noise floor there: RMS of the predicted standard deviations after the fit, metres.
    pub noise_floor: f64,
    /// Held-out readings (or steps, [`RmseOver::PathSteps`]) the RMSEs are over.
    pub heldout_n: usize,
    /// What the RMSEs are over: what the report says and its residual plots show.
    pub rmse_over: RmseOver,
    /// The mean log-likelihood of every held-out reading under the fit, nats a reading: how
    /// fits along different estimated paths (which may keep a few readings near a range limit
    /// in one and not another) compare on the same readings.
    pub heldout_ll_per_reading: f64,
    /// How much the effect changes the predicted readings, metres: the median (a range sensor)
    /// or RMS change of the predictive mean over the tenth of the held-out readings it changes
    /// most (at least 30),
    /// so an effect that acts on a few readings (edges, the first seconds) is measured where
    /// it acts.
    pub size_m: f64,
    /// The declared noise over those readings (RMS predicted standard deviation), metres.
    pub size_noise_m: f64,
    /// How far beyond its sensor's practical floor ([`crate::locate::Floors`]) the effect
    /// changes the readings, as a multiple of the floor: the median over the hundredth of the
    /// held-out readings (at least 30) it changes most in units of the floor there. A range
    /// sensor's floor grows with its noise, and so with the range: an effect that acts at short
    /// range or on a near object (an incidence on a post) is measured where it shows, not under
    /// the far walls' noise.
    pub floor_multiple: f64,
    /// Held-out root mean square of the residuals in units of their predicted standard
    /// deviations, before and after the fit, over the readings of `rmse_before`: a
    /// heteroscedastic sensor's RMSE in metres is its noisiest readings'.
    pub scaled_rmse: (f64, f64),
    /// The latest reading scored, seconds from the recording's start (a warm-up's clock):
    /// how long a drift could be seen to settle.
    pub seen_until_s: f64,
}

/// What a fit's held-out RMSEs are over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RmseOver {
    /// Each reading against the physics' prediction alone.
    Readings,
    /// Each reading predicted given the readings before it (the encoders along a path estimated
    /// from the lidar, whose error they share).
    ReadingsGivenPast,
    /// The sideways motion of the lidar-matched path's steps, which wheels cannot make (a
    /// lidar's mount yaw read from it: `crab.rs`).
    PathSteps,
    /// The lidar-matched path's spans against the encoders': their turns as the wheels' travel
    /// apart, or their travel (`wheel_spans.rs`).
    PathSpans,
    /// A sparse truth's spans between its poses against the encoders', the same way.
    TruthSpans,
}

impl RmseOver {
    /// Whether the fit was read from the path's own motion (its steps or spans) rather than
    /// from its sensor's readings: that motion is its evidence.
    #[must_use]
    pub fn of_path_motion(self) -> bool {
        matches!(self, Self::PathSteps | Self::PathSpans | Self::TruthSpans)
    }
}

/// Readings the size of an effect is measured over: this share of the held-out ones, at
/// least [`SIZE_MIN_READINGS`].
const SIZE_SHARE: f64 = 0.1;
/// The share of the held-out readings the multiple of the floor is measured over (at least
/// [`SIZE_MIN_READINGS`]): an effect that shows on one object of a room (the oblique readings of
/// a post, a hundredth or two of a scan) is measured on that object.
const FLOOR_MULTIPLE_SHARE: f64 = 0.01;
const SIZE_MIN_READINGS: usize = 30;

/// How many training readings a fit uses: at most `max` per sensor, the coarse grid of its
/// search at most `grid` ([`Options::max_fit_rows`], [`Options::grid_fit_rows`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FitRows {
    pub max: usize,
    pub grid: usize,
}

impl FitRows {
    pub(crate) fn of(options: &Options) -> Self {
        Self {
            max: options.max_fit_rows,
            grid: options.grid_fit_rows,
        }
    }

    /// `data`'s training rows the fit uses, and those its grid is searched on when fewer.
    fn of_data(self, data: &SensorData) -> (Vec<usize>, Option<Vec<usize>>) {
        let train = fit_rows(data, self.max);
        let grid = fit_rows(data, self.grid);
        let thinner = grid.len() < train.len();
        (train, thinner.then_some(grid))
    }
}

/// Training rows for fitting: every `stride`-th, at most `max_rows`. Data of two rows per
/// reading (the encoders' two wheels) take an odd stride, so that both rows stay in.
pub(crate) fn fit_rows(data: &SensorData, max_rows: usize) -> Vec<usize> {
    let train = data.rows(Some(false));
    let mut stride = train.len().div_ceil(max_rows.max(1)).max(1);
    if data.queries.rows_per_reading() == 2 && stride % 2 == 0 {
        stride += 1;
    }
    train.into_iter().step_by(stride).collect()
}

/// The log-likelihood of `rows` under `h`: what an effect is scored by (its gains, the BIC,
/// its standard errors).
fn total_ll(ctx: &Context<'_>, data: &SensorData, h: &Hypothesis, rows: &[usize]) -> f64 {
    summed_ll(data, rows, &ctx.predict(data, h, rows))
}

/// The log-likelihood a fit maximises: that of each reading's own prediction, an error the
/// readings share (the encoders' along an estimated path) left independent. The parameters
/// are then the readings' least-squares-like match, which that error does not bias but only
/// makes less certain (so it enters the scoring, [`total_ll`]); conditioned on the readings
/// before, the likelihood is flat along what the shared error could also explain, and a mount
/// fitted through the encoders by it lands far off (several times its size).
fn fit_ll(ctx: &Context<'_>, data: &SensorData, h: &Hypothesis, rows: &[usize]) -> f64 {
    summed_ll(data, rows, &ctx.predict_unconditioned(data, h, rows))
}

fn summed_ll(data: &SensorData, rows: &[usize], preds: &[Predictive]) -> f64 {
    rows.iter()
        .zip(preds)
        .map(|(&i, p)| log_likelihood(data.y[i], p, data.epsilon, data.outlier_density))
        .sum()
}

/// The mean of a predictive mixture (NaN: no reading expected).
fn predictive_mean(p: &Predictive) -> f64 {
    let w: f64 = p.iter().map(|g| g.weight).sum();
    if p.is_empty() || w <= 0.0 {
        return f64::NAN;
    }
    p.iter().map(|g| g.weight * g.mean_m).sum::<f64>() / w
}

/// The effect size: the change of the predictive mean from `before` to `after` over the
/// readings it changes most (the share [`SIZE_SHARE`]), with the predicted standard deviation
/// there; and the multiple of the practical floor (`floor` of a reading's standard deviation)
/// the effect changes the readings by where it changes them most in units of that floor (the
/// median over the share [`FLOOR_MULTIPLE_SHARE`]). For a range sensor it is the median of those changes (and the standard deviation of
/// that reading): a geometric effect (a mount, a delay) flips a few readings at an object's
/// edge between two surfaces metres apart, which would make a millimetre's effect look a metre
/// large. The encoders' and the drive's predictions have no such jumps, and an effect of
/// theirs acts on few readings (a lag on the windows after a change of command): their RMS.
fn effect_size(
    before: &[Predictive],
    after: &[Predictive],
    ranges: bool,
    world_reach_m: &[f64],
    floor: &dyn Fn(f64) -> f64,
) -> ((f64, f64), f64) {
    let mut change: Vec<(f64, f64)> = before
        .iter()
        .zip(after)
        .enumerate()
        .filter_map(|(k, (b, a))| {
            // Beyond what the world's own error can move the reading (a map's cells).
            let reach = world_reach_m.get(k).copied().unwrap_or(0.0);
            let raw = (predictive_mean(a) - predictive_mean(b)).abs();
            let d = if raw.is_finite() {
                (raw - reach).max(0.0)
            } else {
                raw
            };
            let sd = a.iter().map(|g| g.weight * g.sd_m).sum::<f64>()
                / a.iter().map(|g| g.weight).sum::<f64>();
            (d.is_finite() && sd.is_finite()).then_some((d.abs(), sd))
        })
        .collect();
    if change.is_empty() {
        return ((0.0, f64::NAN), 0.0);
    }
    let n = change.len();
    let top_k = |share: f64| ((n as f64 * share) as usize).max(SIZE_MIN_READINGS).min(n);
    let size_of_top = |top: &[(f64, f64)]| {
        let k = top.len();
        if ranges {
            return top[k / 2];
        }
        let rms = |f: &dyn Fn(&(f64, f64)) -> f64| {
            (top.iter().map(|x| f(x).powi(2)).sum::<f64>() / k as f64).sqrt()
        };
        (rms(&|x| x.0), rms(&|x| x.1))
    };
    change.sort_by(|a, b| b.0.total_cmp(&a.0));
    let in_metres = size_of_top(&change[..top_k(SIZE_SHARE)]);
    let mut multiples: Vec<f64> = change
        .iter()
        .map(|&(d, sd)| {
            let f = floor(sd);
            if f > 0.0 {
                d / f
            } else {
                0.0
            }
        })
        .collect();
    multiples.sort_by(|a, b| b.total_cmp(a));
    let k = top_k(FLOOR_MULTIPLE_SHARE);
    (in_metres, multiples[k / 2])
}

/// The root mean square of `fits`' residuals in units of their standard deviations, over those
/// `keep` keeps.
fn scaled_rms(fits: &[Fit], keep: impl Fn(usize) -> bool) -> f64 {
    let scaled: Vec<f64> = fits
        .iter()
        .enumerate()
        .filter(|(i, f)| f.residual.is_finite() && f.sd > 0.0 && keep(*i))
        .map(|(_, f)| (f.residual / f.sd).powi(2))
        .collect();
    if scaled.is_empty() {
        return f64::NAN;
    }
    (scaled.iter().sum::<f64>() / scaled.len() as f64).sqrt()
}

/// Scores `effect` with `params` on top of `base`: its gains over the base on both halves,
/// the held-out RMSE before and after, its size; `param_sd` from the curvature of the training
/// likelihood in its own parameters (the base held fixed).
pub(crate) fn score(
    ctx: &Context<'_>,
    data: &SensorData,
    base: &Hypothesis,
    effect: Effect,
    params: Vec<f64>,
    train: &[usize],
) -> CandidateFit {
    let train_base = total_ll(ctx, data, base, train);
    let mut objective = |x: &[f64]| total_ll(ctx, data, &base.and(effect, x.to_vec()), train);
    let best = objective(&params);
    let param_sd = free_standard_errors(effect, &params, best, &mut objective);
    // The BIC's count is the free parameters' (a held one was not fitted).
    let free = effect.free(&params);
    let fitted = base.and(effect, params.clone());
    let heldout = data.rows(Some(true));
    let before_p = ctx.predict(data, base, &heldout);
    let after_p = ctx.predict(data, &fitted, &heldout);
    let before = fits(data, &heldout, &before_p);
    let after = fits(data, &heldout, &after_p);
    let heldout_ll: f64 = after.iter().map(|f| f.ll).sum();
    let heldout_gain = heldout_ll - before.iter().map(|f| f.ll).sum::<f64>();
    // RMSE over the held-out readings the fitted model explains (not outliers to it), before
    // and after: a reading neither model can predict (a rare direction-noise flip past the
    // quadrature's reach) would otherwise dominate both.
    let both = |i: usize| before[i].residual.is_finite() && !after[i].outlier;
    let (rmse_before, _, _) = rmse(&before, both);
    let (rmse_after, noise_floor, heldout_n) = rmse(&after, both);
    let scaled_rmse = (scaled_rms(&before, both), scaled_rms(&after, both));
    let ranges = matches!(data.sensor, Sensor::Lidar | Sensor::Sonar);
    // Along a path matched from the scans the path's own error changes in time as well (it
    // is matched from the first scans alone at the start), so there the world's reach counts
    // against every effect.
    let reach: Vec<f64> = if ctx.estimated || effect.entry().mimicked_by_the_world() {
        heldout.iter().map(|&i| data.world_reach(i)).collect()
    } else {
        Vec::new()
    };
    let floor = |noise_m: f64| ctx.floors.floor_m(data.sensor, noise_m);
    let ((size_m, size_noise_m), floor_multiple) = if ctx.conditions(data) {
        effect_size(
            &ctx.predict_unconditioned(data, base, &heldout),
            &ctx.predict_unconditioned(data, &fitted, &heldout),
            ranges,
            &reach,
            &floor,
        )
    } else {
        effect_size(&before_p, &after_p, ranges, &reach, &floor)
    };
    let train_gain = best - train_base;
    CandidateFit {
        effect,
        sensor: data.sensor,
        bic_gain: 2.0 * train_gain - free.len() as f64 * (train.len() as f64).ln(),
        params,
        param_sd,
        train_gain,
        heldout_gain,
        rmse_before,
        rmse_after,
        noise_floor,
        heldout_n,
        rmse_over: if ctx.conditions(data) {
            RmseOver::ReadingsGivenPast
        } else {
            RmseOver::Readings
        },
        heldout_ll_per_reading: heldout_ll / after.len().max(1) as f64,
        size_m,
        size_noise_m,
        floor_multiple,
        scaled_rmse,
        seen_until_s: data.t.iter().copied().fold(0.0, f64::max),
    }
}

/// Fits `effect` on top of `base` to its sensor's data and scores it.
pub(crate) fn fit_candidate(
    ctx: &Context<'_>,
    data: &SensorData,
    base: &Hypothesis,
    effect: Effect,
    rows: FitRows,
) -> CandidateFit {
    fit_candidate_in(ctx, data, base, effect, effect.shapes(), rows)
}

/// As [`fit_candidate`], searching only `shapes` of the effect's (see [`Effect::shapes`]).
pub(crate) fn fit_candidate_in(
    ctx: &Context<'_>,
    data: &SensorData,
    base: &Hypothesis,
    effect: Effect,
    shapes: &[&[usize]],
    rows: FitRows,
) -> CandidateFit {
    let specs = effect.params();
    let (train, grid) = rows.of_data(data);
    let ll_on = |x: &[f64], rows: &[usize]| fit_ll(ctx, data, &base.and(effect, x.to_vec()), rows);
    let mut coarse = grid.map(|grid| move |x: &[f64]| ll_on(x, &grid));
    let (params, _) = maximize_shapes(
        specs,
        shapes,
        effect.shapes_refined_together(),
        effect.refined_besides_shapes(ctx.estimated),
        &effect.absent(0.0),
        &mut |x: &[f64]| ll_on(x, &train),
        coarse.as_mut().map(|c| c as Objective<'_>),
    );
    let mut fit = score(ctx, data, base, effect, params, &train);
    // A parameter of none of the shapes searched (of fewer than the effect's) was held at its
    // absence, not fitted: its standard error is 0, shown as "held".
    if shapes.len() < effect.shapes().len() {
        for (i, sd) in fit.param_sd.iter_mut().enumerate() {
            if !shapes.iter().any(|shape| shape.contains(&i)) {
                *sd = 0.0;
            }
        }
    }
    fit
}

/// Fits `effect` on top of `base` to several sensors' data at once (their summed training
/// log-likelihood): the parameters and their standard errors (from that sum's curvature; a
/// held parameter's 0).
pub(crate) fn fit_across(
    ctx: &Context<'_>,
    data: &[&SensorData],
    base: &Hypothesis,
    effect: Effect,
    rows: FitRows,
) -> (Vec<f64>, Vec<f64>) {
    let (trains, grids): (Vec<Vec<usize>>, Vec<Option<Vec<usize>>>) =
        data.iter().map(|d| rows.of_data(d)).unzip();
    let across = |x: &[f64],
                  ll: fn(&Context<'_>, &SensorData, &Hypothesis, &[usize]) -> f64,
                  coarse: bool| {
        let h = base.and(effect, x.to_vec());
        data.iter()
            .zip(&trains)
            .zip(&grids)
            .map(|((d, train), grid)| {
                let rows = match grid {
                    Some(grid) if coarse => grid,
                    _ => train,
                };
                ll(ctx, d, &h, rows)
            })
            .sum::<f64>()
    };
    let thinned = grids.iter().any(Option::is_some);
    let mut coarse = thinned.then_some(|x: &[f64]| across(x, fit_ll, true));
    let (params, _) = maximize_shapes(
        effect.params(),
        effect.shapes(),
        effect.shapes_refined_together(),
        effect.refined_besides_shapes(ctx.estimated),
        &effect.absent(0.0),
        &mut |x: &[f64]| across(x, fit_ll, false),
        coarse.as_mut().map(|c| c as Objective<'_>),
    );
    let mut scored = |x: &[f64]| across(x, total_ll, false);
    let best = scored(&params);
    let param_sd = free_standard_errors(effect, &params, best, &mut scored);
    (params, param_sd)
}

/// The standard errors of `effect`'s `params` from the curvature of `log_likelihood` (whose
/// value there is `best`) in the free parameters; a parameter the fit held at its absence was
/// not fitted, its standard error is 0.
fn free_standard_errors(
    effect: Effect,
    params: &[f64],
    best: f64,
    log_likelihood: &mut dyn FnMut(&[f64]) -> f64,
) -> Vec<f64> {
    let free = effect.free(params);
    let mut param_sd = in_free_standard_errors(effect, params, &free, best, log_likelihood);
    // A form the data do not determine (an incidence's power of tan θ where nothing is met
    // obliquely) leaves the curvature singular: the size's error is then given at that form.
    if param_sd.iter().any(|sd| !sd.is_finite()) {
        let sized: Vec<usize> = free
            .iter()
            .copied()
            .filter(|i| !effect.form_params().contains(i))
            .collect();
        if sized.len() < free.len() {
            param_sd = in_free_standard_errors(effect, params, &sized, best, log_likelihood);
        }
    }
    param_sd
}

/// The standard errors of `params`' parameters `free` (the others 0).
fn in_free_standard_errors(
    effect: Effect,
    params: &[f64],
    free: &[usize],
    best: f64,
    log_likelihood: &mut dyn FnMut(&[f64]) -> f64,
) -> Vec<f64> {
    let specs: Vec<ParamSpec> = free.iter().map(|&i| effect.params()[i]).collect();
    let at: Vec<f64> = free.iter().map(|&i| params[i]).collect();
    let mut in_free = |y: &[f64]| {
        let mut x = params.to_vec();
        for (&i, &v) in free.iter().zip(y) {
            x[i] = v;
        }
        log_likelihood(&x)
    };
    let mut param_sd = vec![0.0; params.len()];
    for (&i, sd) in free
        .iter()
        .zip(standard_errors(&specs, &at, best, &mut in_free, 2e-3))
    {
        param_sd[i] = sd;
    }
    param_sd
}

/// Refits the effects of one sensor `chosen` (each fitted in turn on top of those before it
/// and of `base`, the effects named in other sensors that show in this one) jointly: every
/// parameter of `chosen` at once, from where the turns left them, `base` held. Each is then
/// scored against the others and `base`: its gain is what it adds to them.
pub(crate) fn refit_jointly(
    ctx: &Context<'_>,
    data: &SensorData,
    chosen: &[CandidateFit],
    base: &Hypothesis,
    max_fit_rows: usize,
) -> Vec<CandidateFit> {
    if chosen.len() < 2 {
        return chosen.to_vec();
    }
    let train = fit_rows(data, max_fit_rows);
    // Each effect's free parameters refitted, its held ones kept.
    let free: Vec<Vec<usize>> = chosen.iter().map(|c| c.effect.free(&c.params)).collect();
    let specs: Vec<ParamSpec> = chosen
        .iter()
        .zip(&free)
        .flat_map(|(c, f)| f.iter().map(|&i| c.effect.params()[i]))
        .collect();
    let start: Vec<f64> = chosen
        .iter()
        .zip(&free)
        .flat_map(|(c, f)| f.iter().map(|&i| c.params[i]))
        .collect();
    let split = |x: &[f64]| -> Vec<(Effect, Vec<f64>)> {
        let mut at = 0;
        chosen
            .iter()
            .zip(&free)
            .map(|(c, f)| {
                let mut params = c.params.clone();
                for &i in f {
                    params[i] = x[at];
                    at += 1;
                }
                (c.effect, params)
            })
            .collect()
    };
    let with = |effects: &[(Effect, Vec<f64>)]| -> Hypothesis {
        effects
            .iter()
            .fold(base.clone(), |h, (e, p)| h.and(*e, p.clone()))
    };
    let mut objective = |x: &[f64]| fit_ll(ctx, data, &with(&split(x)), &train);
    let (x, _) = refine(&specs, &start, 30 * specs.len(), &mut objective);
    let joint = split(&x);
    joint
        .iter()
        .map(|(effect, params)| {
            let others: Vec<(Effect, Vec<f64>)> =
                joint.iter().filter(|(e, _)| e != effect).cloned().collect();
            score(ctx, data, &with(&others), *effect, params.clone(), &train)
        })
        .collect()
}

/// Whether `effect` can be tried on these data at all.
pub(crate) fn applicable(effect: Effect, ctx: &Context<'_>, sensors: &[Sensor]) -> bool {
    if !sensors.contains(&effect.sensor()) {
        return false;
    }
    match effect {
        // A per-reading lidar already takes each reading at its own instant.
        Effect::LidarMotionSkew => ctx.physics.declared().lidar.is_some_and(|l| l.snapshot),
        // Fitted on the lidar's reads and losses, not on its ranges (`crate::dropout`).
        Effect::LidarDropout => false,
        _ => true,
    }
}
