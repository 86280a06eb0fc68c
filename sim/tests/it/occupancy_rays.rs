//! Rays cast into an occupancy map, and maps built from beams.

use std::f64::consts::PI;

use hilsim_sim::occupancy::{Cell, MapBuilder, OccupancyMap};

const R: f64 = 0.05;

/// A 10 m square map at 5 cm, corner at (-5, -5), all free.
fn free_map() -> OccupancyMap {
    let mut map = OccupancyMap::new(R, [-5.0, -5.0], 200, 200).unwrap();
    for iy in 0..200 {
        for ix in 0..200 {
            map.set_cell(ix, iy, Cell::Free);
        }
    }
    map
}

/// Occupies the cells of the line through `p` along the unit `u`, `thickness` cells deep
/// behind it (against `n`, the normal the rays see), rasterised one cell per column (or row,
/// for a steep line) as Bresenham's algorithm draws it.
fn draw_wall(map: &mut OccupancyMap, p: [f64; 2], u: [f64; 2], n: [f64; 2], thickness: usize) {
    let steep = u[1].abs() > u[0].abs();
    let (a, b) = if steep { (1, 0) } else { (0, 1) };
    for k in 0..200 {
        // Cell centre along the major axis, the line's coordinate on the other.
        let along = -5.0 + (k as f64 + 0.5) * R;
        let t = (along - p[a]) / u[a];
        let other = p[b] + t * u[b];
        for depth in 0..thickness {
            let other = other - n[b].signum() * depth as f64 * R;
            let mut xy = [0.0; 2];
            xy[a] = along;
            xy[b] = other;
            if let Some((ix, iy)) = map.cell_index(xy) {
                map.set_cell(ix, iy, Cell::Occupied);
            }
        }
    }
}

/// `a` is `b` but for rounding.
fn assert_near(a: [f64; 2], b: [f64; 2]) {
    assert!(
        (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12,
        "{a:?} vs {b:?}"
    );
}

fn angle_deg(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] * b[0] + a[1] * b[1])
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// The fitted normal's worst error on a rasterised line: its face midpoints are placed to
/// half a cell across a window of ±3 cells, which tilts a least-squares line by up to a few
/// degrees (4.8° measured over these walls and rays).
const MAX_TURN: f64 = 5.0;

#[test]
fn a_slanted_wall_is_hit_within_a_cell_diagonal_with_its_normal_within_a_few_degrees() {
    let diagonal = R * 2f64.sqrt();
    for wall_deg in [10.0, 30.0, 45.0, 60.0, 77.0, 120.0, 163.0] {
        for thickness in [1, 3] {
            let w: f64 = f64::to_radians(wall_deg);
            let u = [w.cos(), w.sin()];
            // The wall passes 0.013 m off the centre, so that it is on no grid line; rays come
            // from the side `n` points to.
            let n = [-u[1], u[0]];
            let p = [0.013 * n[0], 0.013 * n[1]];
            let mut map = free_map();
            draw_wall(&mut map, p, u, n, thickness);
            for origin_k in 0..5 {
                let s = -1.5 + 0.75 * origin_k as f64;
                let origin = [p[0] + 2.0 * n[0] + s * u[0], p[1] + 2.0 * n[1] + s * u[1]];
                // Rays within 45° of the wall's normal: at grazing incidence a half-cell step
                // of the rasterised line moves the hit along the ray by half a cell over the
                // sine of the incidence, more than the diagonal below 45°.
                for ray_k in -8..=8 {
                    let off = f64::to_radians(5.0 * ray_k as f64);
                    let base = (-n[1]).atan2(-n[0]) + off;
                    let d = [base.cos(), base.sin()];
                    // Exact: where the ray meets the line.
                    let exact = ((origin[0] - p[0]) * n[0] + (origin[1] - p[1]) * n[1])
                        / -(d[0] * n[0] + d[1] * n[1]);
                    let hit = map.cast_ray(origin, d, 10.0).expect("the wall is hit");
                    let error = (hit.distance_m - exact).abs();
                    let turn = angle_deg(hit.normal, n);
                    assert!(
                        error <= diagonal,
                        "wall {wall_deg}°×{thickness}, ray {off}: {} vs {exact}",
                        hit.distance_m
                    );
                    assert!(
                        turn <= MAX_TURN,
                        "wall {wall_deg}°×{thickness}, ray {off}: normal {:?} vs {n:?}",
                        hit.normal
                    );
                    assert!((hit.normal[0].hypot(hit.normal[1]) - 1.0).abs() < 1e-12);
                }
            }
        }
    }
}

