//! One correspondence set's least squares in (x, y, θ): Gauss–Newton on the point-to-line
//! residuals, solved only along the directions the geometry observes, and the information that
//! decides whether the match is degenerate.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// A current point matched to a reference line.
#[derive(Debug, Clone, Copy)]
pub(super) struct Pair {
    /// The current point in the current (lidar) frame.
    pub p: [f64; 2],
    /// The line's unit normal in the reference frame.
    pub normal: [f64; 2],
    /// The line is `{ q : normal · q = offset }`.
    pub offset: f64,
    /// The line's position variance at the point, in units of one point's variance.
    pub variance_factor: f64,
    /// Signed distance from the transformed point to the line, metres.
    pub residual: f64,
}

impl Pair {
    /// The residual at `x` and its gradient in (x, y, θ).
    fn linearise(&self, x: &[f64; 3]) -> (f64, Vector3<f64>) {
        let (sin, cos) = x[2].sin_cos();
        let rp = [
            cos * self.p[0] - sin * self.p[1],
            sin * self.p[0] + cos * self.p[1],
        ];
        let n = self.normal;
        let r = n[0] * (rp[0] + x[0]) + n[1] * (rp[1] + x[1]) - self.offset;
        // d(R p)/dθ is R p turned by +90°.
        let dtheta = -n[0] * rp[1] + n[1] * rp[0];
        (r, Vector3::new(n[0], n[1], dtheta))
    }
}

/// Most Gauss–Newton steps on one correspondence set: the residual is linear in (x, y, cos θ,
/// sin θ), so two or three steps reach the set's exact minimum (what PL-ICP's closed form gives).
const INNER_STEPS: usize = 4;

/// The Gauss–Newton normal equations of a correspondence set at a motion.
#[derive(Debug, Clone, Copy)]
pub(super) struct Normal {
    /// `Jᵀ J`.
    pub jtj: Matrix3<f64>,
    /// `Jᵀ r`.
    jtr: Vector3<f64>,
    /// Root mean square distance of the current points from the lidar, metres: the lever that
    /// puts a rotation in metres beside the translations.
    pub lever_m: f64,
    /// Correspondences.
    count: usize,
}

/// How well a correspondence set fixes the motion.
#[derive(Debug, Clone, Copy)]
pub(super) struct Observability {
    /// The smallest eigenvalue of the information per correspondence with θ scaled by the lever
    /// (each translation row is a unit normal, so the eigenvalues sum to at most 2).
    pub smallest: f64,
    /// Its eigenvector in (x m, y m, θ·lever m).
    pub weakest: [f64; 3],
}

impl Normal {
    /// The normal equations at `x`.
    pub fn at(pairs: &[Pair], x: &[f64; 3]) -> Self {
        let mut jtj = Matrix3::zeros();
        let mut jtr = Vector3::zeros();
        let mut r2 = 0.0;
        for pair in pairs {
            let (r, j) = pair.linearise(x);
            jtj += j * j.transpose();
            jtr += j * r;
            r2 += pair.p[0] * pair.p[0] + pair.p[1] * pair.p[1];
        }
        let lever = (r2 / pairs.len().max(1) as f64).sqrt();
        Self {
            jtj,
            jtr,
            lever_m: if lever > 1e-6 { lever } else { 1.0 },
            count: pairs.len(),
        }
    }

