//! Scan-to-scan matching of a 2-D lidar: point-to-line ICP (Censi, "An ICP variant using a
//! point-to-line metric", ICRA 2008). It gives the lidar's motion between two revolutions, the
//! measurement that the odometry calibration (Censi, Franchi, Marchionni, Oriolo, IEEE T-RO
//! 29(2), 2013) sets against the wheels.
//!
//! Each iteration moves the current scan by the motion so far, matches each of its points to
//! the nearest segment between neighbouring reference points on one surface (`reference`: a
//! search along the bearing, not over all pairs), keeps the correspondences within a gate that
//! shrinks with the residuals' spread and then the best `1 − trim_fraction` of them (trimmed
//! ICP), and moves to the motion that minimises their squared distances to the segments' lines
//! (`solve`). It stops when a step is below the convergence thresholds, or when it comes back
//! to a motion it has already reached (a cycle between correspondence sets).
//!
//! A segment's line is the total-least-squares line of its two points and of their neighbours
//! on the same surface within [`MatchOptions::line_fit_radius_m`]; with a radius of zero it is
//! the line through the two points, PL-ICP's own. With centimetre noise and readings a degree
//! apart, neighbours 2 cm apart tilt a two-point line by tens of degrees, and such tilted lines
//! would both blur the motion and make a corridor look as if its walls fixed the motion along
//! them.
//!
//! What it can tell: on scans ray-cast in an irregular room with 1 cm range noise and 360 beams
//! (`tests/scan_match.rs`), over 200 motions of up to 0.2 m and 11° from a zero guess, the
//! error was 1.2–1.3 mm RMS in x and y and 0.034° in θ. The covariance is somewhat optimistic:
//! the mean squared Mahalanobis distance of the errors was 3.7 where 3 would fit, because it
//! leaves out how the noise moves the correspondences and the trim. With two-point lines the
//! errors were 15 % larger and that mean 6.0.

mod reference;
mod solve;

use hilsim_recording::{wrap_angle, Pose};

use reference::{usable, Reference, Surfaces};
use solve::{refine, Normal, Pair};

/// One revolution of a 2-D lidar as points in the lidar's own frame (x forward, y left),
/// metres, in the order of increasing beam angle (readings that were invalid or out of range
/// left out).
///
/// Points that are not finite, lie at the lidar or beyond a kilometre are ignored by
/// [`match_scans`]; the order does not matter to it (it sorts by bearing).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scan {
    /// The points, metres.
    pub points: Vec<[f64; 2]>,
}

impl Scan {
    /// The scan of `(angle rad, range m)` readings; readings with a non-finite angle or range,
    /// or a range that is not positive, are left out.
    ///
    /// ```
    /// use hilsim_calibrator::scan_match::Scan;
    /// let scan = Scan::from_polar([(0.0, 2.0), (std::f64::consts::FRAC_PI_2, 1.0), (0.1, f64::NAN)]);
    /// assert_eq!(scan.points.len(), 2);
    /// assert!((scan.points[1][1] - 1.0).abs() < 1e-12);
    /// ```
    #[must_use]
    pub fn from_polar(readings: impl IntoIterator<Item = (f64, f64)>) -> Self {
        Self {
            points: readings
                .into_iter()
                .filter(|(a, r)| a.is_finite() && r.is_finite() && *r > 0.0)
                .map(|(a, r)| {
                    let (sin, cos) = a.sin_cos();
                    [r * cos, r * sin]
                })
                .collect(),
        }
    }
}

