//! The shapes a mechanism takes here: the catalogue's first-order form, physical forms from
//! the literature that the catalogue does not write, and random smooth monotone curves, so
//! that a self-test on this reality cannot be passed by knowing the catalogue's formulas.
//!
//! Every form of a mechanism is scaled to agree with the catalogue's at one reference point
//! (an incidence error at 45°, a reflectivity walk at half the reference reflectivity, a
//! warm-up at power-on), so the size the self-test scores means the same whatever the form.

/// The ranges a range-error curve spans, metres (from the unit's head out):
/// `Concealed::LidarRangeCurve`'s curve is drawn over [0, this].
pub const RANGE_CURVE_SPAN_M: f64 = 8.0;

/// Knots of a random curve.
pub const KNOTS: usize = 6;

/// A smooth nondecreasing curve rising from 0 at its first knot to 1 at its last, constant
/// beyond its ends: monotone piecewise-cubic Hermite interpolation with Fritsch–Carlson
/// slopes (Fritsch and Carlson, "Monotone piecewise cubic interpolation", SIAM J. Numer.
/// Anal. 17, 1980), which never overshoots its knots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Curve {
    x: [f64; KNOTS],
    y: [f64; KNOTS],
    slope: [f64; KNOTS],
}

/// The least share of a random curve's rise between neighbouring knots, relative to the
/// largest: the curve keeps rising everywhere, so a form normalised at an inner point stays
/// within a few times its catalogue counterpart at the ends.
const MIN_RISE: f64 = 0.15;

impl Curve {
    /// The curve through knots `x` (increasing) with values `y` (nondecreasing), rescaled
    /// to rise from 0 to 1. `None` when the knots do not rise.
    #[must_use]
    pub fn through(x: [f64; KNOTS], y: [f64; KNOTS]) -> Option<Self> {
        let rise = y[KNOTS - 1] - y[0];
        if rise.is_nan()
            || rise <= 0.0
            || x.windows(2)
                .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
            || y.windows(2).any(|w| w[1] < w[0])
        {
            return None;
        }
        let y = y.map(|v| (v - y[0]) / rise);
        let secant: Vec<f64> = (0..KNOTS - 1)
            .map(|k| (y[k + 1] - y[k]) / (x[k + 1] - x[k]))
            .collect();
        let mut slope = [0.0; KNOTS];
        slope[0] = secant[0];
        slope[KNOTS - 1] = secant[KNOTS - 2];
        for k in 1..KNOTS - 1 {
            slope[k] = if secant[k - 1] * secant[k] > 0.0 {
                (secant[k - 1] + secant[k]) / 2.0
            } else {
                0.0
            };
        }
        // Fritsch–Carlson: slopes within the circle of radius 3 keep each piece monotone.
        for k in 0..KNOTS - 1 {
            if secant[k] == 0.0 {
                slope[k] = 0.0;
                slope[k + 1] = 0.0;
                continue;
            }
            let (a, b) = (slope[k] / secant[k], slope[k + 1] / secant[k]);
            let r = a.hypot(b);
            if r > 3.0 {
                slope[k] = 3.0 / r * a * secant[k];
                slope[k + 1] = 3.0 / r * b * secant[k];
            }
        }
        Some(Self { x, y, slope })
    }

    /// A random curve over `[lo, hi]`: inner knots at uniformly drawn places (kept apart by
    /// a tenth of an even spacing), each rise between neighbours uniform in [`MIN_RISE`], 1].
    /// `unit` draws uniformly in [0, 1).
    #[must_use]
    pub fn random(lo: f64, hi: f64, mut unit: impl FnMut() -> f64) -> Self {
        let mut inner: Vec<f64> = (0..KNOTS - 2).map(|_| unit()).collect();
        inner.sort_by(f64::total_cmp);
        let gap = 0.1 / (KNOTS - 1) as f64;
        let mut x = [0.0; KNOTS];
        x[KNOTS - 1] = 1.0;
        for (k, u) in inner.into_iter().enumerate() {
            x[k + 1] = u.clamp(x[k] + gap, 1.0 - gap * (KNOTS - 2 - k) as f64);
        }
        let x = x.map(|u| lo + (hi - lo) * u);
        let mut y = [0.0; KNOTS];
        for k in 1..KNOTS {
            y[k] = y[k - 1] + MIN_RISE + (1.0 - MIN_RISE) * unit();
        }
        Self::through(x, y).expect("knots that rise")
    }