    /// The scaling that puts θ in metres: diag(1, 1, 1/lever).
    fn scale(&self) -> Matrix3<f64> {
        Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1.0 / self.lever_m))
    }

    /// The eigen-decomposition of the scaled information per correspondence, if finite.
    fn eigen(&self) -> Option<SymmetricEigen<f64, nalgebra::U3>> {
        let s = self.scale();
        let m = s * self.jtj * s / self.count.max(1) as f64;
        if !m.iter().all(|v| v.is_finite()) {
            return None;
        }
        // A bounded iteration count: the default (none) could spin on a pathological matrix.
        SymmetricEigen::try_new(m, f64::EPSILON, 1_000)
    }

    /// How well the set fixes the motion; `None` when its numbers are not finite.
    pub fn observability(&self) -> Option<Observability> {
        let eigen = self.eigen()?;
        let i = eigen.eigenvalues.imin();
        let v = eigen.eigenvectors.column(i);
        Some(Observability {
            smallest: eigen.eigenvalues[i],
            weakest: [v[0], v[1], v[2]],
        })
    }

    /// The Gauss–Newton step, zero along directions whose scaled information per correspondence
    /// is below `min_observability` (a near-singular direction would otherwise take a step set
    /// by the noise); `None` when the numbers are not finite.
    fn step(&self, min_observability: f64) -> Option<Vector3<f64>> {
        let eigen = self.eigen()?;
        let s = self.scale();
        let g = s * self.jtr / self.count.max(1) as f64;
        let mut step = Vector3::zeros();
        for (i, &mu) in eigen.eigenvalues.iter().enumerate() {
            if mu > min_observability && mu > 0.0 {
                let v = eigen.eigenvectors.column(i);
                step -= v * (v.dot(&g) / mu);
            }
        }
        let step = s * step;
        step.iter().all(|v| v.is_finite()).then_some(step)
    }

    /// `(Jᵀ J)⁻¹`, if the set fixes every direction.
    pub fn inverse(&self) -> Option<Matrix3<f64>> {
        let eigen = self.eigen()?;
        // The scaled information per correspondence is of order one; far smaller is singular.
        if !eigen.eigenvalues.iter().all(|&mu| mu > 1e-12) {
            return None;
        }
        let s = self.scale();
        let inv = eigen.eigenvectors
            * Matrix3::from_diagonal(&eigen.eigenvalues.map(|mu| 1.0 / mu))
            * eigen.eigenvectors.transpose();
        Some(s * inv * s / self.count as f64)
    }
}

/// The motion minimising the set's squared point-to-line residuals, from `x`; the residuals
/// are updated to it. `None` when the numbers stop being finite.
pub(super) fn refine(
    pairs: &mut [Pair],
    x: [f64; 3],
    min_observability: f64,
    tiny: (f64, f64),
) -> Option<[f64; 3]> {
    let mut x = x;
    for _ in 0..INNER_STEPS {
        let step = Normal::at(pairs, &x).step(min_observability)?;
        x = [x[0] + step[0], x[1] + step[1], x[2] + step[2]];
        if step[0].hypot(step[1]) < tiny.0 && step[2].abs() < tiny.1 {
            break;
        }
    }
    for pair in pairs.iter_mut() {
        pair.residual = pair.linearise(&x).0;
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points on two perpendicular walls (x = 2, y = 3) seen after a known motion.
    fn pairs(truth: [f64; 3]) -> Vec<Pair> {
        let (sin, cos) = truth[2].sin_cos();
        let mut out = Vec::new();
        for i in 0..20 {
            // World points on the walls, then into the current frame: p = Rᵀ (w - t).
            for (w, normal, offset) in [
                ([2.0, -1.0 + 0.1 * i as f64], [1.0, 0.0], 2.0),
                ([-1.0 + 0.1 * i as f64, 3.0], [0.0, 1.0], 3.0),
            ] {
                let d = [w[0] - truth[0], w[1] - truth[1]];
                out.push(Pair {
                    p: [cos * d[0] + sin * d[1], -sin * d[0] + cos * d[1]],
                    normal,
                    offset,
                    variance_factor: 1.0,
                    residual: 0.0,
                });
            }
        }
        out
    }

    #[test]
    fn refine_reaches_the_exact_motion_of_noiseless_lines() {
        let truth = [0.2, -0.1, 0.15];
        let mut p = pairs(truth);
        let x = refine(&mut p, [0.0; 3], 1e-3, (1e-12, 1e-12)).expect("finite");
        for k in 0..3 {
            assert!((x[k] - truth[k]).abs() < 1e-9, "{x:?}");
        }
        assert!(p.iter().all(|q| q.residual.abs() < 1e-9));
    }

    #[test]
    fn one_wall_leaves_the_translation_along_it_unobservable() {
        let p: Vec<Pair> = pairs([0.0; 3]).into_iter().step_by(2).collect();
        let o = Normal::at(&p, &[0.0; 3]).observability().expect("finite");
        assert!(o.smallest.abs() < 1e-12, "{o:?}");
        // The wall x = 2 fixes x; y (and a mix of y and θ) is free.
        assert!(o.weakest[0].abs() < 1e-9, "{o:?}");
        assert!(Normal::at(&p, &[0.0; 3]).inverse().is_none());
    }
}
