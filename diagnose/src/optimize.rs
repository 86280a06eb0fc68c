//! Maximising a likelihood over an effect's parameters (one, two, or the mount's three): a
//! coarse grid over the searched box (the likelihood need not be concave there: a time
//! constant, a beam width), then a golden-section search (one parameter) or Nelder–Mead (n)
//! from the best grid point, in each parameter's own scale (logarithmic for ranges spanning
//! decades), clamped to the box. The uncertainty is the curvature at the maximum: the inverse
//! observed information.

use crate::catalogue::ParamSpec;

fn from_unit(spec: &ParamSpec, u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    if spec.log {
        (spec.lo.ln() + u * (spec.hi.ln() - spec.lo.ln())).exp()
    } else {
        spec.lo + u * (spec.hi - spec.lo)
    }
}

/// Nelder–Mead's evaluations after the grid: 60 for two parameters (what the one- and
/// two-parameter fits have always had), 30 more for each further one.
fn simplex_evals(n: usize) -> usize {
    60 + 30 * n.saturating_sub(2)
}

/// The maximum of `f` over the box of `specs`, with the value there, after at most about
/// the grid's points (the product of each parameter's) and [`simplex_evals`] evaluations.
pub(crate) fn maximize(specs: &[ParamSpec], f: &mut dyn FnMut(&[f64]) -> f64) -> (Vec<f64>, f64) {
    maximize_coarse_first(specs, f, None)
}

/// A function of the parameters to maximise.
pub(crate) type Objective<'f> = &'f mut dyn FnMut(&[f64]) -> f64;

/// Grid points whose coarse value is best, evaluated again in full: the start is the best of
/// them. A thinned share of the readings ranks the grid's far-apart points as the whole does
/// (their log-likelihoods differ by far more than the thinning's noise); the few best are
/// checked in full so that two close basins are not told apart by the thinned share alone.
const GRID_RECHECKED: usize = 3;

/// As [`maximize`], the coarse grid searched on `coarse` when given: a cheaper estimate of
/// `f` of the same shape (the log-likelihood of a thinned share of the same readings, whose
/// scale may differ). The [`GRID_RECHECKED`] best grid points are evaluated with `f`, and the
/// search goes on from the best of them with `f` alone.
pub(crate) fn maximize_coarse_first(
    specs: &[ParamSpec],
    f: &mut dyn FnMut(&[f64]) -> f64,
    mut coarse: Option<Objective<'_>>,
) -> (Vec<f64>, f64) {
    let in_box = |v: f64| if v.is_finite() { v } else { f64::NEG_INFINITY };
    let x_of =
        |u: &[f64]| -> Vec<f64> { specs.iter().zip(u).map(|(s, &u)| from_unit(s, u)).collect() };
    let mut eval = |u: &[f64]| -> f64 { in_box(f(&x_of(u))) };
    // The coarse grid.
    let dims: Vec<usize> = specs.iter().map(|s| s.grid.max(2)).collect();
    let total: usize = dims.iter().product();
    let grid_point = |index: usize| -> Vec<f64> {
        let mut rest = index;
        dims.iter()
            .map(|&d| {
                let i = rest % d;
                rest /= d;
                i as f64 / (d - 1) as f64
            })
            .collect()
    };
    // The grid points evaluated in full: every one, or the coarse estimate's best.
    let starts: Vec<usize> = match coarse.as_mut() {
        Some(coarse) => {
            let mut ranked: Vec<(f64, usize)> = (0..total)
                .map(|index| (in_box(coarse(&x_of(&grid_point(index)))), index))
                .collect();
            // Best first; ties in grid order, so the result does not depend on the sort.
            ranked.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            ranked
                .iter()
                .take(GRID_RECHECKED)
                .map(|&(_, index)| index)
                .collect()
        }
        None => (0..total).collect(),
    };
    let mut best_u = vec![0.5; specs.len()];
    let mut best_v = f64::NEG_INFINITY;
    for index in starts {
        let u = grid_point(index);
        let v = eval(&u);
        if v > best_v {
            best_v = v;
            best_u = u;
        }
    }
    let cell: Vec<f64> = dims.iter().map(|&d| 1.0 / (d - 1) as f64).collect();
    if specs.len() == 1 {
        // Golden section on the two grid cells around the best point.
        let (mut a, mut b) = (
            (best_u[0] - cell[0]).max(0.0),
            (best_u[0] + cell[0]).min(1.0),
        );
        let r = (5f64.sqrt() - 1.0) / 2.0;
        let mut c = b - r * (b - a);
        let mut d = a + r * (b - a);
        let (mut fc, mut fd) = (eval(&[c]), eval(&[d]));
        for _ in 0..30 {
            // 1e-4 of the searched range: far below any parameter's standard error.
            if (b - a) < 1e-4 {
                break;
            }
            if fc > fd {
                b = d;
                d = c;
                fd = fc;
                c = b - r * (b - a);
                fc = eval(&[c]);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + r * (b - a);
                fd = eval(&[d]);
            }
        }
        for (u, v) in [(c, fc), (d, fd)] {
            if v > best_v {
                best_v = v;
                best_u = vec![u];
            }
        }
    } else {
        let (u, v) = simplex_search(&mut eval, &best_u, &cell);
        if v > best_v {
            best_v = v;
            best_u = u;
        }
    }
    let x = specs
        .iter()
        .zip(&best_u)
        .map(|(s, &u)| from_unit(s, u))
        .collect();
    (x, best_v)
}