    /// Its value at `v`.
    #[must_use]
    pub fn at(&self, v: f64) -> f64 {
        if v.is_nan() || v <= self.x[0] {
            return 0.0;
        }
        if v >= self.x[KNOTS - 1] {
            return 1.0;
        }
        let k = self.x.partition_point(|&x| x <= v).clamp(1, KNOTS - 1) - 1;
        let h = self.x[k + 1] - self.x[k];
        let s = (v - self.x[k]) / h;
        let (s2, s3) = (s * s, s * s * s);
        (2.0 * s3 - 3.0 * s2 + 1.0) * self.y[k]
            + (s3 - 2.0 * s2 + s) * h * self.slope[k]
            + (-2.0 * s3 + 3.0 * s2) * self.y[k + 1]
            + (s3 - s2) * h * self.slope[k + 1]
    }

    /// Where it first reaches `level` (in (0, 1)), by bisection.
    #[must_use]
    pub fn reaches(&self, level: f64) -> f64 {
        let (mut lo, mut hi) = (self.x[0], self.x[KNOTS - 1]);
        for _ in 0..60 {
            let mid = (lo + hi) / 2.0;
            if self.at(mid) < level {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        (lo + hi) / 2.0
    }
}

const DEG_45: f64 = std::f64::consts::FRAC_PI_4;

/// How an incidence error grows with the angle θ between the beam and the surface's normal:
/// `g(θ)`, 0 head-on and 1 at 45°.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IncidenceGrowth {
    /// `tan θ`: the footprint's depth along the beam (the catalogue's first-order form).
    Tangent,
    /// `(sec θ − 1) / (√2 − 1)`: the footprint's length and the return's spread grow as
    /// `1/cos θ` (Soudarissanane et al., "Scanning geometry: influencing factor on the quality
    /// of terrestrial laser scanning points", ISPRS J. Photogramm. 66, 2011).
    Secant,
    /// Nothing up to `onset_rad`, then `tan θ − tan onset` (scaled to 1 at 45°): a spot that
    /// stays within one pixel of the camera until the surface is steep enough to stretch it.
    Onset { onset_rad: f64 },
    /// A random smooth increasing curve of θ over [0°, 80°].
    Curve(Curve),
}

impl IncidenceGrowth {
    /// `g(θ)`.
    #[must_use]
    pub fn at(&self, theta: f64) -> f64 {
        match *self {
            Self::Tangent => theta.tan(),
            Self::Secant => (1.0 / theta.cos() - 1.0) / (std::f64::consts::SQRT_2 - 1.0),
            Self::Onset { onset_rad } => {
                (theta.tan() - onset_rad.tan()).max(0.0) / (1.0 - onset_rad.tan())
            }
            Self::Curve(c) => c.at(theta) / c.at(DEG_45),
        }
    }
}

/// How a range walk grows as a surface darkens: `h(ρ)`, 0 at the reference reflectivity and
/// 1 at half of it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ReflectivityWalk {
    /// `ρ_ref/ρ − 1` (the catalogue's form).
    Inverse,
    /// `log₂(ρ_ref/ρ)`: a threshold detector's walk follows the log of the return's amplitude
    /// (Kilpelä, "Pulsed time-of-flight laser range finder techniques", Oulu 2004, ch. 3).
    Logarithmic,
    /// A random smooth increasing curve of `ln(ρ_ref/ρ)` over [−1, 3].
    Curve(Curve),
}

impl ReflectivityWalk {
    /// `h(ρ)` against `reference`.
    #[must_use]
    pub fn at(&self, reflectivity: f64, reference: f64) -> f64 {
        let darker = (reference / reflectivity.max(1e-3)).ln();
        match *self {
            Self::Inverse => darker.exp() - 1.0,
            Self::Logarithmic => darker / std::f64::consts::LN_2,
            Self::Curve(c) => {
                (c.at(darker) - c.at(0.0)) / (c.at(std::f64::consts::LN_2) - c.at(0.0))
            }
        }
    }
}