/// The matcher's settings; [`MatchOptions::default`] suits a 360-beam lidar with centimetre
/// noise such as the Neato XV-11.
#[derive(Debug, Clone, PartialEq)]
pub struct MatchOptions {
    /// Most iterations before [`MatchFailure::NotConverged`].
    pub max_iterations: usize,
    /// The widest gate on a point's distance to its segment, metres: the first iterations'.
    /// Later gates are `gate_sigmas` times the residuals' robust spread, within
    /// [`MatchOptions::min_correspondence_m`] and this.
    pub max_correspondence_m: f64,
    /// The narrowest gate, metres (keeps noiseless data from shrinking the gate to nothing).
    pub min_correspondence_m: f64,
    /// The gate in robust standard deviations of the residuals (1.4826 × their median
    /// absolute value, so that outliers do not widen it).
    pub gate_sigmas: f64,
    /// Fraction of the gated correspondences dropped, the largest residuals first (trimmed
    /// ICP), in [0, 1).
    pub trim_fraction: f64,
    /// Fewer correspondences (or usable current points) than this is
    /// [`MatchFailure::TooFewPoints`]; at least 4 (three unknowns and a residual to measure the
    /// noise).
    pub min_points: usize,
    /// An iteration moving the lidar less than this (metres) and turning it less than
    /// `convergence_rad` ends the match.
    pub convergence_m: f64,
    /// See `convergence_m`, radians.
    pub convergence_rad: f64,
    /// Neighbouring reference points further apart than this (metres) plus `jump_fraction` of
    /// their range are on different surfaces (a jump, e.g. an edge in front of a wall).
    pub jump_m: f64,
    /// See `jump_m`.
    pub jump_fraction: f64,
    /// Neighbours within this distance (metres) of a segment's middle, on the same surface,
    /// join the fit of its line; 0 makes it the line through the segment's two points.
    pub line_fit_radius_m: f64,
    /// The smallest share of the information a direction of the motion may have before the
    /// match is [`MatchFailure::Degenerate`]: the smallest eigenvalue of `JᵀJ / m` with θ
    /// multiplied by the current points' RMS range, a number between 0 and about 1 (½ for a
    /// square room's translations). With 1 cm noise, a corridor's walls alone give 0.002–0.008
    /// (their fitted lines' tilt from the noise), a corridor closed by a wall 4 m ahead
    /// 0.05–0.08, an irregular room 0.15–0.2. Steps are also taken only along directions above
    /// it.
    pub min_observability: f64,
}

impl Default for MatchOptions {
    fn default() -> Self {
        Self {
            max_iterations: 50,
            // A robot at 0.5 m/s and a lidar at 5 Hz (the XV-11's rate) moves 0.1 m between
            // revolutions; 0.3 m leaves room for the odometry guess's error.
            max_correspondence_m: 0.3,
            // Twice the XV-11's ~1 cm range noise.
            min_correspondence_m: 0.02,
            gate_sigmas: 5.0,
            // Censi's PL-ICP keeps 90 % of the correspondences (ICRA 2008, section V).
            trim_fraction: 0.1,
            min_points: 20,
            convergence_m: 1e-4,
            convergence_rad: 1e-4,
            jump_m: 0.2,
            jump_fraction: 0.05,
            // Ten readings a degree apart at 1 m; two at 3 m.
            line_fit_radius_m: 0.1,
            min_observability: 0.02,
        }
    }
}

impl MatchOptions {
    /// Checks every setting, naming the first bad one.
    ///
    /// # Errors
    /// [`MatchFailure::InvalidInput`] naming the setting and what it must be.
    pub fn validate(&self) -> Result<(), MatchFailure> {
        let bad = |what: String| Err(MatchFailure::InvalidInput(what));
        let positive = [
            ("max_correspondence_m", self.max_correspondence_m),
            ("min_correspondence_m", self.min_correspondence_m),
            ("gate_sigmas", self.gate_sigmas),
            ("convergence_m", self.convergence_m),
            ("convergence_rad", self.convergence_rad),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return bad(format!("{name} must be positive and finite, got {v}"));
            }
        }
        let non_negative = [
            ("jump_m", self.jump_m),
            ("jump_fraction", self.jump_fraction),
            ("line_fit_radius_m", self.line_fit_radius_m),
            ("min_observability", self.min_observability),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return bad(format!("{name} must be zero or more and finite, got {v}"));
            }
        }
        if self.min_correspondence_m > self.max_correspondence_m {
            return bad(format!(
                "min_correspondence_m ({}) must not exceed max_correspondence_m ({})",
                self.min_correspondence_m, self.max_correspondence_m
            ));
        }
        if !(0.0..1.0).contains(&self.trim_fraction) {
            return bad(format!(
                "trim_fraction must be in [0, 1), got {}",
                self.trim_fraction
            ));
        }
        if self.min_points < 4 {
            return bad(format!(
                "min_points must be at least 4 (three unknowns and a residual to measure the \
                 noise), got {}",
                self.min_points
            ));
        }
        if self.max_iterations == 0 {
            return bad("max_iterations must be at least 1, got 0".to_string());
        }
        Ok(())
    }

    fn surfaces(&self) -> Surfaces {
        Surfaces {
            jump_m: self.jump_m,
            jump_fraction: self.jump_fraction,
            fit_radius_m: self.line_fit_radius_m,
        }
    }
}