/// As [`maximize`], searching `shapes` one at a time first: each a set of the parameters left
/// free (indices into `specs`), the others held at `held`; then, with several and `together`,
/// refining the shapes' parameters and `also_refined` together from the best shape's maximum.
/// No shape is [`maximize`] over all; one (or several not `together`) is the best shape's
/// maximum with the rest held. Each shape's grid is searched on `coarse` when given
/// ([`maximize_coarse_first`]).
pub(crate) fn maximize_shapes(
    specs: &[ParamSpec],
    shapes: &[&[usize]],
    together: bool,
    also_refined: &[usize],
    held: &[f64],
    f: &mut dyn FnMut(&[f64]) -> f64,
    mut coarse: Option<Objective<'_>>,
) -> (Vec<f64>, f64) {
    if shapes.is_empty() {
        return maximize_coarse_first(specs, f, coarse);
    }
    let mut best = (held.to_vec(), f64::NEG_INFINITY);
    for shape in shapes {
        let free: Vec<ParamSpec> = shape.iter().map(|&i| specs[i]).collect();
        let full = |y: &[f64]| {
            let mut x = held.to_vec();
            for (&i, &v) in shape.iter().zip(y) {
                x[i] = v;
            }
            x
        };
        let mut coarse_in_shape = coarse.as_mut().map(|c| move |y: &[f64]| c(&full(y)));
        let (y, v) = maximize_coarse_first(
            &free,
            &mut |y: &[f64]| f(&full(y)),
            coarse_in_shape.as_mut().map(|c| c as Objective<'_>),
        );
        if v > best.1 {
            best = (full(&y), v);
        }
    }
    if shapes.len() == 1 || !together {
        return best;
    }
    let mut refined: Vec<usize> = shapes
        .iter()
        .flat_map(|shape| shape.iter())
        .chain(also_refined)
        .copied()
        .filter(|&i| i < specs.len())
        .collect();
    refined.sort_unstable();
    refined.dedup();
    let refined_specs: Vec<ParamSpec> = refined.iter().map(|&i| specs[i]).collect();
    let start: Vec<f64> = refined.iter().map(|&i| best.0[i]).collect();
    let from = best.0.clone();
    let full = |y: &[f64]| {
        let mut x = from.clone();
        for (&i, &v) in refined.iter().zip(y) {
            x[i] = v;
        }
        x
    };
    let (y, v) = refine(
        &refined_specs,
        &start,
        simplex_evals(refined.len()),
        &mut |y: &[f64]| f(&full(y)),
    );
    if v > best.1 {
        (full(&y), v)
    } else {
        best
    }
}

fn to_unit(spec: &ParamSpec, x: f64) -> f64 {
    let u = if spec.log {
        (x.max(spec.lo).ln() - spec.lo.ln()) / (spec.hi.ln() - spec.lo.ln())
    } else {
        (x - spec.lo) / (spec.hi - spec.lo)
    };
    u.clamp(0.0, 1.0)
}

/// A local maximum of `f` near `start` (within the box of `specs`), with the value there:
/// Nelder–Mead from `start` with steps of half a grid cell, at most `max_evals` evaluations.
/// For a joint refit of parameters each already fitted on its own.
pub(crate) fn refine(
    specs: &[ParamSpec],
    start: &[f64],
    max_evals: usize,
    f: &mut dyn FnMut(&[f64]) -> f64,
) -> (Vec<f64>, f64) {
    let mut eval = |u: &[f64]| -> f64 {
        let x: Vec<f64> = specs.iter().zip(u).map(|(s, &u)| from_unit(s, u)).collect();
        let v = f(&x);
        if v.is_finite() {
            v
        } else {
            f64::NEG_INFINITY
        }
    };
    let u0: Vec<f64> = specs
        .iter()
        .zip(start)
        .map(|(s, &x)| to_unit(s, x))
        .collect();
    let step: Vec<f64> = specs
        .iter()
        .map(|s| 0.5 / (s.grid.max(2) - 1) as f64)
        .collect();
    let (u, v, _) = nelder_mead(&mut eval, &u0, &step, max_evals);
    let x = specs
        .iter()
        .zip(&u)
        .map(|(s, &u)| from_unit(s, u))
        .collect();
    (x, v)
}

/// Nelder–Mead from `start` with steps `step`, and again from where it got with steps a
/// tenth as large while it has not converged, at most three times: a likelihood far sharper
/// than the grid (a wheel's radius to 1e-5 from a cell of 0.05) can use up the simplex's
/// budget before it shrinks that far. A converged search is left as it was.
fn simplex_search(
    f: &mut dyn FnMut(&[f64]) -> f64,
    start: &[f64],
    step: &[f64],
) -> (Vec<f64>, f64) {
    let budget = simplex_evals(start.len());
    let (mut u, mut v, mut converged) = nelder_mead(f, start, step, budget);
    let mut step = step.to_vec();
    for _ in 0..3 {
        if converged {
            break;
        }
        step.iter_mut().for_each(|s| *s /= 10.0);
        (u, v, converged) = nelder_mead(f, &u, &step, budget);
    }
    (u, v)
}

/// Nelder–Mead maximisation in the unit box from `start` with initial steps `step`: the best
/// point, its value, and whether the simplex converged (else the budget ran out).
fn nelder_mead(
    f: &mut dyn FnMut(&[f64]) -> f64,
    start: &[f64],
    step: &[f64],
    max_evals: usize,
) -> (Vec<f64>, f64, bool) {
    let n = start.len();
    let clamp = |x: Vec<f64>| x.into_iter().map(|v| v.clamp(0.0, 1.0)).collect::<Vec<_>>();
    let mut simplex: Vec<(Vec<f64>, f64)> = Vec::with_capacity(n + 1);
    simplex.push((start.to_vec(), f(start)));
    for i in 0..n {
        let mut x = start.to_vec();
        x[i] = if x[i] + step[i] <= 1.0 {
            x[i] + step[i]
        } else {
            x[i] - step[i]
        };
        let x = clamp(x);
        let v = f(&x);
        simplex.push((x, v));
    }
    let mut evals = n + 1;
    let mut converged = false;
    while evals < max_evals {
        simplex.sort_by(|a, b| b.1.total_cmp(&a.1));
        // Converged when the simplex spans less than 0.01 nats or 1e-4 of the box.
        let spread = simplex[0].1 - simplex[n].1;
        let size = (0..n)
            .map(|j| {
                let (lo, hi) = simplex.iter().fold((1.0f64, 0.0f64), |(lo, hi), (x, _)| {
                    (lo.min(x[j]), hi.max(x[j]))
                });
                hi - lo
            })
            .fold(0.0, f64::max);
        if spread.abs() < 1e-2 || size < 1e-4 {
            converged = true;
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|j| simplex[..n].iter().map(|(x, _)| x[j]).sum::<f64>() / n as f64)
            .collect();
        let worst = simplex[n].clone();
        let along = |t: f64| -> Vec<f64> {
            clamp(
                centroid
                    .iter()
                    .zip(&worst.0)
                    .map(|(c, w)| c + t * (c - w))
                    .collect(),
            )
        };
        let xr = along(1.0);
        let fr = f(&xr);
        evals += 1;
        if fr > simplex[0].1 {
            let xe = along(2.0);
            let fe = f(&xe);
            evals += 1;
            simplex[n] = if fe > fr { (xe, fe) } else { (xr, fr) };
        } else if fr > simplex[n - 1].1 {
            simplex[n] = (xr, fr);
        } else {
            let xc = along(-0.5);
            let fc = f(&xc);
            evals += 1;
            if fc > worst.1 {
                simplex[n] = (xc, fc);
            } else {
                // Shrink towards the best.
                let best = simplex[0].0.clone();
                for item in simplex.iter_mut().skip(1) {
                    let x: Vec<f64> = item
                        .0
                        .iter()
                        .zip(&best)
                        .map(|(x, b)| b + 0.5 * (x - b))
                        .collect();
                    let v = f(&x);
                    *item = (x, v);
                    evals += 1;
                }
            }
        }
    }
    simplex.sort_by(|a, b| b.1.total_cmp(&a.1));
    let (x, v) = simplex.swap_remove(0);
    (x, v, converged)
}

/// Standard errors of the maximiser `x` of the log-likelihood `f`: the square roots of the
/// diagonal of the inverse of minus its Hessian (finite differences, steps of `rel` of each
/// parameter's searched range). `NaN` where the curvature is not that of a maximum.
pub(crate) fn standard_errors(
    specs: &[ParamSpec],
    x: &[f64],
    fx: f64,
    f: &mut dyn FnMut(&[f64]) -> f64,
    rel: f64,
) -> Vec<f64> {
    let n = x.len();
    let h: Vec<f64> = specs
        .iter()
        .zip(x)
        .map(|(s, &v)| {
            let span = if s.log {
                v.abs().max(s.lo) * ((s.hi / s.lo).ln())
            } else {
                s.hi - s.lo
            };
            (span * rel).max(1e-12)
        })
        .collect();
    let at = |f: &mut dyn FnMut(&[f64]) -> f64, d: &[(usize, f64)]| {
        let mut y = x.to_vec();
        for &(i, s) in d {
            y[i] += s;
        }
        f(&y)
    };
    let mut hess = vec![vec![0.0; n]; n];
    for i in 0..n {
        let up = at(f, &[(i, h[i])]);
        let down = at(f, &[(i, -h[i])]);
        hess[i][i] = (up - 2.0 * fx + down) / (h[i] * h[i]);
        for j in 0..i {
            let pp = at(f, &[(i, h[i]), (j, h[j])]);
            let pm = at(f, &[(i, h[i]), (j, -h[j])]);
            let mp = at(f, &[(i, -h[i]), (j, h[j])]);
            let mm = at(f, &[(i, -h[i]), (j, -h[j])]);
            let v = (pp - pm - mp + mm) / (4.0 * h[i] * h[j]);
            hess[i][j] = v;
            hess[j][i] = v;
        }
    }
    // Invert −H (1×1 and 2×2 in closed form, as they always were; larger by Cholesky).
    match n {
        1 => {
            let a = -hess[0][0];
            vec![if a > 0.0 { (1.0 / a).sqrt() } else { f64::NAN }]
        }
        2 => {
            let (a, b, d) = (-hess[0][0], -hess[0][1], -hess[1][1]);
            let det = a * d - b * b;
            if a > 0.0 && det > 0.0 {
                vec![(d / det).sqrt(), (a / det).sqrt()]
            } else {
                vec![f64::NAN; 2]
            }
        }
        _ => {
            let minus: Vec<Vec<f64>> = hess
                .iter()
                .map(|row| row.iter().map(|v| -v).collect())
                .collect();
            inverse_diagonal(&minus).map_or_else(
                || vec![f64::NAN; n],
                |d| d.into_iter().map(f64::sqrt).collect(),
            )
        }
    }
}

/// The diagonal of the inverse of the symmetric matrix `a`, `None` unless it is positive
/// definite (Cholesky).
fn inverse_diagonal(a: &[Vec<f64>]) -> Option<Vec<f64>> {
    let n = a.len();
    let m = nalgebra::DMatrix::from_fn(n, n, |i, j| a[i][j]);
    let inverse = m.cholesky()?.inverse();
    Some((0..n).map(|i| inverse[(i, i)]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(lo: f64, hi: f64, log: bool) -> ParamSpec {
        ParamSpec {
            name: "x",
            unit: "",
            lo,
            hi,
            log,
            grid: 11,
            self_test: crate::SelfTestRange::uniform(lo, hi),
            limits: crate::catalogue::SearchLimits::Both,
        }
    }

    #[test]
    fn finds_the_maximum_of_a_quadratic_and_its_curvature() {
        let specs = [spec(-1.0, 1.0, false)];
        // ln L = −(x − 0.3)² / (2 · 0.05²): the maximiser 0.3, standard error 0.05.
        let mut f = |x: &[f64]| -(x[0] - 0.3).powi(2) / (2.0 * 0.0025);
        let (x, v) = maximize(&specs, &mut f);
        // The search stops within 1e-4 of the range (2e-4 here) of the maximum.
        assert!((x[0] - 0.3).abs() < 2e-4, "{x:?}");
        // A quadratic's curvature is the same everywhere: exact from any point.
        let se = standard_errors(&specs, &x, v, &mut f, 1e-3);
        assert!((se[0] - 0.05).abs() < 1e-6, "{se:?}");
    }

    /// Two shapes, each one term with a shared scale: the maximum lies in one shape's plane
    /// (the other term zero), found there and kept by the joint refinement; one shape alone
    /// holds the parameter it leaves out.
    #[test]
    fn shapes_are_searched_one_at_a_time_then_together() {
        let specs = [
            spec(-0.05, 0.05, false),
            spec(1.0, 1000.0, true),
            spec(-0.1, 0.1, false),
        ];
        let m = [0.0, 12.8, 0.031];
        let mut f = |x: &[f64]| {
            -((x[0] - m[0]) / 1e-3).powi(2)
                - ((x[1].ln() - m[1].ln()) / 0.05).powi(2)
                - ((x[2] - m[2]) / 1e-3).powi(2)
        };
        let held = [0.0, 10.0, 0.0];
        let (x, _) = maximize_shapes(&specs, &[&[0, 1], &[2, 1]], true, &[], &held, &mut f, None);
        assert!((x[0] - m[0]).abs() < 2e-4, "{x:?}");
        assert!((x[1] / m[1] - 1.0).abs() < 0.02, "{x:?}");
        assert!((x[2] - m[2]).abs() < 2e-4, "{x:?}");
        let (x, _) = maximize_shapes(&specs, &[&[0, 1]], true, &[], &held, &mut f, None);
        assert_eq!(x[2], 0.0, "{x:?}");
    }

    /// A parameter of no shape (a warm-up's stretch) stays held at its value unless the joint
    /// refinement is told to free it too; freed, it is found from there.
    #[test]
    fn a_parameter_of_no_shape_is_freed_only_in_the_refinement_it_is_given_to() {
        let specs = [
            spec(-0.05, 0.05, false),
            spec(1.0, 1000.0, true),
            spec(-0.1, 0.1, false),
            spec(0.35, 2.83, true),
        ];
        let m = [0.0, 12.8, 0.031, 1.6];
        let mut f = |x: &[f64]| {
            -((x[0] - m[0]) / 1e-3).powi(2)
                - ((x[1].ln() - m[1].ln()) / 0.05).powi(2)
                - ((x[2] - m[2]) / 1e-3).powi(2)
                - ((x[3].ln() - m[3].ln()) / 0.05).powi(2)
        };
        let held = [0.0, 10.0, 0.0, 1.0];
        let shapes: &[&[usize]] = &[&[0, 1], &[2, 1]];
        let (x, _) = maximize_shapes(&specs, shapes, true, &[], &held, &mut f, None);
        assert_eq!(x[3], 1.0, "{x:?}");
        let (x, _) = maximize_shapes(&specs, shapes, true, &[3], &held, &mut f, None);
        assert!((x[3] / m[3] - 1.0).abs() < 0.02, "{x:?}");
        assert!((x[2] - m[2]).abs() < 2e-4, "{x:?}");
    }

    #[test]
    fn three_parameters_and_their_correlated_errors() {
        let specs = [
            spec(-8.0, 8.0, false),
            spec(-0.1, 0.1, false),
            spec(-0.1, 0.1, false),
        ];
        // ln L = −½ (x − m)ᵀ A (x − m) with A correlating the first two: the maximiser m,
        // the standard errors the square roots of diag(A⁻¹).
        let m = [1.7, -0.02, 0.03];
        let a = [
            [4.0, 100.0, 0.0],
            [100.0, 10_000.0, 0.0],
            [0.0, 0.0, 40_000.0],
        ];
        let mut f = |x: &[f64]| {
            let d: Vec<f64> = x.iter().zip(&m).map(|(x, m)| x - m).collect();
            let mut q = 0.0;
            for i in 0..3 {
                for j in 0..3 {
                    q += d[i] * a[i][j] * d[j];
                }
            }
            -0.5 * q
        };
        let (x, v) = maximize(&specs, &mut f);
        // Within a tenth of each one's standard error (0.707, 0.0141, 0.005).
        assert!((x[0] - m[0]).abs() < 0.07, "{x:?}");
        assert!((x[1] - m[1]).abs() < 0.0015, "{x:?}");
        assert!((x[2] - m[2]).abs() < 0.0005, "{x:?}");
        let se = standard_errors(&specs, &m, 0.0, &mut f, 1e-3);
        // A⁻¹'s diagonal: det of the 2×2 block is 30,000: 10,000/30,000 and 4/30,000.
        let want = [(1.0f64 / 3.0).sqrt(), (4.0f64 / 30_000.0).sqrt(), 0.005];
        for (s, w) in se.iter().zip(want) {
            assert!((s / w - 1.0).abs() < 1e-4, "{se:?}");
        }
        let _ = v;
    }

    /// A coarse estimate of another scale, whose grid ranking puts a false peak first, still
    /// leads to the true maximum: the best grid points are checked in full. The likelihood is
    /// flat far from its peak, so a search started at the false peak would stay there.
    #[test]
    fn a_coarse_grid_starts_the_search_from_the_full_likelihood() {
        let specs = [spec(-1.0, 1.0, false), spec(-1.0, 1.0, false)];
        let bump = |x: &[f64]| {
            let r2 = (x[0] - 0.31).powi(2) + (x[1] + 0.42).powi(2);
            100.0 * (-r2 / (2.0 * 0.1f64.powi(2))).exp()
        };
        // A quarter of the readings: a quarter of the log-likelihood, and a spurious peak at
        // the grid point (0.8, 0.8) that the whole does not have.
        let mut coarse = |x: &[f64]| {
            let at = (x[0] - 0.8).abs() < 1e-9 && (x[1] - 0.8).abs() < 1e-9;
            0.25 * bump(x) + if at { 1e6 } else { 0.0 }
        };
        let mut calls = 0;
        let mut full = |x: &[f64]| {
            calls += 1;
            bump(x)
        };
        let (x, _) = maximize_coarse_first(&specs, &mut full, Some(&mut coarse));
        // The simplex stops within 0.01 nats of the peak's 100: 0.1 · √(2 · 0.01/100) = 0.0014.
        assert!(
            (x[0] - 0.31).abs() < 0.002 && (x[1] + 0.42).abs() < 0.002,
            "{x:?}"
        );
        // The full likelihood saw only the rechecked points and the simplex, not the grid's 121.
        assert!(calls < 121, "{calls}");
    }

    #[test]
    fn two_parameters_on_a_log_scale() {
        let specs = [spec(-0.05, 0.05, false), spec(1.0, 1000.0, true)];
        let mut f =
            |x: &[f64]| -((x[0] - 0.01) / 0.001).powi(2) - ((x[1].ln() - 20f64.ln()) / 0.1).powi(2);
        let (x, _) = maximize(&specs, &mut f);
        assert!((x[0] - 0.01).abs() < 1e-4, "{x:?}");
        assert!((x[1] / 20.0 - 1.0).abs() < 0.01, "{x:?}");
    }
}
