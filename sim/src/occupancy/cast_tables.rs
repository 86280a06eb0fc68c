//! What casting rays into a map derives from its cells, made once on the first ray cast:
//! - each cell's clearance, so that a ray crosses open space in leaps (a ray's cells are
//!   otherwise visited one by one, a few hundred across a room at 3 cm cells);
//! - the surface fit of each occupied cell from each of its open sides: a ray that hits a cell
//!   from one side always gets the same fit (its window and the open cells reached from that
//!   side do not depend on the ray), while fitting it takes a flood fill of the window, several
//!   times the cost of the traversal that found the cell.

use std::collections::HashMap;
use std::sync::OnceLock;

use super::OccupancyMap;

/// A fit: the surface's normal (either sign) and its faces' centroid (cells from the hit cell's
/// centre); `None` without a clear surface.
type Fit = Option<([f64; 2], [f64; 2])>;

/// The most fits kept (each ~50 bytes with its key): a map whose surfaces have more sides (a
/// speckled map of many millions of cells) fits each hit as it comes instead.
const MAX_FITS: usize = 2_000_000;

/// The four sides a ray can enter a cell through, as the step from the open cell to it.
const SIDES: [[i64; 2]; 4] = [[1, 0], [-1, 0], [0, 1], [0, -1]];

/// The tables, made on the first ray cast (the map's cells are then settled: changing one
/// empties them).
#[derive(Clone, Default)]
pub(super) struct CastTables(OnceLock<Tables>);

#[derive(Clone)]
struct Tables {
    /// Per cell (as [`OccupancyMap::cells`]), the Chebyshev distance in cells to the nearest
    /// occupied cell (0 on one), at most `u8::MAX`: every cell less than this many cells away
    /// along both axes is open.
    clearance: Vec<u8>,
    /// Keyed by cell and side; `None` beyond [`MAX_FITS`].
    fits: Option<HashMap<u64, Fit>>,
}

impl CastTables {
    fn get(&self, map: &OccupancyMap) -> &Tables {
        self.0.get_or_init(|| Tables {
            clearance: clearance(map),
            fits: fit_all(map),
        })
    }

    /// How many cells around `cell` (in the map) are open along both axes: every cell within
    /// this Chebyshev distance of it is; 0 for an occupied cell or one outside the map.
    pub(super) fn open_radius(&self, map: &OccupancyMap, cell: [i64; 2]) -> u32 {
        let tables = self.get(map);
        map.index(cell)
            .and_then(|i| tables.clearance.get(i))
            .map_or(0, |&c| u32::from(c).saturating_sub(1))
    }

    /// The fit of `cell` hit from the open cell `from` (a 4-neighbour of it, or anything else,
    /// which is fitted directly).
    pub(super) fn fit(&self, map: &OccupancyMap, cell: [i64; 2], from: [i64; 2]) -> Fit {
        let side = SIDES
            .iter()
            .position(|s| [from[0] + s[0], from[1] + s[1]] == cell);
        let fits = self.get(map).fits.as_ref();
        match (side, fits, map.index(cell)) {
            (Some(side), Some(fits), Some(i)) => match fits.get(&key(i, side)) {
                Some(fit) => *fit,
                None => map.fitted_normal(cell, from),
            },
            _ => map.fitted_normal(cell, from),
        }
    }
}

fn key(index: usize, side: usize) -> u64 {
    index as u64 * SIDES.len() as u64 + side as u64
}

/// Every occupied cell's fit from each open side; `None` beyond [`MAX_FITS`].
fn fit_all(map: &OccupancyMap) -> Option<HashMap<u64, Fit>> {
    let mut fits = HashMap::new();
    for iy in 0..map.height as i64 {
        for ix in 0..map.width as i64 {
            if !map.is_occupied(ix, iy) {
                continue;
            }
            let cell = [ix, iy];
            for (side, s) in SIDES.iter().enumerate() {
                let from = [ix - s[0], iy - s[1]];
                if map.is_occupied(from[0], from[1]) {
                    continue;
                }
                if fits.len() >= MAX_FITS {
                    return None;
                }
                let i = map.index(cell)?;
                fits.insert(key(i, side), map.fitted_normal(cell, from));
            }
        }
    }
    Some(fits)
}

/// Each cell's Chebyshev distance to the nearest occupied cell, capped at `u8::MAX`: the
/// two-pass chamfer transform with unit steps to all eight neighbours, exact for this metric
/// (Rosenfeld & Pfaltz, "Distance functions on digital pictures", Pattern Recognition 1, 1968).
/// Cells outside the map are open.
fn clearance(map: &OccupancyMap) -> Vec<u8> {
    let (w, h) = (map.width, map.height);
    let mut d: Vec<u8> = map
        .cells
        .iter()
        .map(|&c| {
            if c == super::Cell::Occupied {
                0
            } else {
                u8::MAX
            }
        })
        .collect();
    let at = |x: usize, y: usize| y * w + x;
    for y in 0..h {
        for x in 0..w {
            let mut v = d[at(x, y)];
            if x > 0 {
                v = v.min(d[at(x - 1, y)].saturating_add(1));
            }
            if y > 0 {
                for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                    v = v.min(d[at(nx, y - 1)].saturating_add(1));
                }
            }
            d[at(x, y)] = v;
        }
    }
    for y in (0..h).rev() {
        for x in (0..w).rev() {
            let mut v = d[at(x, y)];
            if x + 1 < w {
                v = v.min(d[at(x + 1, y)].saturating_add(1));
            }
            if y + 1 < h {
                for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                    v = v.min(d[at(nx, y + 1)].saturating_add(1));
                }
            }
            d[at(x, y)] = v;
        }
    }
    d
}

/// Derived from the cells alone: two maps with the same cells are equal whether or not their
/// tables have been made.
impl PartialEq for CastTables {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for CastTables {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let fits = self.0.get().map(|t| t.fits.as_ref().map(HashMap::len));
        f.debug_struct("CastTables").field("fits", &fits).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::occupancy::Cell;

    #[test]
    fn clearance_is_the_chebyshev_distance_to_the_nearest_occupied_cell() {
        let mut map = OccupancyMap::new(1.0, [0.0, 0.0], 9, 7).unwrap();
        for (x, y) in [(2, 3), (7, 0)] {
            map.set_cell(x, y, Cell::Occupied);
        }
        let d = clearance(&map);
        for y in 0..7_i64 {
            for x in 0..9_i64 {
                let exact = [(2_i64, 3_i64), (7, 0)]
                    .iter()
                    .map(|&(ox, oy)| (x - ox).abs().max((y - oy).abs()))
                    .min()
                    .unwrap();
                assert_eq!(
                    i64::from(d[y as usize * 9 + x as usize]),
                    exact,
                    "({x}, {y})"
                );
            }
        }
    }
}
