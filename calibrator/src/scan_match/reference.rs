//! The reference scan made searchable: its points sorted by bearing, the segments between
//! neighbours that lie on one surface, each segment's line, and the nearest-segment search.
//!
//! The search is Censi's projective one (PL-ICP, ICRA 2008, section IV): a point's nearest
//! segment lies near its own bearing, so the walk starts at the segment spanning that bearing
//! and goes outwards both ways until no further segment can be nearer. A segment lies in the
//! wedge between its ends' bearings, so a point `q` is at least `|q|·sin Δ` from it, `Δ` the
//! angle from `q`'s bearing to the wedge (at least `|q|` once `Δ ≥ 90°`); that bound only grows
//! along the walk, so the walk stops at the first segment whose bound exceeds the best distance.
//! `|q|·sin Δ` is the cross product of `q` with the unit bearing, so the walk needs no
//! trigonometry, and the bearings are ordered by a pseudo-angle rather than `atan2`: this runs
//! for every point of every iteration.

use std::f64::consts::FRAC_1_SQRT_2;

/// Farthest a usable point may lie from the lidar, metres: no 2-D lidar reads beyond a
/// kilometre, and the cap keeps every square and sum of squares finite.
const MAX_RANGE_M: f64 = 1_000.0;
/// Nearest a usable point may lie, metres: a point at the lidar has no bearing (the XV-11's
/// nearest reading is 0.06 m, its datasheet's minimum range).
const MIN_RANGE_M: f64 = 1e-6;
/// Cosine of the widest angle a segment may span, 45°. The search's bound needs each segment
/// inside the wedge between its ends' bearings, true for spans under a quarter turn; a gap this
/// wide is missing readings, not a surface seen by a lidar.
const COS_MAX_SPAN: f64 = FRAC_1_SQRT_2;
/// Shortest segment with a direction, metres: closer points are one point read twice.
const MIN_SEGMENT_M: f64 = 1e-6;
/// Most neighbours on each side of a segment that its line fit takes (bounds the work on a
/// dense scan; the fit's radius is the real limit).
const MAX_FIT_SIDE: usize = 8;

/// Whether a point can be matched: finite, and neither at the lidar nor beyond any lidar's reach.
pub(super) fn usable(p: &[f64; 2]) -> bool {
    let r2 = p[0] * p[0] + p[1] * p[1];
    p[0].is_finite()
        && p[1].is_finite()
        && (MIN_RANGE_M.powi(2)..=MAX_RANGE_M.powi(2)).contains(&r2)
}

/// A number in [0, 4) growing with `p`'s bearing counter-clockwise from +x, like the bearing
/// in [0, 2π) but without `atan2` (the "diamond angle": the position on the unit L1 circle).
/// NaN at the origin.
fn pseudo_angle(p: [f64; 2]) -> f64 {
    let t = p[1] / (p[0].abs() + p[1].abs());
    match (p[0] >= 0.0, p[1] >= 0.0) {
        (true, true) => t,
        (false, _) => 2.0 - t,
        (true, false) => 4.0 + t,
    }
}

/// `a × b`, the z of the cross product.
fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `a · b`.
fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The line a segment's residuals are measured to: the total-least-squares line of the
/// segment's ends and of the neighbours on the same surface within the fit radius.
#[derive(Debug, Clone, Copy)]
pub(super) struct Line {
    /// The fitted points' centroid.
    point: [f64; 2],
    /// Unit vector along the line.
    direction: [f64; 2],
    /// Unit normal (the direction turned by +90°).
    pub normal: [f64; 2],
    /// Points fitted.
    count: f64,
    /// Sum of the fitted points' squared distances from the centroid along the line, m².
    spread: f64,
}

impl Line {
    /// `normal · point`: the line is `{ q : normal · q = offset }`.
    pub fn offset(&self) -> f64 {
        self.normal[0] * self.point[0] + self.normal[1] * self.point[1]
    }

    /// The variance of the line's position at `q`, in units of one point's variance: the
    /// regression's prediction variance `1/k + u²/Σu²`, `u` the distance from the centroid
    /// along the line (1 at the end of a two-point segment, ½ at its middle).
    pub fn variance_factor(&self, q: [f64; 2]) -> f64 {
        let u =
            self.direction[0] * (q[0] - self.point[0]) + self.direction[1] * (q[1] - self.point[1]);
        1.0 / self.count + u * u / self.spread
    }

