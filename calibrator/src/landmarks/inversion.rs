//! Turning a raw reading back into a distance: the inverse of the fitted mean reading
//! f(d) = Σ αᵢ dⁱ, the paper's phase #3, eq. (30): d̂ = argmin over d ≥ 0 of (f(d) − d̃)².
//!
//! Orders 1 and 2 have closed forms (for order 2 the root on the increasing branch,
//! f′(d) = √disc ≥ 0, written so that it stays exact as α₂ → 0). Beyond, the polynomial is
//! searched for a root on an increasing stretch of the search interval (grid bracketing, then
//! bisection), the one nearest the straight-line inverse when several exist; a reading outside
//! f's range there gets eq. (30)'s minimiser of |f(d) − d̃|.

use super::regression::{horner, horner_derivative};
use crate::CalibrationError;

/// The inverse of a fitted range model.
///
/// ```
/// use hilsim_calibrator::landmarks::Inverse;
/// let inv = Inverse::new(&[0.0525, 0.8838, 0.0584], [0.0, 7.5]).unwrap();
/// let reading = 0.0525 + 0.8838 * 2.0 + 0.0584 * 4.0;
/// assert!((inv.distance(reading) - 2.0).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Inverse {
    alpha: Vec<f64>,
    lo: f64,
    hi: f64,
}

/// Grid intervals searched for sign changes at orders above 2.
const GRID: usize = 256;

impl Inverse {
    /// The inverse of f(d) = Σ αᵢ dⁱ over the search interval `domain` (metres, d ≥ 0).
    ///
    /// # Errors
    /// [`CalibrationError::Unidentifiable`] when f is constant (order 0: the reading says nothing
    /// about the distance) or nowhere increasing on the interval; [`CalibrationError::Invalid`]
    /// for a non-finite coefficient or an empty interval.
    pub fn new(alpha: &[f64], domain: [f64; 2]) -> Result<Self, CalibrationError> {
        if alpha.iter().any(|a| !a.is_finite()) {
            return Err(CalibrationError::Invalid(
                "a range model coefficient is not finite".into(),
            ));
        }
        let lo = domain[0].max(0.0);
        let hi = domain[1];
        if !(hi.is_finite() && hi > lo) {
            return Err(CalibrationError::Invalid(format!(
                "the inversion interval [{lo}, {hi}] m is empty"
            )));
        }
        let mut alpha = alpha.to_vec();
        while alpha.len() > 1 && alpha.last() == Some(&0.0) {
            alpha.pop();
        }
        if alpha.len() < 2 {
            return Err(CalibrationError::Unidentifiable(
                "the range model is constant (order 0): a reading says nothing about the \
                 distance"
                    .into(),
            ));
        }
        let increasing = (0..=GRID)
            .any(|i| horner_derivative(&alpha, lo + (hi - lo) * i as f64 / GRID as f64) > 0.0);
        if !increasing {
            return Err(CalibrationError::Unidentifiable(
                "the fitted range model does not increase with distance anywhere in range".into(),
            ));
        }
        Ok(Self { alpha, lo, hi })
    }

    /// The coefficients α.
    #[must_use]
    pub fn alpha(&self) -> &[f64] {
        &self.alpha
    }

    /// The distance whose mean reading is `reading`, metres (finite, ≥ 0).
    #[must_use]
    pub fn distance(&self, reading: f64) -> f64 {
        let a = &self.alpha;
        match a.len() {
            2 => ((reading - a[0]) / a[1]).max(0.0),
            3 => quadratic(a[0] - reading, a[1], a[2]).max(0.0),
            _ => self.search(reading),
        }
    }