/// How a warm-up's error settles with time `t` since power-on: `w(t)`, 1 at power-on, towards
/// 0, with time scale τ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Settling {
    /// `e^{−t/τ}`: one thermal mass (the catalogue's form).
    Exponential,
    /// Two masses: a share settling ten times faster than the rest, `s e^{−10 t/τ} + (1 − s)
    /// e^{−t/τ}` (a unit's electronics and its housing; Glennie and Lichti, "Temporal stability
    /// of the Velodyne HDL-64E S2 scanner", Remote Sens. 3, 2011, saw a warm-up of this kind).
    TwoMasses { fast_share: f64 },
    /// A thermostat's ramp: `1 − t/(2τ)` until it reaches its set point at 2τ (the same area as
    /// the exponential).
    Ramp,
    /// One minus a random smooth increasing curve of `t/τ` over [0, 4].
    Curve(Curve),
}

impl Settling {
    /// `w(t)` with time scale `tau_s`.
    #[must_use]
    pub fn at(&self, t_s: f64, tau_s: f64) -> f64 {
        let u = t_s / tau_s;
        match *self {
            Self::Exponential => (-u).exp(),
            Self::TwoMasses { fast_share } => {
                fast_share * (-10.0 * u).exp() + (1.0 - fast_share) * (-u).exp()
            }
            Self::Ramp => (1.0 - u / 2.0).max(0.0),
            Self::Curve(c) => 1.0 - c.at(u),
        }
    }
}

/// Which range a sonar reports from the echoes across its beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EchoPick {
    /// The nearest echo within the cone's half-angle (the catalogue's form).
    Nearest,
    /// The range of the echoes' energy centroid, each direction weighted by the beam's
    /// Gaussian main lobe `e^{−2 φ²/φ₀²}` (φ₀ the half-angle) and the echo's spreading `1/d²`:
    /// an envelope detector that times the echo's centre rather than its onset.
    BeamCentroid,
    /// The nearest echo whose amplitude, `e^{−2 φ²/φ₀²} (2 m / d)²` over the lobe, clears the
    /// threshold the half-angle sets at 2 m: a Polaroid-style transducer's cone narrows with
    /// range (Leonard and Durrant-Whyte, *Directed Sonar Sensing for Mobile Robot
    /// Navigation*, 1992, ch. 2).
    Threshold,
}

/// How a wheel's slip grows with its acceleration `a`: `f(a)`, m/s², odd in a. A form other
/// than the catalogue's is scaled to agree with it at the run's largest acceleration, so that
/// its gain means the same for the largest step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Traction {
    /// `a` (the catalogue's form).
    Linear,
    /// `a_s tanh(a/a_s)`: the slip ratio saturates as the tyre's force curve flattens
    /// (Pacejka, *Tyre and Vehicle Dynamics*, ch. 1).
    Saturating { accel_mps2: f64, top_mps2: f64 },
    /// `a_top C(|a|)` with the sign of a: a random smooth increasing curve over [0, a_top].
    Curve { top_mps2: f64, curve: Curve },
}

impl Traction {
    /// `f(a)`.
    #[must_use]
    pub fn at(&self, a: f64) -> f64 {
        match *self {
            Self::Linear => a,
            Self::Saturating {
                accel_mps2,
                top_mps2,
            } => {
                let s = accel_mps2.max(1e-6);
                (a / s).tanh() / (top_mps2 / s).tanh() * top_mps2
            }
            Self::Curve { top_mps2, curve } => a.signum() * top_mps2 * curve.at(a.abs()),
        }
    }
}

/// How a wheel's speed follows its command, with response time τ (its step response reaches
/// `1 − 1/e` of the step at τ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DriveResponse {
    /// `τ v̇ + v = u` (the catalogue's form).
    FirstOrder,
    /// A second-order motor and load, `v̈ = ωₙ² (u − v) − 2 ζ ωₙ v̇`.
    SecondOrder { damping: f64 },
    /// A controller that limits the wheel's acceleration; `accel_mps2` set so that the
    /// largest commanded step reaches `1 − 1/e` at τ.
    SlewLimited { accel_mps2: f64 },
    /// A transport delay of `share · τ` before a first-order lag of the rest.
    DeadTime { share: f64 },
}

