//! A scenario's world drawn as an occupancy map: what a SLAM map of the room would hold, to
//! test a diagnosis against a map that is only as exact as its cells.

use hilsim_sim::occupancy::{Cell, MapError, OccupancyMap};
use hilsim_sim::Scenario;

/// Cells beyond the world's shapes on every side, so that the walls' outer faces are in the map.
const BORDER_CELLS: f64 = 4.0;

/// The scenario's walls, cylinders and boards as an occupancy map of `resolution_m` cells, each
/// shape moved `offset_m` along its outward normal (walls away from the world's centre,
/// cylinders and boards grown): a cell is occupied when a shape's outline passes through it or
/// its centre lies inside a cylinder or a board; every other cell is free.
///
/// # Errors
/// The map would exceed [`hilsim_sim::occupancy::MAX_CELLS`], or the resolution is not positive.
pub fn map_of_world(
    scenario: &Scenario,
    resolution_m: f64,
    offset_m: f64,
) -> Result<OccupancyMap, MapError> {
    let w = &scenario.world;
    let mut outlines: Vec<Vec<[f64; 2]>> = Vec::new();
    let points: Vec<[f64; 2]> = w
        .walls
        .iter()
        .flat_map(|wall| [wall.from, wall.to])
        .chain(w.cylinders.iter().map(|c| c.center))
        .chain(w.boards.iter().map(|b| b.center))
        .collect();
    let centre = if points.is_empty() {
        [0.0, 0.0]
    } else {
        let n = points.len() as f64;
        [0, 1].map(|a| points.iter().map(|p| p[a]).sum::<f64>() / n)
    };
    for wall in &w.walls {
        let (a, b) = (wall.from, wall.to);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy).max(1e-12);
        let mut normal = [dy / len, -dx / len];
        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        if normal[0] * (mid[0] - centre[0]) + normal[1] * (mid[1] - centre[1]) < 0.0 {
            normal = [-normal[0], -normal[1]];
        }
        let shift = |p: [f64; 2]| [p[0] + normal[0] * offset_m, p[1] + normal[1] * offset_m];
        outlines.push(vec![shift(a), shift(b)]);
    }
    let mut discs = Vec::new();
    for c in &w.cylinders {
        let r = c.radius + offset_m;
        let n = 64;
        outlines.push(
            (0..=n)
                .map(|k| {
                    let a = std::f64::consts::TAU * f64::from(k) / f64::from(n);
                    [c.center[0] + r * a.cos(), c.center[1] + r * a.sin()]
                })
                .collect(),
        );
        discs.push((c.center, r));
    }
    let mut boxes = Vec::new();
    for b in &w.boards {
        let (sin, cos) = b.yaw_deg.to_radians().sin_cos();
        let (hl, ht) = (b.length / 2.0 + offset_m, b.thickness / 2.0 + offset_m);
        let corner = |u: f64, v: f64| {
            [
                b.center[0] + cos * u - sin * v,
                b.center[1] + sin * u + cos * v,
            ]
        };
        outlines.push(vec![
            corner(-hl, -ht),
            corner(hl, -ht),
            corner(hl, ht),
            corner(-hl, ht),
            corner(-hl, -ht),
        ]);
        boxes.push((b.center, [cos, sin], [hl, ht]));
    }
    let all: Vec<[f64; 2]> = outlines.iter().flatten().copied().collect();
    let (lo, hi) = all.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        },
    );
    let (lo, hi) = if all.is_empty() {
        ([0.0; 2], [0.0; 2])
    } else {
        (lo, hi)
    };
    let border = BORDER_CELLS * resolution_m;
    let origin = [lo[0] - border, lo[1] - border];
    let cells = |a: usize| ((hi[a] - lo[a] + 2.0 * border) / resolution_m).ceil() as usize;
    let mut map = OccupancyMap::new(resolution_m, origin, cells(0).max(1), cells(1).max(1))?;
    let (width, height) = map.size();
    for iy in 0..height {
        for ix in 0..width {
            let p = [
                origin[0] + (ix as f64 + 0.5) * resolution_m,
                origin[1] + (iy as f64 + 0.5) * resolution_m,
            ];
            let inside = discs
                .iter()
                .any(|(c, r)| (p[0] - c[0]).hypot(p[1] - c[1]) <= *r)
                || boxes.iter().any(|(c, [cos, sin], [hl, ht])| {
                    let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
                    (cos * dx + sin * dy).abs() <= *hl && (-sin * dx + cos * dy).abs() <= *ht
                });
            map.set_cell(ix, iy, if inside { Cell::Occupied } else { Cell::Free });
        }
    }
    // Each outline walked in steps of a quarter cell: every cell it passes through.
    for outline in &outlines {
        for pair in outline.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            let steps = (len / (resolution_m / 4.0)).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let u = k as f64 / steps as f64;
                let p = [a[0] + (b[0] - a[0]) * u, a[1] + (b[1] - a[1]) * u];
                if let Some((ix, iy)) = map.cell_index(p) {
                    map.set_cell(ix, iy, Cell::Occupied);
                }
            }
        }
    }
    Ok(map)
}