    fn search(&self, reading: f64) -> f64 {
        let a = &self.alpha;
        let g = |d: f64| horner(a, d) - reading;
        let at = |i: usize| self.lo + (self.hi - self.lo) * i as f64 / GRID as f64;
        // The straight line through the interval's ends: the guess that picks among roots.
        let (f0, f1) = (horner(a, self.lo), horner(a, self.hi));
        let guess = if f1 != f0 {
            self.lo + (reading - f0) / (f1 - f0) * (self.hi - self.lo)
        } else {
            (self.lo + self.hi) / 2.0
        };
        let mut best: Option<f64> = None;
        for i in 0..GRID {
            let (x0, x1) = (at(i), at(i + 1));
            let (g0, g1) = (g(x0), g(x1));
            if g0 == 0.0 || g0 < 0.0 && g1 > 0.0 {
                let root = if g0 == 0.0 { x0 } else { bisect(&g, x0, x1) };
                if best.is_none_or(|b| (root - guess).abs() < (b - guess).abs()) {
                    best = Some(root);
                }
            }
        }
        if let Some(root) = best {
            return root;
        }
        if g(self.hi) == 0.0 {
            return self.hi;
        }
        // No root: eq. (30)'s minimiser of |f − d̃| over the interval, to the grid's resolution,
        // then refined by golden-section search around it.
        let i = (0..=GRID)
            .min_by(|&i, &j| g(at(i)).abs().total_cmp(&g(at(j)).abs()))
            .unwrap_or(0);
        let (mut l, mut r) = (at(i.saturating_sub(1)), at((i + 1).min(GRID)));
        let phi = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..80 {
            let m1 = r - phi * (r - l);
            let m2 = l + phi * (r - l);
            if g(m1).abs() <= g(m2).abs() {
                r = m2;
            } else {
                l = m1;
            }
        }
        (l + r) / 2.0
    }
}

/// The root of c + b d + a d² on the increasing branch (f′ = b + 2 a d = √disc ≥ 0), in the
/// form 2(−c)/(b + √disc) that stays exact as a → 0; the vertex (eq. (30)'s least-squares
/// answer) when the reading lies beyond the parabola's extreme.
fn quadratic(c: f64, b: f64, a: f64) -> f64 {
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return if a != 0.0 { -b / (2.0 * a) } else { 0.0 };
    }
    let q = b + disc.sqrt();
    if q > 0.0 {
        -2.0 * c / q
    } else if a != 0.0 {
        -b / (2.0 * a)
    } else {
        0.0
    }
}

/// Bisection for a sign change g(x0) < 0 < g(x1).
fn bisect(g: &impl Fn(f64) -> f64, mut x0: f64, mut x1: f64) -> f64 {
    for _ in 0..100 {
        let m = (x0 + x1) / 2.0;
        if m <= x0 || m >= x1 {
            break;
        }
        if g(m) < 0.0 {
            x0 = m;
        } else {
            x1 = m;
        }
    }
    (x0 + x1) / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_one_to_three_round_trip() {
        for alpha in [
            vec![0.05, 0.9],
            vec![0.0525, 0.8838, 0.0584],
            vec![0.0525, 0.8838, -0.03],
            vec![0.01, 1.02, -0.02, 0.004],
        ] {
            let inv = Inverse::new(&alpha, [0.0, 6.0]).unwrap();
            for i in 1..50 {
                let d = 0.1 * i as f64;
                let got = inv.distance(horner(&alpha, d));
                assert!((got - d).abs() < 1e-9, "{alpha:?} at {d}: {got}");
            }
        }
    }

    #[test]
    fn constant_and_decreasing_models_are_refused() {
        assert!(matches!(
            Inverse::new(&[1.0], [0.0, 5.0]),
            Err(CalibrationError::Unidentifiable(_))
        ));
        assert!(matches!(
            Inverse::new(&[1.0, -1.0], [0.0, 5.0]),
            Err(CalibrationError::Unidentifiable(_))
        ));
    }

    #[test]
    fn beyond_the_parabola_gives_the_vertex() {
        // f(d) = d − 0.1 d² peaks at d = 5 with f = 2.5.
        let inv = Inverse::new(&[0.0, 1.0, -0.1], [0.0, 6.0]).unwrap();
        assert!((inv.distance(3.0) - 5.0).abs() < 1e-12);
    }
}
