//! Casting a ray into the map: the first occupied cell along it, and the surface's normal there.

use super::traverse::Traversal;
use super::OccupancyMap;

/// A ray's first occupied cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapHit {
    /// Distance from the ray's origin to where it enters the cell, metres.
    pub distance_m: f64,
    /// Distance from the ray's origin to the surface inside the cell, metres: where the ray
    /// meets the line through the centres of the surface's first occupied cells (the faces the
    /// normal is fitted to, moved half a cell's depth into them); without a clear surface, the
    /// nearest the ray comes to the cell's centre. Within the cell: from `distance_m` to where
    /// the ray leaves it. A map built from scans puts a wall's cells where its hits fell, so its
    /// surface runs through their centres on average; the entry is half a cell short of it.
    pub surface_m: f64,
    /// The surface's normal at the hit: unit, world frame, facing the ray's origin.
    pub normal: [f64; 2],
}

/// How far from the hit cell the normal's fit looks, in cells: a 7 × 7 window holds about
/// fourteen faces of a rasterised line, enough to give its direction within 5° (4.8° the worst
/// of `tests/occupancy_rays.rs`'s walls; 13° with a 5 × 5 window, 3.5° with 9 × 9), and little
/// enough of a corner or a curve to still see one surface.
const NORMAL_RADIUS_CELLS: i64 = 3;

/// The faces' spread across their principal axis, as a fraction of the spread along it, above
/// which they have no clear axis (a corner, a blob): a rasterised straight line's face
/// midpoints spread a fraction of a cell² across it against several cells² along it; an L of
/// two equal arms or a square blob's ratio is 1.
const AXIS_RATIO: f64 = 0.25;

