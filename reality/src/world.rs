//! The world as this generator sees it: line segments (walls, the four faces of each board) and
//! circles (cylinders), each with its reflectivity, and rays cast against them.

use hilsim_sim::scenario::Scenario;

/// Reflectivity of an obstacle that names no material (the scenario format's `default`).
const DEFAULT_REFLECTIVITY: f64 = 0.8;

#[derive(Debug, Clone, Copy)]
enum Shape {
    Segment { a: [f64; 2], b: [f64; 2] },
    Circle { centre: [f64; 2], radius: f64 },
}

#[derive(Debug, Clone, Copy)]
struct Surface {
    shape: Shape,
    reflectivity: f64,
}

/// Where a ray meets the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray, metres.
    pub range_m: f64,
    /// Angle between the ray and the surface normal, radians (0: head-on).
    pub incidence_rad: f64,
    /// The surface's reflectivity.
    pub reflectivity: f64,
}

/// How the world differs from the scenario's (a few millimetres: the nuisance "the world a
/// few mm off").
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WorldOffsets {
    /// The first wall is moved along its normal by this much, metres.
    pub wall_shift_m: f64,
    /// Every cylinder's radius grows by this much, metres.
    pub radius_change_m: f64,
}

/// The obstacles.
#[derive(Debug, Clone)]
pub struct World {
    surfaces: Vec<Surface>,
}

impl World {
    /// The scenario's world, moved by `offsets`.
    #[must_use]
    pub fn new(scenario: &Scenario, offsets: WorldOffsets) -> Self {
        let w = &scenario.world;
        let rho = |m: &Option<String>| {
            m.as_ref()
                .and_then(|name| w.materials.get(name))
                .map_or(DEFAULT_REFLECTIVITY, |m| m.reflectivity)
        };
        let mut surfaces = Vec::new();
        for (i, wall) in w.walls.iter().enumerate() {
            let (mut a, mut b) = (wall.from, wall.to);
            if i == 0 {
                let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
                let len = dx.hypot(dy).max(1e-12);
                let n = [-dy / len, dx / len];
                for p in [&mut a, &mut b] {
                    p[0] += n[0] * offsets.wall_shift_m;
                    p[1] += n[1] * offsets.wall_shift_m;
                }
            }
            surfaces.push(Surface {
                shape: Shape::Segment { a, b },
                reflectivity: rho(&wall.material),
            });
        }
        for c in &w.cylinders {
            surfaces.push(Surface {
                shape: Shape::Circle {
                    centre: c.center,
                    radius: (c.radius + offsets.radius_change_m).max(1e-3),
                },
                reflectivity: rho(&c.material),
            });
        }
        for board in &w.boards {
            // A rectangle: `length` along yaw, `thickness` across it.
            let (s, c) = board.yaw_deg.to_radians().sin_cos();
            let (hl, ht) = (board.length / 2.0, board.thickness / 2.0);
            let corner = |u: f64, v: f64| {
                [
                    board.center[0] + u * c - v * s,
                    board.center[1] + u * s + v * c,
                ]
            };
            let corners = [
                corner(-hl, -ht),
                corner(hl, -ht),
                corner(hl, ht),
                corner(-hl, ht),
            ];
            for k in 0..4 {
                surfaces.push(Surface {
                    shape: Shape::Segment {
                        a: corners[k],
                        b: corners[(k + 1) % 4],
                    },
                    reflectivity: rho(&board.material),
                });
            }
        }
        Self { surfaces }
    }

    /// The nearest surface along the ray from `origin` in direction `heading_rad`, within
    /// `max_m`.
    #[must_use]
    pub fn cast(&self, origin: [f64; 2], heading_rad: f64, max_m: f64) -> Option<Hit> {
        let d = [heading_rad.cos(), heading_rad.sin()];
        let mut best: Option<Hit> = None;
        for s in &self.surfaces {
            let hit = match s.shape {
                Shape::Segment { a, b } => segment(origin, d, a, b),
                Shape::Circle { centre, radius } => circle(origin, d, centre, radius),
            };
            if let Some((t, normal)) = hit {
                if t <= max_m && best.is_none_or(|h| t < h.range_m) {
                    let cos = (d[0] * normal[0] + d[1] * normal[1]).abs().min(1.0);
                    best = Some(Hit {
                        range_m: t,
                        incidence_rad: cos.acos(),
                        reflectivity: s.reflectivity,
                    });
                }
            }
        }
        best
    }
}

/// Ray `o + t d` (t > 0) against segment `a b`: the distance and the segment's unit normal.
fn segment(o: [f64; 2], d: [f64; 2], a: [f64; 2], b: [f64; 2]) -> Option<(f64, [f64; 2])> {
    let e = [b[0] - a[0], b[1] - a[1]];
    let denom = d[0] * e[1] - d[1] * e[0];
    if denom.abs() < 1e-12 {
        return None;
    }
    let w = [a[0] - o[0], a[1] - o[1]];
    let t = (w[0] * e[1] - w[1] * e[0]) / denom;
    let u = (w[0] * d[1] - w[1] * d[0]) / denom;
    if t > 1e-9 && (0.0..=1.0).contains(&u) {
        let len = e[0].hypot(e[1]);
        Some((t, [-e[1] / len, e[0] / len]))
    } else {
        None
    }
}

/// Ray `o + t d` (t > 0, |d| = 1) against a circle from outside: the distance and the normal.
fn circle(o: [f64; 2], d: [f64; 2], c: [f64; 2], r: f64) -> Option<(f64, [f64; 2])> {
    let w = [o[0] - c[0], o[1] - c[1]];
    let b = w[0] * d[0] + w[1] * d[1];
    let cc = w[0] * w[0] + w[1] * w[1] - r * r;
    let disc = b * b - cc;
    if disc < 0.0 || cc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    if t <= 1e-9 {
        return None;
    }
    let p = [o[0] + t * d[0] - c[0], o[1] + t * d[1] - c[1]];
    Some((t, [p[0] / r, p[1] / r]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_meet_a_segment_and_a_circle_where_geometry_says() {
        let (t, n) = segment([0.0, 0.0], [1.0, 0.0], [2.0, -1.0], [2.0, 1.0]).unwrap();
        assert!((t - 2.0).abs() < 1e-12 && n[0].abs() > 0.999);
        assert!(segment([0.0, 0.0], [-1.0, 0.0], [2.0, -1.0], [2.0, 1.0]).is_none());
        let (t, _) = circle([0.0, 0.0], [1.0, 0.0], [3.0, 0.0], 0.5).unwrap();
        assert!((t - 2.5).abs() < 1e-12);
        assert!(circle([0.0, 0.0], [0.0, 1.0], [3.0, 0.0], 0.5).is_none());
    }
}
