//! `lidar_dropout`: readings missing where the world says the unit would read. Fitted by
//! maximum likelihood on the lidar's reads and losses ([`crate::residuals::DropoutRows`]), a
//! Bernoulli likelihood: a reading is lost with chance `p₀ + (1 − p₀) q`, `q` the catalogue's
//! loss by returned power (`hilsim_lidar_emulator::effects::dropout_probability`: by range,
//! incidence and reflectivity) and `p₀` the share lost at random whatever the geometry (a unit's
//! occasional invalid reading), profiled out. Its absence is the loss at random alone, `p₀` the
//! training half's share lost. It moves no reading and no path: the ranges' residuals, which
//! keep the valid readings only, are the same with it or without it.

use hilsim_lidar_emulator::effects::{dropout_probability_of, ReturnLogs};
use hilsim_sim::scenario::LidarDropout;

use crate::catalogue::{Effect, Sensor, REFERENCE_REFLECTIVITY};
use crate::explain::CandidateFit;
use crate::optimize::{maximize, standard_errors};
use crate::outcome::Options;
use crate::residuals::{Context, DropoutRows};

/// A chance kept this far from 0 and 1, so that one reading the model calls impossible costs
/// 21 nats rather than an infinite log-likelihood.
const CHANCE_GUARD: f64 = 1e-9;
/// Bisection steps of the profiled `p₀` (2⁻⁴⁰ of its range).
const PROFILE_STEPS: usize = 40;
/// The share of the held-out rows the dropout's size is measured over: the tenth it loses most.
const SIZE_SHARE: f64 = 0.1;

/// The logarithms of each of `rows`' `idx` returns, taken once for a fit that weighs them under
/// many dropouts.
fn return_logs(rows: &DropoutRows, idx: &[usize]) -> Vec<ReturnLogs> {
    idx.iter()
        .map(|&i| ReturnLogs::new(rows.range_m[i], rows.cos_incidence[i], rows.reflectivity[i]))
        .collect()
}

/// The catalogue's loss by power at each of `returns` under `params` (d½, s, m; m 1, a diffuse
/// surface's, when not given).
fn power_loss(returns: &[ReturnLogs], params: &[f64]) -> Vec<f64> {
    let dropout = LidarDropout {
        half_loss_range_m: params.first().copied().unwrap_or(f64::NAN),
        log_power_spread: params.get(1).copied().unwrap_or(f64::NAN),
        reference: REFERENCE_REFLECTIVITY,
        incidence_power: params.get(2).copied().unwrap_or(1.0),
    };
    returns
        .iter()
        .map(|r| dropout_probability_of(&dropout, r))
        .collect()
}

/// The Bernoulli log-likelihood of `lost` under the chances `p₀ + (1 − p₀) q`.
fn log_likelihood(lost: &[bool], q: &[f64], p0: f64) -> f64 {
    lost.iter()
        .zip(q)
        .map(|(&l, &q)| {
            let p = (p0 + (1.0 - p0) * q).clamp(CHANCE_GUARD, 1.0 - CHANCE_GUARD);
            if l {
                p.ln()
            } else {
                (1.0 - p).ln()
            }
        })
        .sum()
}