#[test]
fn distances_are_exact_at_cell_boundaries_along_and_across_axes() {
    let mut map = free_map();
    // Column ix = 140: x in [2.0, 2.05).
    for iy in 0..200 {
        map.set_cell(140, iy, Cell::Occupied);
    }
    // Exact but for the rounding of the boundary's place, -5 + 140 · 0.05.
    let hit = map.cast_ray([0.0, 0.0], [1.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 2.0).abs() < 1e-12, "{}", hit.distance_m);
    assert_near(hit.normal, [-1.0, 0.0]);
    // From the far side, and starting exactly on a boundary, and along a grid line.
    let hit = map.cast_ray([4.0, 0.3], [-1.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 1.95).abs() < 1e-12, "{}", hit.distance_m);
    assert_near(hit.normal, [1.0, 0.0]);
    let hit = map.cast_ray([1.0, 0.05], [1.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 1.0).abs() < 1e-12);
    // Within range only: the hit at exactly max_m counts, short of it does not.
    assert!(map.cast_ray([0.0, 0.0], [1.0, 0.0], 2.0 + 1e-12).is_some());
    assert!(map.cast_ray([0.0, 0.0], [1.0, 0.0], 1.99).is_none());
    // Along the wall, never into it; away from it.
    assert!(map.cast_ray([0.0, 0.0], [0.0, 1.0], 10.0).is_none());
    assert!(map.cast_ray([0.0, 0.0], [-1.0, 0.0], 10.0).is_none());
    // A direction need not be unit.
    let hit = map.cast_ray([0.0, 0.0], [3.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 2.0).abs() < 1e-12);
}

#[test]
fn a_ray_from_outside_the_map_enters_it() {
    let mut map = free_map();
    map.set_cell(0, 100, Cell::Occupied);
    // From x = -7 along +x: the map begins at -5 and its first cell is the occupied one.
    let hit = map.cast_ray([-7.0, 0.01], [1.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 2.0).abs() < 1e-12);
    assert_eq!(hit.normal, [-1.0, 0.0]);
    assert!(map.cast_ray([-7.0, 0.01], [1.0, 0.0], 1.9).is_none());
    assert!(
        map.cast_ray([-7.0, 9.0], [1.0, 0.0], 100.0).is_none(),
        "passes above the map"
    );
    assert!(
        map.cast_ray([-7.0, 0.01], [-1.0, 0.0], 100.0).is_none(),
        "away from the map"
    );
}

#[test]
fn a_ray_through_a_corner_does_not_leak_through_a_diagonal_wall() {
    let mut map = free_map();
    // A one-cell diagonal wall: cells (100 + k, 120 - k).
    for k in -30..30 {
        map.set_cell((100 + k) as usize, (120 - k) as usize, Cell::Occupied);
    }
    // From the centre of cell (100, 100) along (1, 1): through the corners of the cells on the
    // diagonal, between (109, 110) and (110, 109)... which are on the wall (x + y = 220 - 1?).
    for start in [[100usize, 100usize], [101, 100], [95, 99]] {
        let o = [
            -5.0 + (start[0] as f64 + 0.5) * R,
            -5.0 + (start[1] as f64 + 0.5) * R,
        ];
        let d = [0.5f64.sqrt(), 0.5f64.sqrt()];
        let hit = map.cast_ray(o, d, 10.0).expect("the wall stops the ray");
        let end = [o[0] + d[0] * hit.distance_m, o[1] + d[1] * hit.distance_m];
        // The wall's cells span x + y from 219 to 221 cells (their corners): the ray stops
        // on its near side.
        let sum = (end[0] + 5.0) / R + (end[1] + 5.0) / R;
        assert!(
            (219.0 - 1e-9..=221.0 + 1e-9).contains(&sum),
            "{start:?}: stopped at {sum}"
        );
    }
}