/// How a footprint over several surfaces blends their ranges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Blend {
    /// A top-hat footprint, the weighted harmonic mean (a triangulation camera's spot
    /// centroid, the catalogue's form).
    TopHatHarmonic,
    /// A Gaussian footprint (its 1/e² half-width the given one), the power-weighted arithmetic
    /// mean: a phase-measuring unit's mixed pixel (Hebert and Krotkov, "3D measurements from
    /// imaging laser radars: how good are they?", Image Vis. Comput. 10, 1992).
    GaussianMean,
    /// A footprint whose profile falls across its half-width as one minus a random smooth
    /// increasing curve of the offset, blended harmonically or arithmetically.
    Profile { curve: Curve, harmonic: bool },
}

impl Blend {
    /// The footprint's weight at offset `u` (in half-widths, over [−1, 1]) and the offset's
    /// angle in half-widths.
    #[must_use]
    pub fn profile(&self, u: f64) -> (f64, f64) {
        match *self {
            Self::TopHatHarmonic => (u, 1.0),
            Self::GaussianMean => (2.0 * u, (-8.0 * u * u).exp()),
            Self::Profile { curve, .. } => (u, 1.0 - curve.at(u.abs())),
        }
    }

    /// Whether it blends the ranges harmonically (a spot's centroid on a camera).
    #[must_use]
    pub fn harmonic(&self) -> bool {
        match *self {
            Self::TopHatHarmonic => true,
            Self::GaussianMean => false,
            Self::Profile { harmonic, .. } => harmonic,
        }
    }
}

/// What makes a lidar lose returns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LossBy {
    /// A log-normally scattered power `ρ cos θ / d²` below a threshold (the catalogue's form).
    Power,
    /// The range alone, as a unit whose gain is set for its surfaces: the loss chance a random
    /// smooth increasing curve of `ln(d / d½)` over [−1.5, 1.5], whatever it falls on.
    RangeCurve(Curve),
}

#[cfg(test)]
mod tests {
    use super::*;

    fn draws(seed: u64) -> impl FnMut() -> f64 {
        let mut s = crate::Stream::new(seed, "form-test");
        move || s.unit()
    }

    #[test]
    fn a_random_curve_rises_from_zero_to_one_smoothly_and_never_falls() {
        for seed in 0..50 {
            let c = Curve::random(-1.0, 3.0, draws(seed));
            assert_eq!(c.at(-2.0), 0.0);
            assert_eq!(c.at(5.0), 1.0);
            let mut last = 0.0;
            for k in 0..=400 {
                let v = c.at(-1.0 + 4.0 * f64::from(k) / 400.0);
                assert!(v >= last - 1e-12, "seed {seed}: {v} after {last}");
                last = v;
            }
            assert!((c.at(3.0) - 1.0).abs() < 1e-12);
            let half = c.reaches(0.5);
            assert!((c.at(half) - 0.5).abs() < 1e-9);
        }
    }

    #[test]
    fn every_form_agrees_with_the_catalogues_at_its_reference_point() {
        let c = Curve::random(0.0, 80f64.to_radians(), draws(3));
        for g in [
            IncidenceGrowth::Tangent,
            IncidenceGrowth::Secant,
            IncidenceGrowth::Onset {
                onset_rad: 30f64.to_radians(),
            },
            IncidenceGrowth::Curve(c),
        ] {
            assert!((g.at(DEG_45) - 1.0).abs() < 1e-12, "{g:?}");
            assert!(g.at(0.0).abs() < 1e-12, "{g:?}");
        }
        let c = Curve::random(-1.0, 3.0, draws(4));
        for h in [
            ReflectivityWalk::Inverse,
            ReflectivityWalk::Logarithmic,
            ReflectivityWalk::Curve(c),
        ] {
            assert!((h.at(0.4, 0.8) - 1.0).abs() < 1e-12, "{h:?}");
            assert!(h.at(0.8, 0.8).abs() < 1e-12, "{h:?}");
            assert!(h.at(0.9, 0.8) < 0.0, "{h:?}");
        }
        let c = Curve::random(0.0, 4.0, draws(5));
        for w in [
            Settling::Exponential,
            Settling::TwoMasses { fast_share: 0.5 },
            Settling::Ramp,
            Settling::Curve(c),
        ] {
            assert!((w.at(0.0, 10.0) - 1.0).abs() < 1e-12, "{w:?}");
            assert!(w.at(60.0, 10.0) < 0.01, "{w:?}");
        }
        // The secant's form is not the tangent's: at 70° it is 4.64 against 2.75.
        assert!((IncidenceGrowth::Secant.at(70f64.to_radians()) - 4.64).abs() < 0.01);
    }
}
