//! Casting a ray into the map: the first occupied cell along it, and the surface's normal there.

use super::traverse::Traversal;
use super::OccupancyMap;

/// A ray's first occupied cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapHit {
    /// Distance from the ray's origin to where it enters the cell, metres.
    pub distance_m: f64,
    /// Distance from the ray's origin to the surface inside the cell, metres: where the ray
    /// meets the line through the centres of the occupied cells near the hit (the surface the
    /// normal is fitted to); without a clear surface, the nearest the ray comes to the cell's
    /// centre. Within the cell: from `distance_m` to where the ray leaves it. A map built from
    /// scans puts a wall's cells where its hits fell, so its surface runs through their centres
    /// on average; the entry is half a cell short of it.
    pub surface_m: f64,
    /// The surface's normal at the hit: unit, world frame, facing the ray's origin.
    pub normal: [f64; 2],
}

/// How far from the hit cell the normal's fit looks, in cells: a 5 × 5 window holds five cells
/// of a rasterised line, enough to give its direction within a few degrees, and little enough of
/// a corner or a curve to still see one surface.
const NORMAL_RADIUS_CELLS: i64 = 2;

/// The cells' spread across their principal axis, as a fraction of the spread along it, above
/// which they have no clear axis (a blob, a corner): a rasterised straight line's cells spread
/// `1/12` of a cell² across it against `2` along it in a 5 × 5 window (ratio ≈ 0.04, at most
/// ≈ 0.15 for the worst rounding); a square blob's ratio is 1.
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
    /// The normal is fitted to the cells near the hit (see [`MapHit::normal`]): the principal
    /// axis of the centres of the occupied cells within two cells of it that face the ray (have
    /// a free or unknown neighbour on the ray's side) is the surface's direction, and the normal
    /// is perpendicular to it. With fewer than three such cells or no clear axis (a lone cell, a
    /// corner, a blob) it is the normal of the cell face the ray entered through.
    ///
    /// `None` when nothing is hit within `max_m`, or for a direction of zero length or a value
    /// that is not finite.
    #[must_use]
    pub fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<MapHit> {
        let norm = dir[0].hypot(dir[1]);
        if !(norm > 0.0 && norm.is_finite() && origin.iter().all(|v| v.is_finite()))
            || !(max_m >= 0.0)
        {
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
        let r = self.resolution_m;
        let centre_of = |offset: [f64; 2]| {
            [0, 1].map(|a| self.origin[a] + (cell[a] as f64 + 0.5 + offset[a]) * r - origin[a])
        };
        let (normal, surface) = match self.fitted_normal(cell, d) {
            Some((normal, offset)) => {
                let c = centre_of(offset);
                let along = normal[0] * d[0] + normal[1] * d[1];
                let t = (normal[0] * c[0] + normal[1] * c[1]) / along;
                (normal, if along < 0.0 { t } else { span[0] })
            }
            None => {
                let c = centre_of([0.0, 0.0]);
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

    /// The normal of the line through the occupied cells near `cell` that face a ray along `d`,
    /// when they have a clear principal axis, and their centroid's offset from `cell`, cells.
    fn fitted_normal(&self, cell: [i64; 2], d: [f64; 2]) -> Option<([f64; 2], [f64; 2])> {
        let back = d.map(|v| {
            if v > 0.0 {
                -1
            } else if v < 0.0 {
                1
            } else {
                0
            }
        });
        let (mut n, mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for dy in -NORMAL_RADIUS_CELLS..=NORMAL_RADIUS_CELLS {
            for dx in -NORMAL_RADIUS_CELLS..=NORMAL_RADIUS_CELLS {
                let (x, y) = (cell[0] + dx, cell[1] + dy);
                if !self.is_occupied(x, y) {
                    continue;
                }
                let faces_ray = (back[0] != 0 && !self.is_occupied(x + back[0], y))
                    || (back[1] != 0 && !self.is_occupied(x, y + back[1]));
                if !faces_ray {
                    continue;
                }
                let (fx, fy) = (dx as f64, dy as f64);
                n += 1.0;
                sx += fx;
                sy += fy;
                sxx += fx * fx;
                syy += fy * fy;
                sxy += fx * fy;
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
        let normal = [-sin, cos];
        let facing = if normal[0] * d[0] + normal[1] * d[1] > 0.0 {
            [sin, -cos]
        } else {
            normal
        };
        Some((facing, [mx, my]))
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