#[test]
fn a_ray_starting_inside_a_wall_sees_out_of_it() {
    let mut map = free_map();
    for iy in 0..200 {
        for ix in 98..102 {
            map.set_cell(ix, iy, Cell::Occupied);
        }
        map.set_cell(150, iy, Cell::Occupied);
    }
    // Inside the 4-cell wall at x in [-0.1, 0.1): out of it, then to the next at x = 2.5.
    let hit = map.cast_ray([0.0, 0.0], [1.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 2.5).abs() < 1e-12, "{}", hit.distance_m);
    assert_near(hit.normal, [-1.0, 0.0]);
    // A ray outside, toward the wall, stops at it.
    let hit = map.cast_ray([-1.0, 0.0], [1.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 0.9).abs() < 1e-12);
}

#[test]
fn rays_with_values_that_are_not_finite_hit_nothing() {
    let map = free_map();
    assert!(map.cast_ray([f64::NAN, 0.0], [1.0, 0.0], 10.0).is_none());
    assert!(map.cast_ray([0.0, 0.0], [0.0, 0.0], 10.0).is_none());
    assert!(map
        .cast_ray([0.0, 0.0], [1.0, f64::INFINITY], 10.0)
        .is_none());
    assert!(map.cast_ray([0.0, 0.0], [1.0, 0.0], f64::NAN).is_none());
    let empty = MapBuilder::new(R).finish(2, 0.25);
    assert_eq!(empty.size(), (0, 0));
    assert!(empty.cast_ray([0.0, 0.0], [1.0, 0.0], 10.0).is_none());
}

/// A square room with walls at ±`HALF` (off the grid lines), and a person: a disc.
const HALF: f64 = 2.01;
const PERSON: ([f64; 2], f64) = ([0.3, 0.2], 0.15);

/// Where a beam from `o` along `d` ends: the room's wall, or the person when `person`.
fn range(o: [f64; 2], d: [f64; 2], person: bool) -> f64 {
    let wall = |p: f64, v: f64| {
        if v > 0.0 {
            (HALF - p) / v
        } else if v < 0.0 {
            (-HALF - p) / v
        } else {
            f64::INFINITY
        }
    };
    let mut t = wall(o[0], d[0]).min(wall(o[1], d[1]));
    if person {
        let (c, r) = PERSON;
        let m = [o[0] - c[0], o[1] - c[1]];
        let b = m[0] * d[0] + m[1] * d[1];
        let disc = b * b - (m[0] * m[0] + m[1] * m[1] - r * r);
        if disc >= 0.0 {
            let near = -b - disc.sqrt();
            if near > 0.0 {
                t = t.min(near);
            }
        }
    }
    t
}

#[test]
fn a_room_scanned_from_many_poses_has_its_walls_and_not_the_person_who_walked_through() {
    let mut builder = MapBuilder::new(R);
    let scans = 50;
    let beams = 720;
    for s in 0..scans {
        // Poses on a circle of 1.2 m around the room's centre; the person stands in scans 10
        // and 11 only.
        let a = 2.0 * PI * s as f64 / scans as f64;
        let o = [1.2 * a.cos(), 1.2 * a.sin()];
        let person = s == 10 || s == 11;
        for b in 0..beams {
            let h = 2.0 * PI * (b as f64 + 0.5) / beams as f64;
            let d = [h.cos(), h.sin()];
            let t = range(o, d, person);
            builder
                .add_beam(o, [o[0] + t * d[0], o[1] + t * d[1]], true)
                .unwrap();
        }
    }
    let map = builder.finish(
        MapBuilder::DEFAULT_MIN_HITS,
        MapBuilder::DEFAULT_OCCUPIED_RATIO,
    );
    let cell = |ix: i64, iy: i64| map.cell_at([(ix as f64 + 0.5) * R, (iy as f64 + 0.5) * R]);
    // The walls' cells: x = 2.01 is in column 40, x = -2.01 in column -41; the same for rows.
    // Two cells from each corner are left out (there both walls' beams graze each other).
    let mut missing = Vec::new();
    for k in -39..=38 {
        for (ix, iy) in [(40, k), (-41, k), (k, 40), (k, -41)] {
            if cell(ix, iy) != Cell::Occupied {
                missing.push((ix, iy, cell(ix, iy)));
            }
        }
    }
    assert!(missing.is_empty(), "wall cells not occupied: {missing:?}");
    // The room's inside, two cells clear of the walls, person's place included: free.
    let mut wrong = Vec::new();
    for iy in -39..=38 {
        for ix in -39..=38 {
            if cell(ix, iy) != Cell::Free {
                wrong.push((ix, iy, cell(ix, iy)));
            }
        }
    }
    assert!(wrong.is_empty(), "inside cells not free: {wrong:?}");
    // Behind the walls: never seen.
    assert_eq!(map.cell_at([2.2, 0.0]), Cell::Unknown);
    // And the finished map is one a lidar sees the walls in.
    let hit = map.cast_ray([0.0, 0.0], [1.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 2.0).abs() < 1e-9);
}