    /// The total-least-squares line of `points`, or `None` when they do not fix a direction.
    fn fit(points: impl Iterator<Item = [f64; 2]> + Clone) -> Option<Self> {
        let (mut n, mut sx, mut sy) = (0.0, 0.0, 0.0);
        for p in points.clone() {
            n += 1.0;
            sx += p[0];
            sy += p[1];
        }
        let c = [sx / n, sy / n];
        let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
        for p in points {
            let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
            sxx += dx * dx;
            sxy += dx * dy;
            syy += dy * dy;
        }
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let (sin, cos) = angle.sin_cos();
        // The scatter along the principal direction (its larger eigenvalue).
        let spread = cos * cos * sxx + 2.0 * sin * cos * sxy + sin * sin * syy;
        (spread > MIN_SEGMENT_M * MIN_SEGMENT_M && spread.is_finite()).then_some(Self {
            point: c,
            direction: [cos, sin],
            normal: [-sin, cos],
            count: n,
            spread,
        })
    }
}

/// How a reference scan's neighbours are joined into surfaces and lines.
#[derive(Debug, Clone, Copy)]
pub(super) struct Surfaces {
    /// Neighbours further apart than this plus `jump_fraction` of their range are a jump.
    pub jump_m: f64,
    /// See `jump_m`.
    pub jump_fraction: f64,
    /// Neighbours within this distance of a segment's middle join its line fit.
    pub fit_radius_m: f64,
}

/// The segment from sorted point `k` to point `k + 1` (the last one closes the turn).
#[derive(Debug, Clone, Copy)]
struct Segment {
    a: [f64; 2],
    b: [f64; 2],
    /// `None` when the two points are not on one surface.
    line: Option<Line>,
}

/// A reference scan ready for nearest-segment searches.
#[derive(Debug, Clone)]
pub(super) struct Reference {
    /// Pseudo-angles of the usable points' bearings, ascending.
    bearing: Vec<f64>,
    /// The unit vectors along those bearings.
    unit: Vec<[f64; 2]>,
    /// `segments[k]` joins points `k` and `(k + 1) % n`.
    segments: Vec<Segment>,
    /// Segments that are surfaces.
    surfaces: usize,
}

impl Reference {
    /// The usable points of `points` sorted by bearing, and their segments.
    pub fn new(points: &[[f64; 2]], rules: Surfaces) -> Self {
        let mut sorted: Vec<(f64, [f64; 2])> = points
            .iter()
            .filter(|p| usable(p))
            .map(|p| (pseudo_angle(*p), *p))
            .collect();
        sorted.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let n = sorted.len();
        let bearing: Vec<f64> = sorted.iter().map(|s| s.0).collect();
        let pts: Vec<[f64; 2]> = sorted.iter().map(|s| s.1).collect();
        let range: Vec<f64> = pts.iter().map(|p| dot(*p, *p).sqrt()).collect();
        let unit: Vec<[f64; 2]> = pts
            .iter()
            .zip(&range)
            .map(|(p, r)| [p[0] / r, p[1] / r])
            .collect();
        if n < 2 {
            return Self {
                bearing,
                unit,
                segments: Vec::new(),
                surfaces: 0,
            };
        }
        let next = |k: usize| (k + 1) % n;
        let prev = |k: usize| (k + n - 1) % n;
        // Whether segment k joins two points of one surface.
        let surface: Vec<bool> = (0..n)
            .map(|k| {
                let (a, b) = (pts[k], pts[next(k)]);
                let (ua, ub) = (unit[k], unit[next(k)]);
                // Counter-clockwise from a to b by at most the widest span.
                let span_ok = cross(ua, ub) >= 0.0 && dot(ua, ub) >= COS_MAX_SPAN;
                let d = [b[0] - a[0], b[1] - a[1]];
                let length = dot(d, d).sqrt();
                let reach = range[k].max(range[next(k)]);
                span_ok
                    && length >= MIN_SEGMENT_M
                    && length <= rules.jump_m + rules.jump_fraction * reach
            })
            .collect();
        let radius = rules.fit_radius_m;
        let segments: Vec<Segment> = (0..n)
            .map(|k| {
                let (a, b) = (pts[k], pts[next(k)]);
                if !surface[k] {
                    return Segment { a, b, line: None };
                }
                let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
                let near = |i: usize| {
                    let d = [pts[i][0] - mid[0], pts[i][1] - mid[1]];
                    dot(d, d) <= radius * radius
                };
                // Neighbours on the same surface, outwards from each end; at most n points in
                // all, so that a small closed scan takes no point twice.
                let mut before = 0;
                let mut i = k;
                while before < MAX_FIT_SIDE && before + 2 < n && surface[prev(i)] && near(prev(i)) {
                    i = prev(i);
                    before += 1;
                }
                let mut after = 0;
                let mut j = next(k);
                while after < MAX_FIT_SIDE && before + after + 2 < n && surface[j] && near(next(j))
                {
                    j = next(j);
                    after += 1;
                }
                let first = (k + n - before) % n;
                let fitted = (0..before + after + 2).map(|o| pts[(first + o) % n]);
                Segment {
                    a,
                    b,
                    line: Line::fit(fitted),
                }
            })
            .collect();
        let surfaces = segments.iter().filter(|s| s.line.is_some()).count();
        Self {
            bearing,
            unit,
            segments,
            surfaces,
        }
    }

