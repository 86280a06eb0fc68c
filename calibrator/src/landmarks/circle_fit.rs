//! Circle and line fits to a segment's points: the centre of a cylinder of known radius
//! (geometric least squares), a free-radius fit to check the radius or estimate it, and a line
//! fit to tell a wall from a cylinder.

/// A fitted circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// Centre, metres.
    pub centre: [f64; 2],
    /// Radius, metres.
    pub radius: f64,
    /// Weighted root-mean-square of the geometric residuals |p − c| − r, metres.
    pub rms: f64,
    /// Standard error of the radius when the weights are inverse variances (free fits only;
    /// 0 for known-radius fits).
    pub radius_se: f64,
}

/// The centre of a circle of radius `r` fitted to `points` by weighted geometric least squares,
/// minimising Σ wᵢ (|pᵢ − c| − r)², Gauss–Newton from `init` with step halving.
///
/// Starting beyond the points (seen from the sensor) picks the solution on the far side, the
/// one a convex cylinder gives. `None` when the fit fails to produce a finite centre.
#[must_use]
pub fn fit_known_radius(points: &[[f64; 2]], w: &[f64], r: f64, init: [f64; 2]) -> Option<Circle> {
    if points.len() < 2 {
        return None;
    }
    let cost = |c: [f64; 2]| -> f64 {
        points
            .iter()
            .zip(w)
            .map(|(p, wi)| wi * (dist(*p, c) - r).powi(2))
            .sum()
    };
    let mut c = init;
    let mut f = cost(c);
    for _ in 0..50 {
        // Normal equations of the 2-parameter problem.
        let (mut a11, mut a12, mut a22, mut g1, mut g2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (p, wi) in points.iter().zip(w) {
            let d = dist(*p, c).max(1e-12);
            let (jx, jy) = ((c[0] - p[0]) / d, (c[1] - p[1]) / d);
            let e = d - r;
            a11 += wi * jx * jx;
            a12 += wi * jx * jy;
            a22 += wi * jy * jy;
            g1 += wi * jx * e;
            g2 += wi * jy * e;
        }
        // A little damping keeps two-point fits (a singular direction) well posed.
        let damp = 1e-9 * (a11 + a22).max(1e-30);
        let (a11, a22) = (a11 + damp, a22 + damp);
        let det = a11 * a22 - a12 * a12;
        if !(det.is_finite() && det > 0.0) {
            break;
        }
        let dx = -(a22 * g1 - a12 * g2) / det;
        let dy = -(a11 * g2 - a12 * g1) / det;
        let mut step = 1.0;
        let mut improved = false;
        for _ in 0..20 {
            let trial = [c[0] + step * dx, c[1] + step * dy];
            let ft = cost(trial);
            if ft <= f {
                c = trial;
                improved = f - ft > 1e-15 * f.max(1e-30);
                f = ft;
                break;
            }
            step /= 2.0;
        }
        if !improved || (dx * dx + dy * dy).sqrt() * step < 1e-10 {
            break;
        }
    }
    let wsum: f64 = w.iter().sum();
    (c[0].is_finite() && c[1].is_finite() && wsum > 0.0).then(|| Circle {
        centre: c,
        radius: r,
        rms: (f / wsum).sqrt(),
        radius_se: 0.0,
    })
}

/// A circle of free radius: Kåsa's algebraic fit, refined geometrically (Gauss–Newton on centre
/// and radius). `None` with fewer than three points or a degenerate (straight) configuration.
#[must_use]
pub fn fit_free(points: &[[f64; 2]], w: &[f64]) -> Option<Circle> {
    if points.len() < 3 {
        return None;
    }
    let init = kasa(points, w)?;
    let mut c = init.centre;
    let mut r = init.radius;
    let cost = |c: [f64; 2], r: f64| -> f64 {
        points
            .iter()
            .zip(w)
            .map(|(p, wi)| wi * (dist(*p, c) - r).powi(2))
            .sum()
    };
    let mut f = cost(c, r);
    for _ in 0..50 {
        let mut a = nalgebra::Matrix3::<f64>::zeros();
        let mut g = nalgebra::Vector3::<f64>::zeros();
        for (p, wi) in points.iter().zip(w) {
            let d = dist(*p, c).max(1e-12);
            let j = nalgebra::Vector3::new((c[0] - p[0]) / d, (c[1] - p[1]) / d, -1.0);
            a += *wi * j * j.transpose();
            g += *wi * j * (d - r);
        }
        let Some(step) = (a + nalgebra::Matrix3::identity() * 1e-12 * a.trace())
            .lu()
            .solve(&g)
        else {
            break;
        };
        let mut t = 1.0;
        let mut improved = false;
        for _ in 0..20 {
            let (ct, rt) = ([c[0] - t * step[0], c[1] - t * step[1]], r - t * step[2]);
            let ft = cost(ct, rt);
            if ft <= f {
                improved = f - ft > 1e-15 * f.max(1e-30);
                c = ct;
                r = rt;
                f = ft;
                break;
            }
            t /= 2.0;
        }
        if !improved {
            break;
        }
    }
    let wsum: f64 = w.iter().sum();
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    for (p, wi) in points.iter().zip(w) {
        let d = dist(*p, c).max(1e-12);
        let j = nalgebra::Vector3::new((c[0] - p[0]) / d, (c[1] - p[1]) / d, -1.0);
        a += *wi * j * j.transpose();
    }
    let radius_se = a
        .try_inverse()
        .map_or(f64::INFINITY, |inv| inv[(2, 2)].max(0.0).sqrt());
    (c[0].is_finite() && r.is_finite() && r > 0.0).then(|| Circle {
        centre: c,
        radius: r,
        rms: (f / wsum).sqrt(),
        radius_se,
    })
}

/// Kåsa's fit: minimises Σ wᵢ (|pᵢ − c|² − r²)², linear in (c, r² − |c|²).
fn kasa(points: &[[f64; 2]], w: &[f64]) -> Option<Circle> {
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    let mut b = nalgebra::Vector3::<f64>::zeros();
    for (p, wi) in points.iter().zip(w) {
        let row = nalgebra::Vector3::new(2.0 * p[0], 2.0 * p[1], 1.0);
        a += *wi * row * row.transpose();
        b += *wi * row * (p[0] * p[0] + p[1] * p[1]);
    }
    let x = a.lu().solve(&b)?;
    let r2 = x[2] + x[0] * x[0] + x[1] * x[1];
    (r2 > 0.0 && r2.is_finite()).then(|| Circle {
        centre: [x[0], x[1]],
        radius: r2.sqrt(),
        rms: 0.0,
        radius_se: 0.0,
    })
}

/// Weighted root-mean-square perpendicular distance of `points` to their total-least-squares
/// line.
#[must_use]
pub fn line_rms(points: &[[f64; 2]], w: &[f64]) -> f64 {
    let wsum: f64 = w.iter().sum();
    if points.len() < 2 || wsum <= 0.0 {
        return 0.0;
    }
    let mx = points.iter().zip(w).map(|(p, wi)| wi * p[0]).sum::<f64>() / wsum;
    let my = points.iter().zip(w).map(|(p, wi)| wi * p[1]).sum::<f64>() / wsum;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (p, wi) in points.iter().zip(w) {
        let (dx, dy) = (p[0] - mx, p[1] - my);
        sxx += wi * dx * dx;
        sxy += wi * dx * dy;
        syy += wi * dy * dy;
    }
    // The smaller eigenvalue of the scatter matrix is the weighted squared perpendicular sum.
    let tr = sxx + syy;
    let det = sxx * syy - sxy * sxy;
    let small = tr / 2.0 - ((tr * tr / 4.0 - det).max(0.0)).sqrt();
    (small.max(0.0) / wsum).sqrt()
}

/// Euclidean distance.
#[must_use]
pub fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(c: [f64; 2], r: f64, from: f64, to: f64, n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let a = from + (to - from) * i as f64 / (n - 1) as f64;
                [c[0] + r * a.cos(), c[1] + r * a.sin()]
            })
            .collect()
    }

    #[test]
    fn known_radius_fit_recovers_the_centre() {
        let pts = arc([2.0, 1.0], 0.12, 2.5, 3.8, 7);
        let w = vec![1.0; pts.len()];
        let c = fit_known_radius(&pts, &w, 0.12, [2.1, 1.1]).unwrap();
        assert!(dist(c.centre, [2.0, 1.0]) < 1e-9, "{c:?}");
        assert!(c.rms < 1e-9);
    }

    #[test]
    fn free_fit_recovers_the_radius_and_lines_are_straight() {
        let pts = arc([1.0, -1.0], 0.3, 1.0, 2.5, 9);
        let w = vec![1.0; pts.len()];
        let c = fit_free(&pts, &w).unwrap();
        assert!((c.radius - 0.3).abs() < 1e-9 && dist(c.centre, [1.0, -1.0]) < 1e-9);
        let line: Vec<[f64; 2]> = (0..5).map(|i| [i as f64, 2.0 * i as f64 + 1.0]).collect();
        assert!(line_rms(&line, &[1.0; 5]) < 1e-9);
        assert!(line_rms(&pts, &w) > 0.01);
    }
}