#[test]
fn a_beam_without_return_passes_up_to_its_end_only() {
    let mut builder = MapBuilder::new(R);
    builder.add_beam([0.01, 0.01], [1.01, 0.01], false).unwrap();
    builder.add_beam([0.01, 0.01], [1.01, 0.01], false).unwrap();
    let map = builder.finish(1, 0.25);
    assert_eq!(map.cell_at([0.5, 0.01]), Cell::Free);
    assert_eq!(map.cell_at([1.01, 0.01]), Cell::Free);
    assert_eq!(map.cell_at([1.06, 0.01]), Cell::Unknown);
    assert_eq!(map.size(), (21, 1));
}

#[test]
fn a_builder_refuses_bad_beams_and_a_map_past_its_limit() {
    let mut builder = MapBuilder::new(R);
    assert!(builder.add_beam([f64::NAN, 0.0], [1.0, 0.0], true).is_err());
    // 1 km × 1 km at 5 cm is 400 M cells.
    builder.add_beam([0.0, 0.0], [1.01, 1.02], true).unwrap();
    let err = builder
        .add_beam([0.0, 0.0], [1000.0, 1000.0], true)
        .unwrap_err()
        .to_string();
    assert!(err.contains("100000000 cells"), "{err}");
    // The refused beam left nothing.
    let map = builder.finish(1, 0.25);
    assert_eq!(map.cell_at([1.01, 1.01]), Cell::Occupied);
    assert!(map.size().0 < 30);
    let mut bad = MapBuilder::new(0.0);
    assert!(bad.add_beam([0.0, 0.0], [1.0, 0.0], true).is_err());
}

#[test]
fn the_surface_runs_through_the_centres_of_a_walls_cells() {
    let r = 0.05;
    let mut map = OccupancyMap::new(r, [0.0, 0.0], 100, 100).unwrap();
    for iy in 0..100 {
        // An upright wall in column 40 (x from 2.00 to 2.05 m) …
        map.set_cell(40, iy, Cell::Occupied);
    }
    for k in 0..30 {
        // … and a 45° staircase, cells (60 + k, 10 + k).
        map.set_cell(60 + k, 10 + k, Cell::Occupied);
    }
    let hit = map.cast_ray([0.5, 2.51], [1.0, 0.0], 10.0).unwrap();
    assert!((hit.distance_m - 1.5).abs() < 1e-9, "{hit:?}");
    assert!((hit.surface_m - 1.525).abs() < 1e-9, "{hit:?}");
    // Obliquely at 30° the surface is half a cell deeper along the normal: 0.025 / cos 30°.
    let (sin, cos) = 30f64.to_radians().sin_cos();
    let oblique = map.cast_ray([0.5, 2.51], [cos, sin], 10.0).unwrap();
    assert!(
        (oblique.surface_m - 1.525 / cos).abs() < 1e-6,
        "{oblique:?}"
    );
    // The staircase's centres lie on y = x − 2.5 (metres); a ray across it, from its upper-left
    // side, meets that line within 0.2 cell.
    let from = [3.0, 2.5];
    let d = [
        std::f64::consts::FRAC_1_SQRT_2,
        -std::f64::consts::FRAC_1_SQRT_2,
    ];
    let diagonal = map.cast_ray(from, d, 10.0).unwrap();
    let exact = (from[0] - from[1] - 2.5).abs() / 2f64.sqrt();
    assert!(
        (diagonal.surface_m - exact).abs() < 0.2 * r,
        "{diagonal:?} vs {exact}"
    );
    assert!(diagonal.surface_m >= diagonal.distance_m);
}
