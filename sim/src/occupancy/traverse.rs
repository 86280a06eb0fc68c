//! The cells a ray crosses, in order: Amanatides & Woo, "A fast voxel traversal algorithm for
//! ray tracing", Eurographics 1987. Each step crosses the nearer of the next vertical and the
//! next horizontal cell boundary; the distance to each is kept exactly (`first + k · delta`, not
//! a running sum) so that it does not drift over thousands of cells.

/// A ray's walk through a lattice of square cells of side `r` whose cell `(0, 0)` has its
/// lower-left corner at the frame's origin.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Traversal {
    /// The cell the ray is in.
    pub cell: [i64; 2],
    step: [i64; 2],
    /// The ray's length across one cell along each axis (infinite along an axis it keeps to).
    delta: [f64; 2],
    /// Where the ray crosses its first boundary along each axis.
    first: [f64; 2],
    /// Boundaries crossed along each axis.
    crossed: [f64; 2],
    /// Where the ray crosses its next boundary along each axis.
    next: [f64; 2],
}

impl Traversal {
    /// Starts at `p` (metres, the lattice's frame) along the unit `d`. A point on a boundary is
    /// in the cell the ray goes into; a ray along a boundary line travels in the cells above or
    /// to the right of it.
    #[inline]
    pub fn new(p: [f64; 2], d: [f64; 2], r: f64) -> Self {
        let mut cell = [0; 2];
        let mut step = [0; 2];
        let mut delta = [f64::INFINITY; 2];
        let mut first = [f64::INFINITY; 2];
        for a in 0..2 {
            let g = p[a] / r;
            let mut c = g.floor();
            if g == c && d[a] < 0.0 {
                c -= 1.0;
            }
            cell[a] = c as i64;
            if d[a] > 0.0 {
                step[a] = 1;
                delta[a] = r / d[a];
                first[a] = ((c + 1.0) * r - p[a]) / d[a];
            } else if d[a] < 0.0 {
                step[a] = -1;
                delta[a] = -r / d[a];
                first[a] = (c * r - p[a]) / d[a];
            }
        }
        Self {
            cell,
            step,
            delta,
            first,
            crossed: [0.0; 2],
            next: first,
        }
    }

    /// The direction of travel along each axis (-1, 0 or 1).
    #[inline]
    pub fn step(&self) -> [i64; 2] {
        self.step
    }

    /// Where the ray leaves the current cell, and across which axis's boundary (0: a vertical
    /// one, 1: a horizontal one); `tie` when it leaves through a corner.
    #[inline]
    pub fn exit(&self) -> (f64, usize, bool) {
        let [x, y] = self.next;
        if x < y {
            (x, 0, false)
        } else if y < x {
            (y, 1, false)
        } else {
            (x, 0, true)
        }
    }

    /// Crosses at once every boundary the ray meets until it has crossed `k` (at least 1)
    /// along one axis, exactly as crossing them one at a time would (boundaries at the same
    /// distance together); the ray then has moved at most `k` cells along each axis. Returns
    /// where it crossed the last, across which axis's boundary, and whether that was a corner.
    pub fn leap(&mut self, k: u32) -> (f64, usize, bool) {
        let ahead = f64::from(k.max(1) - 1);
        let at = |a: usize, j: f64| self.first[a] + j * self.delta[a];
        let reach = [0, 1].map(|a| at(a, self.crossed[a] + ahead));
        let axis = usize::from(reach[1] < reach[0]);
        let until = reach[axis];
        let mut last = [f64::NEG_INFINITY; 2];
        for (a, last_a) in last.iter_mut().enumerate() {
            if self.next[a] > until || self.next[a].is_nan() {
                continue;
            }
            let most = self.crossed[a] + ahead;
            // The last boundary at or before `until`: guessed, then settled on the same
            // arithmetic as `cross`.
            let mut j = (self.crossed[a] + ((until - self.next[a]) / self.delta[a]).floor())
                .clamp(self.crossed[a], most);
            while j < most && at(a, j + 1.0) <= until {
                j += 1.0;
            }
            while j > self.crossed[a] && at(a, j) > until {
                j -= 1.0;
            }
            *last_a = at(a, j);
            let crossings = j - self.crossed[a] + 1.0;
            self.cell[a] += self.step[a] * crossings as i64;
            self.crossed[a] = j + 1.0;
            self.next[a] = at(a, self.crossed[a]);
        }
        (until, axis, last[0] == last[1])
    }

