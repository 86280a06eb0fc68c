//! The surface fits of a map's cells, made once: a ray that hits a cell from one of its four
//! sides always gets the same fit (its window and the open cells reached from that side do not
//! depend on the ray), while fitting it takes a flood fill of the window, several times the cost
//! of the traversal that found the cell.

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

/// The fits of every occupied cell from each of its open sides, made on the first ray cast
/// (the map's cells are then settled: changing one empties them).
#[derive(Clone, Default)]
pub(super) struct SurfaceFits(OnceLock<Option<HashMap<u64, Fit>>>);

impl SurfaceFits {
    /// The fit of `cell` hit from the open cell `from` (a 4-neighbour of it, or anything else,
    /// which is fitted directly).
    pub(super) fn fit(&self, map: &OccupancyMap, cell: [i64; 2], from: [i64; 2]) -> Fit {
        let side = SIDES
            .iter()
            .position(|s| [from[0] + s[0], from[1] + s[1]] == cell);
        let table = self.0.get_or_init(|| fit_all(map));
        match (side, table, map.index(cell)) {
            (Some(side), Some(table), Some(i)) => match table.get(&key(i, side)) {
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
    let mut table = HashMap::new();
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
                if table.len() >= MAX_FITS {
                    return None;
                }
                let i = map.index(cell)?;
                table.insert(key(i, side), map.fitted_normal(cell, from));
            }
        }
    }
    Some(table)
}

/// Derived from the cells alone: two maps with the same cells are equal whether or not their
/// fits have been made.
impl PartialEq for SurfaceFits {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for SurfaceFits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let fits = self.0.get().map(|t| t.as_ref().map(HashMap::len));
        f.debug_struct("SurfaceFits").field("fits", &fits).finish()
    }
}