/// The `p₀` of the greatest likelihood given `q`: the log-likelihood is concave in `p₀` (a sum
/// of logarithms of affine functions), so its derivative's root is found by bisection.
fn profiled_p0(lost: &[bool], q: &[f64]) -> f64 {
    // A reading kept adds `−1 / (1 − p₀)` whatever its `q`: those are counted once, and only
    // the losses' terms summed at each step.
    let lost_q: Vec<f64> = lost
        .iter()
        .zip(q)
        .filter(|(l, _)| **l)
        .map(|(_, &q)| q)
        .collect();
    let kept = (lost.len() - lost_q.len()) as f64;
    let slope = |p0: f64| -> f64 {
        lost_q
            .iter()
            .map(|&q| (1.0 - q) / (p0 + (1.0 - p0) * q).max(CHANCE_GUARD))
            .sum::<f64>()
            - kept / (1.0 - p0).max(CHANCE_GUARD)
    };
    let (mut lo, mut hi) = (0.0, 1.0 - CHANCE_GUARD);
    if slope(lo) <= 0.0 {
        return 0.0;
    }
    for _ in 0..PROFILE_STEPS {
        let mid = 0.5 * (lo + hi);
        if slope(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The share of `lost` that is true.
fn share(lost: &[bool]) -> f64 {
    lost.iter().filter(|l| **l).count() as f64 / lost.len().max(1) as f64
}

/// The root mean square of `lost − p` (the Brier score's root).
fn brier_rms(lost: &[bool], p: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = lost.iter().zip(p).fold((0.0, 0usize), |(s, n), (&l, p)| {
        (s + (f64::from(u8::from(l)) - p).powi(2), n + 1)
    });
    (sum / n.max(1) as f64).sqrt()
}

/// How much more the losses vary between revolutions than independent readings would: the sum
/// over revolutions of the squared excess of losses (lost less its chance, summed in the
/// revolution) over the binomial variance those sums would have, at least 1. Losses cluster (a
/// dark wall or a pane of glass loses every beam that meets it in a revolution, and again in
/// the next), so the readings are fewer independent trials than they look; the standard errors
/// are scaled by its root, the quasi-likelihood dispersion of a binomial model with clustered
/// trials (McCullagh and Nelder, *Generalized Linear Models*, 2nd ed., sec. 4.5). `revolution`
/// is each reading's, in the order of `lost` and `p`, with each revolution's readings together.
fn dispersion(lost: &[bool], p: &[f64], revolution: &[u64]) -> f64 {
    let (mut excess, mut variance) = (0.0, 0.0);
    let mut k = 0;
    while k < lost.len() {
        let (mut sum, mut var) = (0.0, 0.0);
        let rev = revolution[k];
        while k < lost.len() && revolution[k] == rev {
            sum += f64::from(u8::from(lost[k])) - p[k];
            var += p[k] * (1.0 - p[k]);
            k += 1;
        }
        excess += sum * sum;
        variance += var;
    }
    if variance > 0.0 {
        (excess / variance).max(1.0)
    } else {
        1.0
    }
}

/// The lidar's dropout fitted on the training half of `rows` and scored on the held-out half
/// against the loss at random; `None` when a half has no rows.
pub(crate) fn fit(rows: &DropoutRows) -> Option<CandidateFit> {
    let (train, held): (Vec<usize>, Vec<usize>) =
        (0..rows.lost.len()).partition(|&i| !rows.heldout[i]);
    if train.is_empty() || held.is_empty() {
        return None;
    }
    let lost = |idx: &[usize]| idx.iter().map(|&i| rows.lost[i]).collect::<Vec<bool>>();
    let (train_lost, held_lost) = (lost(&train), lost(&held));
    // At random: the training half's share, at least half a reading's (a held-out loss is then
    // unlikely, not impossible).
    let base_p = share(&train_lost).max(0.5 / train.len() as f64);
    let zeros = |n: usize| vec![0.0; n];
    let base_train = log_likelihood(&train_lost, &zeros(train.len()), base_p);
    let base_held = log_likelihood(&held_lost, &zeros(held.len()), base_p);
    let specs = Effect::LidarDropout.params();
    let (train_returns, held_returns) = (return_logs(rows, &train), return_logs(rows, &held));
    let mut train_ll = |x: &[f64]| {
        let q = power_loss(&train_returns, x);
        log_likelihood(&train_lost, &q, profiled_p0(&train_lost, &q))
    };
    let (params, best) = maximize(specs, &mut train_ll);
    let q_train = power_loss(&train_returns, &params);
    let p0 = profiled_p0(&train_lost, &q_train);
    let p_train: Vec<f64> = q_train.iter().map(|q| p0 + (1.0 - p0) * q).collect();
    let spread = dispersion(
        &train_lost,
        &p_train,
        &train
            .iter()
            .map(|&i| rows.revolution[i])
            .collect::<Vec<_>>(),
    );
    let param_sd: Vec<f64> = standard_errors(specs, &params, best, &mut train_ll, 0.01)
        .into_iter()
        .map(|sd| sd * spread.sqrt())
        .collect();
    let q_held = power_loss(&held_returns, &params);
    let p_held: Vec<f64> = q_held.iter().map(|q| p0 + (1.0 - p0) * q).collect();
    let held_ll = log_likelihood(&held_lost, &q_held, p0);
    let train_gain = best - base_train;
    let n = held.len();
    let rmse_before = brier_rms(&held_lost, std::iter::repeat(base_p));
    let rmse_after = brier_rms(&held_lost, p_held.iter().copied());
    let noise_floor = (p_held.iter().map(|p| p * (1.0 - p)).sum::<f64>() / n as f64).sqrt();
    let mut most = p_held.clone();
    most.sort_by(|a, b| b.total_cmp(a));
    let top = ((n as f64 * SIZE_SHARE).ceil() as usize).clamp(1, n);
    let size = most[..top].iter().sum::<f64>() / top as f64 - base_p;
    Some(CandidateFit {
        effect: Effect::LidarDropout,
        sensor: Sensor::Lidar,
        params,
        param_sd,
        train_gain,
        heldout_gain: held_ll - base_held,
        bic_gain: 2.0 * train_gain - specs.len() as f64 * (train.len() as f64).ln(),
        rmse_before,
        rmse_after,
        noise_floor,
        heldout_n: n,
        rmse_over: crate::explain::RmseOver::Readings,
        heldout_ll_per_reading: held_ll / n as f64,
        size_m: size,
        size_noise_m: f64::NAN,
        floor_multiple: f64::NAN,
        scaled_rmse: (rmse_before / noise_floor, rmse_after / noise_floor),
        seen_until_s: 0.0,
    })
}

/// Whether the dropout fit `c` earns its place: it gains more than [`Options::min_gain`] on the
/// held-out half and by BIC on the training half, loses half the returns nearer than the search's
/// far end (`Effect::departs`) by more than [`HALF_LOSS_WITHIN_SD`] of its standard errors,
/// and loses at least [`Options::dropout_min_share`] more of the tenth of the readings it loses
/// most than are lost at random.
pub(crate) fn earns_place(c: &CandidateFit, options: &Options) -> bool {
    c.heldout_gain > options.min_gain
        && c.bic_gain > 0.0
        && c.effect.departs(&c.params, 0.0)
        && half_loss_beyond_its_error(c)
        && c.size_m >= options.dropout_min_share
}

/// Standard errors by which a dropout's half-loss range must be nearer than the search's far
/// end: a long-range unit's fit at 38 ± 11 m (a map built beside a turned lidar loses a few far
/// readings it should not) is the far end within its error, one at 28 ± 1.6 m is not.
const HALF_LOSS_WITHIN_SD: f64 = 2.0;

/// Whether `c`'s half-loss range is nearer than its absence by more than
/// [`HALF_LOSS_WITHIN_SD`] standard errors (a standard error that cannot be had is not).
fn half_loss_beyond_its_error(c: &CandidateFit) -> bool {
    let absent = c.effect.absent(0.0)[0];
    match (c.params.first(), c.param_sd.first()) {
        (Some(&half_loss_m), Some(&sd)) => absent - half_loss_m > HALF_LOSS_WITHIN_SD * sd,
        _ => false,
    }
}

/// The dropout fitted on the lidar's reads and losses along `ctx`'s trajectory, when it is
/// tried.
pub(crate) fn fitted(ctx: &Context<'_>, options: &Options) -> Option<CandidateFit> {
    if !options.effects.contains(&Effect::LidarDropout) {
        return None;
    }
    fit(&crate::residuals::dropout_rows(ctx)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_lidar_emulator::effects::dropout_probability;

    /// Uniform numbers in [0, 1) from xorshift64* seeded with `state`: a fixed stream for a
    /// fixed test.
    fn uniform_stream(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Rows at ranges 0.5–6 m at incidences up to 73°, each lost with the loss by power at
    /// (4 m, 0.3, `incidence_power`) on top of 1 % lost at random, drawn from a fixed stream.
    fn rows(n: usize, incidence_power: f64) -> DropoutRows {
        let truth = LidarDropout {
            half_loss_range_m: 4.0,
            log_power_spread: 0.3,
            reference: REFERENCE_REFLECTIVITY,
            incidence_power,
        };
        let mut unit = uniform_stream(0x9e37_79b9_7f4a_7c15);
        let mut r = DropoutRows::default();
        for i in 0..n {
            let d = 0.5 + 5.5 * (i as f64 + 0.5) / n as f64;
            let cos = 0.3 + 0.7 * unit();
            let p = 0.01 + 0.99 * dropout_probability(&truth, d, cos, 0.55);
            r.range_m.push(d);
            r.cos_incidence.push(cos);
            r.reflectivity.push(0.55);
            r.lost.push(unit() < p);
            r.heldout.push(i % 2 == 1);
            r.revolution.push((i / 100) as u64);
        }
        r
    }

    /// The profiled share lost at random is the likelihood's greatest over `p₀`: against a
    /// search every 10⁻⁴ of it, the likelihood at the profile is not lower.
    #[test]
    fn the_profiled_share_lost_at_random_is_the_likeliest() {
        let q: Vec<f64> = (0..1000).map(|i| f64::from(i % 10) * 0.05).collect();
        let lost: Vec<bool> = (0..1000).map(|i| i % 7 == 0 || i % 10 == 9).collect();
        let p0 = profiled_p0(&lost, &q);
        let best = (0..10_000)
            .map(|k| f64::from(k) * 1e-4)
            .map(|p| log_likelihood(&lost, &q, p))
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(p0 > 0.0 && p0 < 0.5, "{p0}");
        assert!(log_likelihood(&lost, &q, p0) >= best - 1e-9);
        // Nothing lost beyond what `q` explains: none at random.
        assert_eq!(profiled_p0(&[false; 4], &[0.5; 4]), 0.0);
    }

    /// Losses drawn one by one spread as a binomial's (dispersion near 1); losses of whole
    /// revolutions (a wall lost at once) spread as many times more as a revolution has readings.
    #[test]
    fn losses_clustered_by_revolution_widen_the_errors_and_independent_ones_do_not() {
        let (revs, per) = (400_usize, 50_usize);
        let mut unit = uniform_stream(0x2545_f491_4f6c_dd1d);
        let revolution: Vec<u64> = (0..revs * per).map(|i| (i / per) as u64).collect();
        let p = vec![0.3; revs * per];
        let independent: Vec<bool> = (0..revs * per).map(|_| unit() < 0.3).collect();
        let whole: Vec<bool> = (0..revs)
            .flat_map(|_| std::iter::repeat_n(unit() < 0.3, per))
            .collect();
        // Over 400 revolutions the estimate's relative spread is about √(2/400) = 7 %: 1.3 is
        // over four of them.
        let one_by_one = dispersion(&independent, &p, &revolution);
        assert!(one_by_one < 1.3, "{one_by_one}");
        // Whole revolutions: 50 readings' worth of variance in each sum (within 30 %).
        let clustered = dispersion(&whole, &p, &revolution);
        assert!((35.0..65.0).contains(&clustered), "{clustered}");
    }

    /// 20,000 rows: the half-loss range within 3 % and the spread within 15 % (several of
    /// their standard errors), named; rows lost at random alone name nothing.
    #[test]
    fn the_loss_by_power_is_recovered_and_loss_at_random_is_not_named() {
        let fit = fit(&rows(20_000, 1.0)).expect("a fit");
        let [d, s] = [fit.params[0], fit.params[1]];
        assert!(
            (d - 4.0).abs() < 0.12,
            "{:?} ± {:?}",
            fit.params,
            fit.param_sd
        );
        assert!(
            (s - 0.3).abs() < 0.045,
            "{:?} ± {:?}",
            fit.params,
            fit.param_sd
        );
        assert!(earns_place(&fit, &Options::default()), "{fit:?}");
        // The same loss read at 38 ± 11 m: the search's far end within two standard errors.
        let vague = CandidateFit {
            params: vec![38.0, s],
            param_sd: vec![11.0, fit.param_sd[1]],
            ..fit.clone()
        };
        assert!(!earns_place(&vague, &Options::default()), "{vague:?}");
        assert!(fit.rmse_after < fit.rmse_before);
        let mut random = rows(20_000, 1.0);
        for (i, l) in random.lost.iter_mut().enumerate() {
            *l = i % 97 == 0;
        }
        let fit = super::fit(&random).expect("a fit");
        assert!(!earns_place(&fit, &Options::default()), "{fit:?}");
    }

    /// A unit that loses its returns by the range alone, whatever the incidence: its incidence
    /// power is fitted near 0 (within 0.15, several standard errors) and its half-loss range
    /// within 3 %.
    #[test]
    fn a_loss_by_the_range_alone_is_fitted_with_no_power_of_the_incidence() {
        let rows = rows(20_000, 0.0);
        let fit = fit(&rows).expect("a fit");
        let [d, _, m] = [fit.params[0], fit.params[1], fit.params[2]];
        assert!(m.abs() < 0.15, "{:?} ± {:?}", fit.params, fit.param_sd);
        assert!(
            (d - 4.0).abs() < 0.12,
            "{:?} ± {:?}",
            fit.params,
            fit.param_sd
        );
        assert!(earns_place(&fit, &Options::default()), "{fit:?}");
    }
}