    /// Usable points.
    pub fn points(&self) -> usize {
        self.bearing.len()
    }

    /// Segments that are surfaces.
    pub fn surfaces(&self) -> usize {
        self.surfaces
    }

    /// The line of the surface segment nearest `q`, and `q`'s distance to that segment, if one
    /// is nearer than `gate` metres.
    pub fn nearest(&self, q: [f64; 2], gate: f64) -> Option<(&Line, f64)> {
        let n = self.segments.len();
        if n == 0 || self.surfaces == 0 {
            return None;
        }
        let rho = dot(q, q).sqrt();
        let mut best: Option<&Line> = None;
        let mut best_d2 = gate * gate;
        let mut try_segment = |k: usize, best_d2: &mut f64| {
            let s = &self.segments[k];
            if let Some(line) = &s.line {
                let d2 = segment_distance2(q, s.a, s.b);
                if d2 < *best_d2 {
                    *best_d2 = d2;
                    best = Some(line);
                }
            }
        };
        // The lower bound on the distance to segments beyond bearing `u`, given `c`, `q`'s
        // cross product with `u` taken in the walk's direction; `None` past a half turn.
        let bound = |u: [f64; 2], c: f64| {
            let d = dot(q, u);
            if d > 0.0 {
                // Within a quarter turn; a slightly negative c is rounding at the same bearing.
                Some(c.abs())
            } else if c >= 0.0 {
                Some(rho)
            } else {
                None
            }
        };
        // The segment whose wedge holds q's bearing (the closing one when q is before the first
        // bearing or after the last).
        let phi = pseudo_angle(q);
        let pos = self.bearing.partition_point(|&b| b <= phi);
        let k0 = (pos + n - 1) % n;
        try_segment(k0, &mut best_d2);
        // Counter-clockwise: segment k starts at bearing k.
        let mut k = k0;
        for _ in 1..n {
            k = (k + 1) % n;
            let u = self.unit[k];
            match bound(u, cross(q, u)) {
                Some(b) if b * b < best_d2 => try_segment(k, &mut best_d2),
                _ => break,
            }
        }
        // Clockwise: segment k ends at bearing k + 1.
        let mut k = k0;
        for _ in 1..n {
            k = (k + n - 1) % n;
            let u = self.unit[(k + 1) % n];
            match bound(u, cross(u, q)) {
                Some(b) if b * b < best_d2 => try_segment(k, &mut best_d2),
                _ => break,
            }
        }
        best.map(|line| (line, best_d2.sqrt()))
    }
}

