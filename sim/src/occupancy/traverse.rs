//! The cells a ray crosses, in order: Amanatides & Woo, "A fast voxel traversal algorithm for
//! ray tracing", Eurographics 1987. Each step crosses the nearer of the next vertical and the
//! next horizontal cell boundary; the distance to each is kept exactly (`first + k · delta`, not
//! a running sum) so that it does not drift over thousands of cells.

/// A ray's walk through a lattice of square cells of side `r` whose cell `(0, 0)` has its
/// lower-left corner at the frame's origin.
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