/// The lidar's motion from the reference scan to the current one: the current scan's frame
/// expressed in the reference's frame (x, y metres, θ radians), so a current point `p` maps to
/// `R(θ) p + (x, y)` in the reference frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanMatch {
    /// (x m, y m, θ rad), θ in (-π, π].
    pub motion: [f64; 3],
    /// The motion's covariance, (x, y, θ) in m and rad: `2 σ² (JᵀJ)⁻¹`, `J` the residuals'
    /// Jacobian at the motion and `σ` [`ScanMatch::point_noise_m`]. The 2 is the reference
    /// scan's noise: the lines carry it, and their errors reach the motion through the same
    /// Jacobian as the current points' do (for two scans of one lidar, about as much).
    pub covariance: [[f64; 3]; 3],
    /// Correspondences used (after the gate and the trim).
    pub correspondences: usize,
    /// Root mean square of their point-to-line residuals, metres.
    pub rms_residual_m: f64,
    /// Iterations run.
    pub iterations: usize,
    /// One point's noise normal to its surface, metres: the residuals' robust spread
    /// (1.4826 × median absolute value), each residual first divided by `√(1 + v)`, `v` its
    /// line's variance at the point in units of a point's.
    pub point_noise_m: f64,
    /// The weakest direction's share of the information (see
    /// [`MatchOptions::min_observability`]).
    pub observability: f64,
}

impl ScanMatch {
    /// The motion as a pose of the current lidar frame in the reference's.
    #[must_use]
    pub fn pose(&self) -> Pose {
        Pose::new(self.motion[0], self.motion[1], self.motion[2])
    }
}

/// Why two scans could not be matched.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MatchFailure {
    /// Too few usable points, surfaces or correspondences to fix the motion.
    #[error(
        "too few points to match: {correspondences} correspondences between {current} usable \
         current points and {reference} usable reference points on {surfaces} surface segments, \
         at least {needed} needed"
    )]
    TooFewPoints {
        /// Usable reference points.
        reference: usize,
        /// Segments of the reference that join two points of one surface.
        surfaces: usize,
        /// Usable current points.
        current: usize,
        /// Correspondences within the gate after the trim (0 when the scans alone fell short).
        correspondences: usize,
        /// [`MatchOptions::min_points`].
        needed: usize,
    },
    /// The iterations ran out before a step fell below the convergence thresholds (or the
    /// numbers stopped being finite: then the step is NaN).
    #[error(
        "the match did not settle in {iterations} iterations: its last step moved {step_m} m \
         and turned {step_rad} rad"
    )]
    NotConverged {
        /// Iterations run.
        iterations: usize,
        /// The last step's translation, metres (NaN when the numbers stopped being finite).
        step_m: f64,
        /// The last step's rotation, radians.
        step_rad: f64,
    },
    /// The scans' geometry does not fix the motion in some direction, e.g. a corridor whose
    /// walls say nothing of the motion along them.
    #[error(
        "the scans do not fix the motion along (x {:.2}, y {:.2}, θ×range {:.2}), as a \
         corridor's walls do not fix the motion along them: that direction's share of the \
         information is {observability:.4}, below {threshold}",
        .weakest[0], .weakest[1], .weakest[2]
    )]
    Degenerate {
        /// The weakest direction's share of the information (see
        /// [`MatchOptions::min_observability`]).
        observability: f64,
        /// [`MatchOptions::min_observability`].
        threshold: f64,
        /// The weakest direction, a unit vector in (x m, y m, θ × RMS range m).
        weakest: [f64; 3],
    },
    /// The options or the guess are not usable.
    #[error("{0}")]
    InvalidInput(String),
}