/// Squared distance from `q` to the segment from `a` to `b`.
fn segment_distance2(q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let u = [b[0] - a[0], b[1] - a[1]];
    let w = [q[0] - a[0], q[1] - a[1]];
    let len2 = dot(u, u);
    let t = if len2 > 0.0 {
        (dot(w, u) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e = [w[0] - t * u[0], w[1] - t * u[1]];
    dot(e, e)
}
#[cfg(test)]
mod tests {
    use super::*;

    const RULES: Surfaces = Surfaces {
        jump_m: 0.2,
        jump_fraction: 0.05,
        fit_radius_m: 0.0,
    };

    #[test]
    fn the_pseudo_angle_grows_with_the_bearing() {
        let keys: Vec<f64> = (0..3600)
            .map(|i| {
                let a = f64::from(i) * std::f64::consts::TAU / 3600.0;
                pseudo_angle([3.0 * a.cos(), 3.0 * a.sin()])
            })
            .collect();
        assert!(keys.windows(2).all(|w| w[0] < w[1]), "not increasing");
        assert!(keys[0] == 0.0 && keys[3599] < 4.0);
    }

    /// A closed polyline of points around the lidar with random-looking ranges.
    fn cloud(n: usize) -> Vec<[f64; 2]> {
        (0..n)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / n as f64;
                let r = 2.0 + 0.3 * (7.0 * a).sin() + 0.1 * (31.0 * a).cos();
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    /// The nearest surface segment by trying them all.
    fn brute(reference: &Reference, q: [f64; 2], gate: f64) -> Option<f64> {
        reference
            .segments
            .iter()
            .filter(|s| s.line.is_some())
            .map(|s| segment_distance2(q, s.a, s.b).sqrt())
            .filter(|d| *d < gate)
            .min_by(f64::total_cmp)
    }

    #[test]
    fn angular_search_finds_the_same_segment_as_trying_all() {
        let reference = Reference::new(&cloud(360), RULES);
        assert_eq!(reference.surfaces(), 360);
        for i in 0..2000 {
            let a = i as f64 * 0.0137;
            let r = 0.05 + (i % 97) as f64 * 0.05;
            let q = [r * a.cos(), r * a.sin()];
            for gate in [0.05, 0.3, 10.0] {
                let fast = reference.nearest(q, gate).map(|(_, d)| d);
                assert_eq!(fast, brute(&reference, q, gate), "q {q:?} gate {gate}");
            }
        }
    }

    #[test]
    fn a_jump_between_neighbours_is_no_surface() {
        // Two walls at 1 m and 3 m: the step between them is longer than 0.2 m + 5 % of 3 m.
        let mut points: Vec<[f64; 2]> = (0..10).map(|i| [1.0, -0.2 + 0.02 * i as f64]).collect();
        points.extend((0..10).map(|i| [3.0, 0.01 + 0.06 * i as f64]));
        let reference = Reference::new(&points, RULES);
        // 9 + 9 segments along the walls; the jump and the closing segment are not surfaces.
        assert_eq!(reference.surfaces(), 18);
    }

    #[test]
    fn duplicate_points_make_no_segment_of_their_own() {
        let points = [[1.0, 0.0], [1.0, 0.0], [1.0, 0.05], [1.0, 0.1]];
        let reference = Reference::new(&points, RULES);
        assert_eq!(reference.surfaces(), 2);
        let (line, d) = reference.nearest([1.1, 0.02], 1.0).expect("a segment");
        assert!((d - 0.1).abs() < 1e-12);
        assert!((line.normal[0].abs() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_fitted_line_averages_the_neighbours() {
        // A straight wall with alternating ±5 mm offsets: the two-point segments tilt, the fit
        // over 0.1 m does not.
        let points: Vec<[f64; 2]> = (0..20)
            .map(|i| {
                [
                    2.0 + if i % 2 == 0 { 0.005 } else { -0.005 },
                    -0.2 + 0.02 * i as f64,
                ]
            })
            .collect();
        let fitted = Reference::new(
            &points,
            Surfaces {
                fit_radius_m: 0.1,
                ..RULES
            },
        );
        let (line, _) = fitted.nearest([2.0, 0.01], 1.0).expect("a segment");
        assert!(line.normal[1].abs() < 0.03, "normal {:?}", line.normal);
        let bare = Reference::new(&points, RULES);
        let (line, _) = bare.nearest([2.0, 0.01], 1.0).expect("a segment");
        assert!(line.normal[1].abs() > 0.3, "normal {:?}", line.normal);
    }
}