impl OccupancyMap {
    /// The first occupied cell along the ray from `origin` (world metres) along `dir` (made unit
    /// here), within `max_m`: the distance to where the ray enters that cell, exact at cell
    /// boundaries (Amanatides & Woo's traversal, see `traverse.rs`). Free and unknown cells,
    /// and everything outside the map, let the ray pass.
    ///
    /// A ray that passes exactly through a corner touches the two cells beside it: either one
    /// occupied stops it there, so a one-pixel diagonal wall has no gaps. A ray along a grid
    /// line travels in the cells above or to the right of it.
    ///
    /// A ray that starts in an occupied cell skips the occupied cells it is in before it first
    /// reaches a free or unknown one, so a lidar that a map's rounding puts on a wall pixel still
    /// sees out (a robot inside a wall is the map's error, not something to report as a hit at
    /// 0 m).
    ///
    /// The normal is fitted to the surface near the hit: the principal axis of the midpoints of
    /// the faces between occupied cells and the open (free or unknown) cells on the ray's side
    /// (those 4-connected to the cell the ray came from) within three cells of the hit is the
    /// surface's direction, and the normal is perpendicular to it, facing the ray's origin. With
    /// fewer than three faces or no clear axis (a lone cell, a corner, a blob) it is the normal
    /// of the cell face the ray entered through.
    ///
    /// `None` when nothing is hit within `max_m`, or for a direction of zero length or a value
    /// that is not finite.
    #[must_use]
    pub fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<MapHit> {
        let norm = dir[0].hypot(dir[1]);
        let usable =
            norm > 0.0 && norm.is_finite() && origin.iter().all(|v| v.is_finite()) && max_m >= 0.0;
        if !usable {
            return None;
        }
        let d = [dir[0] / norm, dir[1] / norm];
        let r = self.resolution_m;
        let mut p = [origin[0] - self.origin[0], origin[1] - self.origin[1]];
        let extent = [self.width as f64 * r, self.height as f64 * r];
        let (t0, entry_axis) = enter(p, d, extent)?;
        if t0 > max_m {
            return None;
        }
        if let Some(a) = entry_axis {
            // Start on the map's edge exactly, so that rounding cannot put the first cell
            // outside it.
            p = [p[0] + d[0] * t0, p[1] + d[1] * t0];
            p[a] = if d[a] > 0.0 { 0.0 } else { extent[a] };
            let b = 1 - a;
            p[b] = p[b].clamp(0.0, extent[b]);
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let mut tr = Traversal::new(p, d, r);
        let step = tr.step();
        let mut t = t0;
        let mut face = entry_axis;
        let mut skipping = entry_axis.is_none();
        loop {
            let [cx, cy] = tr.cell;
            if cx < 0 || cy < 0 || cx >= w || cy >= h {
                return None;
            }
            if self.is_occupied(cx, cy) {
                if !skipping {
                    let (exit, _, _) = tr.exit();
                    return Some(self.hit(origin, [t, t0 + exit], tr.cell, face, d));
                }
            } else {
                skipping = false;
            }
            // Open cells all around: cross them in one leap (the cells, corners and distances
            // the steps below would give).
            let open = if skipping {
                0
            } else {
                self.tables.open_radius(self, tr.cell)
            };
            if open >= 2 {
                let (last, axis, corner) = tr.leap(open);
                let exit = t0 + last;
                if exit > max_m {
                    return None;
                }
                face = Some(if corner {
                    usize::from(d[1].abs() > d[0].abs())
                } else {
                    axis
                });
                t = exit;
                continue;
            }
            let (exit, axis, corner) = tr.exit();
            let exit = t0 + exit;
            if exit > max_m {
                return None;
            }
            if corner {
                if !skipping {
                    for a in 0..2 {
                        let mut beside = tr.cell;
                        beside[a] += step[a];
                        if self.is_occupied(beside[0], beside[1]) {
                            // A corner's cell is touched at a point: its surface is there.
                            return Some(self.hit(origin, [exit, exit], beside, Some(a), d));
                        }
                    }
                }
                tr.cross(0);
                tr.cross(1);
                face = Some(usize::from(d[1].abs() > d[0].abs()));
            } else {
                tr.cross(axis);
                face = Some(axis);
            }
            t = exit;
        }
    }

    /// The hit on `cell`, entered at `span[0]` across the boundary of axis `face` and left at
    /// `span[1]`, of a ray from `origin` (world) along `d`.
    fn hit(
        &self,
        origin: [f64; 2],
        span: [f64; 2],
        cell: [i64; 2],
        face: Option<usize>,
        d: [f64; 2],
    ) -> MapHit {
        let face_normal = match face {
            Some(0) => [-d[0].signum(), 0.0],
            Some(_) => [0.0, -d[1].signum()],
            None => [-d[0], -d[1]],
        };
        // The open cell the ray came from, across the face it entered through.
        let from = match face {
            Some(a) => {
                let mut from = cell;
                from[a] -= if d[a] > 0.0 { 1 } else { -1 };
                from
            }
            None => cell,
        };
        let r = self.resolution_m;
        // A point (cells from the hit cell's centre) relative to the ray's origin, metres.
        let at = |offset: [f64; 2]| {
            [0, 1].map(|a| self.origin[a] + (cell[a] as f64 + 0.5 + offset[a]) * r - origin[a])
        };
        let fit = self.tables.fit(self, cell, from);
        let (normal, surface) = match fit.map(|(axis, faces)| (facing(axis, d), faces)) {
            Some((n, faces)) => {
                // The faces' line moved into the cells: by half a cell across an axis-aligned
                // wall, by a third of the diagonal's half (0.35 cell) across a 45° staircase.
                let depth = 0.5 * n[0].abs().max(n[1].abs());
                let p = at([faces[0] - depth * n[0], faces[1] - depth * n[1]]);
                let along = n[0] * d[0] + n[1] * d[1];
                let t = (n[0] * p[0] + n[1] * p[1]) / along;
                (n, if along < 0.0 { t } else { span[0] })
            }
            None => {
                let c = at([0.0, 0.0]);
                (face_normal, c[0] * d[0] + c[1] * d[1])
            }
        };
        let entry = span[0].max(0.0);
        MapHit {
            distance_m: entry,
            normal,
            surface_m: if surface.is_finite() {
                surface.clamp(entry, span[1].max(entry))
            } else {
                entry
            },
        }
    }

    /// A normal of the surface the ray hit at `cell`, entered from the open cell `from` (either
    /// of its two signs; [`facing`] turns it towards the ray): the perpendicular of the
    /// principal axis of the midpoints of the faces between occupied cells and the open cells
    /// that `from` reaches (4-connected) within the window around `cell`, which are the ray's
    /// side of the surface (a thick wall's far side is out of reach, and so is a thin diagonal
    /// wall's, which 4-connected open cells cannot cross).
    /// Also the faces' centroid, cells from the hit cell's centre.
    pub(super) fn fitted_normal(
        &self,
        cell: [i64; 2],
        from: [i64; 2],
    ) -> Option<([f64; 2], [f64; 2])> {
        const SIDE: usize = 2 * NORMAL_RADIUS_CELLS as usize + 1;
        let local = |c: [i64; 2]| -> Option<usize> {
            let (x, y) = (
                c[0] - cell[0] + NORMAL_RADIUS_CELLS,
                c[1] - cell[1] + NORMAL_RADIUS_CELLS,
            );
            (0..SIDE as i64)
                .contains(&x)
                .then_some(())
                .filter(|()| (0..SIDE as i64).contains(&y))
                .map(|()| y as usize * SIDE + x as usize)
        };
        let mut reached = [false; SIDE * SIDE];
        let mut stack = Vec::with_capacity(SIDE * SIDE);
        if let Some(i) = local(from).filter(|_| !self.is_occupied(from[0], from[1])) {
            reached[i] = true;
            stack.push(from);
        }
        let (mut n, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        while let Some(c) = stack.pop() {
            for step in [[1, 0], [-1, 0], [0, 1], [0, -1]] {
                let next = [c[0] + step[0], c[1] + step[1]];
                let Some(i) = local(next) else {
                    continue;
                };
                if self.is_occupied(next[0], next[1]) {
                    // The face between them, relative to the hit cell's centre.
                    let fx = (c[0] - cell[0]) as f64 + 0.5 * step[0] as f64;
                    let fy = (c[1] - cell[1]) as f64 + 0.5 * step[1] as f64;
                    n += 1.0;
                    sx += fx;
                    sy += fy;
                    sxx += fx * fx;
                    syy += fy * fy;
                    sxy += fx * fy;
                } else if !reached[i] {
                    reached[i] = true;
                    stack.push(next);
                }
            }
        }
        if n < 3.0 {
            return None;
        }
        let (mx, my) = (sx / n, sy / n);
        let (cxx, cyy, cxy) = (sxx / n - mx * mx, syy / n - my * my, sxy / n - mx * my);
        let mean = 0.5 * (cxx + cyy);
        let root = (0.5 * (cxx - cyy)).hypot(cxy);
        let (major, minor) = (mean + root, mean - root);
        if !(major > 0.0 && minor <= AXIS_RATIO * major) {
            return None;
        }
        let along = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
        let (sin, cos) = along.sin_cos();
        Some(([-sin, cos], [mx, my]))
    }
}

/// `normal` or its opposite, whichever faces a ray along `d`.
fn facing(normal: [f64; 2], d: [f64; 2]) -> [f64; 2] {
    if normal[0] * d[0] + normal[1] * d[1] > 0.0 {
        [-normal[0], -normal[1]]
    } else {
        normal
    }
}

/// Where a ray from `p` along `d` enters the rectangle `[0, extent]` (slab method): `t = 0` and
/// no axis when `p` is inside, else the distance and the axis of the side it enters through;
/// `None` when it misses (or only touches an edge or a corner).
fn enter(p: [f64; 2], d: [f64; 2], extent: [f64; 2]) -> Option<(f64, Option<usize>)> {
    let (mut t_in, mut axis, mut t_out) = (0.0, None, f64::INFINITY);
    for a in 0..2 {
        if d[a] == 0.0 {
            if !(p[a] >= 0.0 && p[a] < extent[a]) {
                return None;
            }
            continue;
        }
        let (t1, t2) = ((0.0 - p[a]) / d[a], (extent[a] - p[a]) / d[a]);
        let (lo, hi) = (t1.min(t2), t1.max(t2));
        if lo > t_in {
            t_in = lo;
            axis = Some(a);
        }
        t_out = t_out.min(hi);
    }
    (t_in < t_out).then_some((t_in, axis))
}