/// The lidar's motion from `reference` to `current` (see [`ScanMatch`]), starting from
/// `guess` (e.g. the odometry's), by point-to-line ICP.
///
/// # Requirements
/// The guess within about [`MatchOptions::max_correspondence_m`] of the truth at the scans'
/// ranges (a rotation error times the range counts); the scene mostly static; both scans from
/// one lidar (the covariance assumes their noise alike).
///
/// # Reference
/// A. Censi, "An ICP variant using a point-to-line metric", ICRA 2008: the metric (eq. 4), the
/// projective correspondence search (section IV), the 90 % trim (section V).
///
/// # Errors
/// [`MatchFailure::InvalidInput`] for bad options or a non-finite guess;
/// [`MatchFailure::TooFewPoints`], [`MatchFailure::NotConverged`],
/// [`MatchFailure::Degenerate`] as documented on each. Never panics.
pub fn match_scans(
    reference: &Scan,
    current: &Scan,
    guess: [f64; 3],
    options: &MatchOptions,
) -> Result<ScanMatch, MatchFailure> {
    options.validate()?;
    if !guess.iter().all(|v| v.is_finite()) {
        return Err(MatchFailure::InvalidInput(format!(
            "the guess must be finite, got {guess:?}"
        )));
    }
    let reference = Reference::new(&reference.points, options.surfaces());
    let current: Vec<[f64; 2]> = current.points.iter().copied().filter(usable).collect();
    let too_few = |correspondences: usize| MatchFailure::TooFewPoints {
        reference: reference.points(),
        surfaces: reference.surfaces(),
        current: current.len(),
        correspondences,
        needed: options.min_points,
    };
    if reference.surfaces() < 2 || current.len() < options.min_points {
        return Err(too_few(0));
    }
    let mut work = Work {
        reference: &reference,
        current: &current,
        options,
        pairs: Vec::with_capacity(current.len()),
        kept: 0,
        scratch: Vec::with_capacity(current.len()),
    };
    let tiny = (options.convergence_m / 10.0, options.convergence_rad / 10.0);
    let mut x = [guess[0], guess[1], wrap_angle(guess[2])];
    let mut gate = options.max_correspondence_m;
    let mut last = (f64::NAN, f64::NAN);
    let mut visited: Vec<[f64; 3]> = Vec::with_capacity(options.max_iterations.min(64));
    let mut ran = 0;
    for iteration in 1..=options.max_iterations {
        ran = iteration;
        let spread = work.associate(x, gate);
        if work.kept < options.min_points {
            return Err(too_few(work.kept));
        }
        let Some(next) = refine(
            &mut work.pairs[..work.kept],
            x,
            options.min_observability,
            tiny,
        ) else {
            last = (f64::NAN, f64::NAN);
            break;
        };
        let step = (
            (next[0] - x[0]).hypot(next[1] - x[1]),
            wrap_angle(next[2] - x[2]).abs(),
        );
        x = [next[0], next[1], wrap_angle(next[2])];
        let g = options.gate_sigmas * spread;
        gate = if g.is_finite() {
            g.clamp(options.min_correspondence_m, options.max_correspondence_m)
        } else {
            options.max_correspondence_m
        };
        last = step;
        let close = |y: &[f64; 3]| {
            (x[0] - y[0]).hypot(x[1] - y[1]) < options.convergence_m
                && wrap_angle(x[2] - y[2]).abs() < options.convergence_rad
        };
        // A motion met before is a cycle between correspondence sets (the trim and the gate
        // flip a few points back and forth); any motion on it is as good as the others.
        if step.0 < options.convergence_m && step.1 < options.convergence_rad
            || visited.iter().any(close)
        {
            return work.finish(x, gate, iteration);
        }
        visited.push(x);
    }
    Err(MatchFailure::NotConverged {
        iterations: ran,
        step_m: last.0,
        step_rad: last.1,
    })
}

/// Median absolute deviation to a Gaussian's standard deviation: 1 / Φ⁻¹(3/4).
const MAD_TO_SIGMA: f64 = 1.4826;

/// [`crate::stats::median`]'s value (the mean of the two middle values for an even count) in
/// linear time, `v` reordered: it runs every iteration, where sorting took a tenth of the time.
fn median(v: &mut [f64]) -> f64 {
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    let (below, upper, _) = v.select_nth_unstable_by(n / 2, f64::total_cmp);
    let upper = *upper;
    if n % 2 == 1 {
        upper
    } else {
        let lower = below
            .iter()
            .copied()
            .max_by(f64::total_cmp)
            .unwrap_or(upper);
        (lower + upper) / 2.0
    }
}

/// One match's scans, settings and buffers.
struct Work<'a> {
    reference: &'a Reference,
    current: &'a [[f64; 2]],
    options: &'a MatchOptions,
    pairs: Vec<Pair>,
    /// How many of `pairs` (the first) survive the trim.
    kept: usize,
    scratch: Vec<f64>,
}