    /// Crosses the next boundary along `axis`.
    #[inline]
    pub fn cross(&mut self, axis: usize) {
        self.cell[axis] += self.step[axis];
        self.crossed[axis] += 1.0;
        self.next[axis] = self.first[axis] + self.crossed[axis] * self.delta[axis];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cells from `p` along `d` while the ray has gone less than `len`.
    fn cells(p: [f64; 2], d: [f64; 2], r: f64, len: f64) -> Vec<[i64; 2]> {
        let mut tr = Traversal::new(p, d, r);
        let mut out = vec![tr.cell];
        loop {
            let (t, axis, _) = tr.exit();
            if t >= len {
                return out;
            }
            tr.cross(axis);
            out.push(tr.cell);
        }
    }

    #[test]
    fn a_ray_along_an_axis_visits_each_cell_once() {
        assert_eq!(
            cells([0.5, 0.5], [1.0, 0.0], 1.0, 3.0),
            [[0, 0], [1, 0], [2, 0], [3, 0]]
        );
        assert_eq!(
            cells([0.5, 0.5], [0.0, -1.0], 1.0, 2.0),
            [[0, 0], [0, -1], [0, -2]]
        );
    }

    #[test]
    fn a_ray_starting_on_a_boundary_starts_in_the_cell_it_goes_into() {
        assert_eq!(cells([2.0, 0.5], [-1.0, 0.0], 1.0, 0.5), [[1, 0]]);
        assert_eq!(cells([2.0, 0.5], [1.0, 0.0], 1.0, 0.5), [[2, 0]]);
        // Along a grid line: the cells above it.
        assert_eq!(cells([0.5, 1.0], [1.0, 0.0], 1.0, 1.0), [[0, 1], [1, 1]]);
    }

    #[test]
    fn a_leap_ends_where_crossing_one_boundary_at_a_time_does() {
        // Directions at every angle (the axes and diagonals among them, whose corners tie),
        // from starts on and off the lattice.
        for i in 0..720 {
            let angle = f64::from(i) * std::f64::consts::PI / 360.0;
            let d = [angle.cos(), angle.sin()];
            for p in [[0.0, 0.0], [0.013, 0.29], [1.5, 0.75], [0.1, 0.1]] {
                for k in [1, 2, 5, 40] {
                    let mut leapt = Traversal::new(p, d, 0.05);
                    let mut stepped = leapt.clone();
                    for _ in 0..3 {
                        let (until, axis, corner) = leapt.leap(k);
                        let mut last = (f64::NAN, 0, false);
                        loop {
                            let (t, a, tie) = stepped.exit();
                            if t > until {
                                break;
                            }
                            if tie {
                                stepped.cross(0);
                                stepped.cross(1);
                            } else {
                                stepped.cross(a);
                            }
                            last = (t, a, tie);
                        }
                        assert_eq!(leapt, stepped, "angle {angle}, from {p:?}, k {k}");
                        assert_eq!(until, last.0);
                        assert_eq!(corner, last.2);
                        if !corner {
                            assert_eq!(axis, last.1);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn boundary_distances_do_not_drift_over_many_cells() {
        let d = [0.6, 0.8];
        let mut tr = Traversal::new([0.0, 0.0], d, 0.05);
        for _ in 0..100_000 {
            let (_, axis, _) = tr.exit();
            tr.cross(axis);
        }
        let (t, axis, _) = tr.exit();
        let exact = (tr.cell[axis] + 1) as f64 * 0.05 / d[axis];
        assert!((t - exact).abs() < 1e-9 * exact, "{t} vs {exact}");
    }
}
