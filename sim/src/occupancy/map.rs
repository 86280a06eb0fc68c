//! The grid itself: cells, their place in the world, and looking one up.

use super::cast_tables::CastTables;
use super::MapError;

/// The most cells a map may have: 100 M cells, one byte each (100 MB). That is 0.25 km² at
/// 5 cm cells or 0.04 km² (200 m × 200 m) at 2 cm, more than a building's floor; map_server
/// maps are typically a few thousand pixels a side (16 M cells at 4000 × 4000).
pub const MAX_CELLS: usize = 100_000_000;

/// What a cell of the map is.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Cell {
    /// Known empty: rays pass.
    Free,
    /// Known taken: rays stop at it.
    Occupied,
    /// Never seen (or neither clearly free nor clearly occupied): rays pass.
    Unknown,
}

/// A grid of square cells in the world's frame (see the module's documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct OccupancyMap {
    pub(super) resolution_m: f64,
    /// The lower-left corner of cell `(0, 0)`, world metres.
    pub(super) origin: [f64; 2],
    pub(super) width: usize,
    pub(super) height: usize,
    /// Row-major, row 0 the bottom (lowest `y`).
    pub(super) cells: Vec<Cell>,
    /// What casting rays derives from the cells, made once they are settled.
    pub(super) tables: CastTables,
}

impl OccupancyMap {
    /// A map of `width × height` cells, all [`Cell::Unknown`].
    ///
    /// # Errors
    /// The resolution is not a positive finite number, the origin or the far corner is not
    /// finite, or there are more than [`MAX_CELLS`] cells.
    pub fn new(
        resolution_m: f64,
        origin: [f64; 2],
        width: usize,
        height: usize,
    ) -> Result<Self, MapError> {
        check_geometry(resolution_m, origin, width, height)?;
        Ok(Self {
            resolution_m,
            origin,
            width,
            height,
            cells: vec![Cell::Unknown; width * height],
            tables: CastTables::default(),
        })
    }

    /// The map's resolution: a cell's side, metres.
    #[must_use]
    pub fn resolution_m(&self) -> f64 {
        self.resolution_m
    }

    /// The lower-left corner of cell `(0, 0)`, world metres.
    #[must_use]
    pub fn origin(&self) -> [f64; 2] {
        self.origin
    }

    /// `(width, height)` in cells.
    #[must_use]
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Every cell, row-major from the bottom row (`iy = 0`) up: cell `(ix, iy)` is at
    /// `iy · width + ix`.
    #[must_use]
    pub fn cells(&self) -> &[Cell] {
        &self.cells
    }

    /// Cell `(ix, iy)`, or `None` outside the map.
    #[must_use]
    pub fn cell(&self, ix: usize, iy: usize) -> Option<Cell> {
        (ix < self.width && iy < self.height)
            .then(|| self.cells.get(iy * self.width + ix).copied())
            .flatten()
    }

    /// Sets cell `(ix, iy)`; returns whether it is in the map (nothing changes otherwise).
    pub fn set_cell(&mut self, ix: usize, iy: usize, cell: Cell) -> bool {
        if ix >= self.width || iy >= self.height {
            return false;
        }
        match self.cells.get_mut(iy * self.width + ix) {
            Some(slot) => {
                *slot = cell;
                self.tables = CastTables::default();
                true
            }
            None => false,
        }
    }

    /// The indices of the cell holding the world point `xy`, or `None` outside the map (or for
    /// a coordinate that is not finite).
    #[must_use]
    pub fn cell_index(&self, xy: [f64; 2]) -> Option<(usize, usize)> {
        let ix = ((xy[0] - self.origin[0]) / self.resolution_m).floor();
        let iy = ((xy[1] - self.origin[1]) / self.resolution_m).floor();
        // NaN fails both comparisons.
        let inside = |i: f64, n: usize| i >= 0.0 && i < n as f64;
        (inside(ix, self.width) && inside(iy, self.height)).then_some((ix as usize, iy as usize))
    }

    /// The cell holding the world point `xy`; [`Cell::Unknown`] outside the map.
    #[must_use]
    pub fn cell_at(&self, xy: [f64; 2]) -> Cell {
        self.cell_index(xy)
            .and_then(|(ix, iy)| self.cell(ix, iy))
            .unwrap_or(Cell::Unknown)
    }

    /// The place of cell `[ix, iy]` in [`OccupancyMap::cells`]; `None` outside the map.
    pub(super) fn index(&self, cell: [i64; 2]) -> Option<usize> {
        let (ix, iy) = (
            usize::try_from(cell[0]).ok()?,
            usize::try_from(cell[1]).ok()?,
        );
        (ix < self.width && iy < self.height).then(|| iy * self.width + ix)
    }

    /// Whether cell `(ix, iy)` stops rays; false outside the map.
    #[inline]
    pub(super) fn is_occupied(&self, ix: i64, iy: i64) -> bool {
        if ix < 0 || iy < 0 || ix as usize >= self.width || iy as usize >= self.height {
            return false;
        }
        self.cells.get(iy as usize * self.width + ix as usize) == Some(&Cell::Occupied)
    }
}

/// The checks of [`OccupancyMap::new`], also made before an image's pixels are read.
pub(super) fn check_geometry(
    resolution_m: f64,
    origin: [f64; 2],
    width: usize,
    height: usize,
) -> Result<(), MapError> {
    if !(resolution_m.is_finite() && resolution_m > 0.0) {
        return Err(MapError::invalid(format!(
            "a map's resolution must be a positive number of metres, not {resolution_m}"
        )));
    }
    let cells = width.checked_mul(height).filter(|&n| n <= MAX_CELLS);
    if cells.is_none() {
        return Err(MapError::TooLarge {
            message: format!(
                "a map of {width} × {height} cells is more than the {MAX_CELLS} cells allowed"
            ),
        });
    }
    let far = [
        origin[0] + width as f64 * resolution_m,
        origin[1] + height as f64 * resolution_m,
    ];
    if !origin.iter().chain(&far).all(|v| v.is_finite()) {
        return Err(MapError::invalid(format!(
            "a map's origin must be finite, and its far corner too, not {origin:?}"
        )));
    }
    Ok(())
}