impl Work<'_> {
    /// Matches the current points moved by `x` to the reference within `gate`, then trims;
    /// returns the gated residuals' robust spread (1.4826 × their median absolute value).
    fn associate(&mut self, x: [f64; 3], gate: f64) -> f64 {
        self.pairs.clear();
        let (sin, cos) = x[2].sin_cos();
        for p in self.current {
            let q = [
                cos * p[0] - sin * p[1] + x[0],
                sin * p[0] + cos * p[1] + x[1],
            ];
            if let Some((line, _)) = self.reference.nearest(q, gate) {
                let offset = line.offset();
                self.pairs.push(Pair {
                    p: *p,
                    normal: line.normal,
                    offset,
                    variance_factor: line.variance_factor(q),
                    residual: line.normal[0] * q[0] + line.normal[1] * q[1] - offset,
                });
            }
        }
        self.scratch.clear();
        self.scratch
            .extend(self.pairs.iter().map(|p| p.residual.abs()));
        let spread = MAD_TO_SIGMA * median(&mut self.scratch);
        let n = self.pairs.len();
        let keep = ((1.0 - self.options.trim_fraction) * n as f64).ceil() as usize;
        if keep < n {
            self.pairs
                .select_nth_unstable_by(keep, |a, b| a.residual.abs().total_cmp(&b.residual.abs()));
        }
        self.kept = keep.min(n);
        spread
    }

    /// The result at the converged motion `x`: its correspondences, covariance and the check
    /// that the geometry fixes it.
    fn finish(
        &mut self,
        x: [f64; 3],
        gate: f64,
        iterations: usize,
    ) -> Result<ScanMatch, MatchFailure> {
        self.associate(x, gate);
        let m = self.kept;
        if m < self.options.min_points {
            return Err(MatchFailure::TooFewPoints {
                reference: self.reference.points(),
                surfaces: self.reference.surfaces(),
                current: self.current.len(),
                correspondences: m,
                needed: self.options.min_points,
            });
        }
        let normal = Normal::at(&self.pairs[..m], &x);
        let not_finite = MatchFailure::NotConverged {
            iterations,
            step_m: f64::NAN,
            step_rad: f64::NAN,
        };
        let observability = normal.observability().ok_or(not_finite.clone())?;
        let degenerate = MatchFailure::Degenerate {
            observability: observability.smallest,
            threshold: self.options.min_observability,
            weakest: observability.weakest,
        };
        if observability.smallest < self.options.min_observability {
            return Err(degenerate);
        }
        let inverse = normal.inverse().ok_or(degenerate)?;
        // One point's noise, from all the gated residuals (the trim would bias it low).
        self.scratch.clear();
        self.scratch.extend(
            self.pairs
                .iter()
                .map(|p| p.residual.abs() / (1.0 + p.variance_factor).sqrt()),
        );
        let point_m = MAD_TO_SIGMA * median(&mut self.scratch);
        // The three fitted unknowns shrink the residuals by (m - 3) / m on average.
        let sigma2 = point_m * point_m * m as f64 / (m - 3) as f64;
        let cov = inverse * (2.0 * sigma2);
        let rms = (self.pairs[..m]
            .iter()
            .map(|p| p.residual * p.residual)
            .sum::<f64>()
            / m as f64)
            .sqrt();
        let result = ScanMatch {
            motion: x,
            covariance: [
                [cov[(0, 0)], cov[(0, 1)], cov[(0, 2)]],
                [cov[(1, 0)], cov[(1, 1)], cov[(1, 2)]],
                [cov[(2, 0)], cov[(2, 1)], cov[(2, 2)]],
            ],
            correspondences: m,
            rms_residual_m: rms,
            iterations,
            point_noise_m: point_m,
            observability: observability.smallest,
        };
        let finite = result.covariance.iter().flatten().all(|v| v.is_finite())
            && result.rms_residual_m.is_finite()
            && result.point_noise_m.is_finite();
        if finite {
            Ok(result)
        } else {
            Err(not_finite)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_linear_median_equals_the_shared_one() {
        for n in 0..40 {
            let v: Vec<f64> = (0..n)
                .map(|i| f64::from((i * 37 + 11) % 23) - 5.0)
                .collect();
            let (mut a, mut b) = (v.clone(), v);
            let (fast, shared) = (median(&mut a), crate::stats::median(&mut b));
            assert!(fast == shared || fast.is_nan() && shared.is_nan(), "n {n}");
        }
    }
}
