//! A map built from range scans at known poses: the counting model (each cell's beams that end
//! in it against those that pass through it), the map estimate that maximises the likelihood of
//! the beams when each cell either reflects or passes a beam with a fixed probability (Hähnel,
//! Burgard & Thrun, "Learning compact 3D models of indoor and outdoor environments with a
//! mobile robot", Robotics and Autonomous Systems 44, 2003).

use super::cast_tables::CastTables;
use super::map::{check_geometry, MAX_CELLS};
use super::traverse::Traversal;
use super::{Cell, MapError, OccupancyMap};

/// The most cells a [`MapBuilder`] may hold counts for: 100 M cells of 4 bytes (400 MB), in
/// tiles of 64 × 64 allocated where beams go. The finished map's rectangle is bounded by
/// [`MAX_CELLS`] as well.
pub const MAX_BUILDER_CELLS: usize = 100_000_000;

/// A tile is `1 << TILE_BITS` cells a side: 64 × 64 cells of 4 bytes, 16 KiB, 3.2 m at 5 cm.
const TILE_BITS: u32 = 6;
const TILE_SIDE: i64 = 1 << TILE_BITS;
const TILE_CELLS: usize = 1 << (2 * TILE_BITS);

/// One cell's beams.
#[derive(Clone, Copy, Default)]
struct Counts {
    /// Beams that ended in the cell (saturating).
    hits: u16,
    /// Beams that passed through it (saturating).
    passes: u16,
}

/// Builds an [`OccupancyMap`] from beams at known poses (see [`MapBuilder::finish`] for how
/// counts become cells). The map grows as beams arrive, in tiles of 64 × 64 cells where beams
/// go, up to [`MAX_BUILDER_CELLS`].
///
/// ```
/// use hilsim_sim::occupancy::{Cell, MapBuilder};
/// let mut builder = MapBuilder::new(0.05);
/// builder.add_beam([0.0, 0.0], [1.02, 0.01], true).unwrap();
/// builder.add_beam([0.0, 0.0], [1.02, 0.01], true).unwrap();
/// // A beam that returned nothing within its 0.5 m range.
/// builder.add_beam([0.0, 0.1], [0.5, 0.1], false).unwrap();
/// let map = builder.finish(MapBuilder::DEFAULT_MIN_HITS, MapBuilder::DEFAULT_OCCUPIED_RATIO);
/// assert_eq!(map.cell_at([1.02, 0.01]), Cell::Occupied);
/// assert_eq!(map.cell_at([0.5, 0.01]), Cell::Free);
/// assert_eq!(map.cell_at([0.7, 0.1]), Cell::Unknown);
/// ```
#[must_use]
pub struct MapBuilder {
    resolution_m: f64,
    /// The lowest tile of `index`, in tiles.
    tile_origin: [i64; 2],
    /// `index`'s size in tiles.
    tiles_wide: usize,
    tiles_high: usize,
    /// Per tile of the rectangle, row-major: 0 when no beam went there, else 1 + its number.
    index: Vec<u32>,
    /// Each allocated tile's lowest cell, by number.
    tile_cells: Vec<[i64; 2]>,
    /// The allocated tiles' counts, one tile after another, row-major within each.
    counts: Vec<Counts>,
    /// The rectangle of cells the beams so far may have touched: lowest, highest.
    bounds: Option<[[i64; 2]; 2]>,
}

impl MapBuilder {
    /// The fewest beams that must end in a cell for it to be occupied: 2, so that one stray
    /// reading (a lidar's mixed pixel at an edge, a speck of dust) is not a wall.
    pub const DEFAULT_MIN_HITS: u32 = 2;

    /// The share of a cell's beams that must end in it for it to be occupied: 0.25, the
    /// threshold GMapping applies to the same counts (`occ_thresh`, ROS wiki `gmapping`). Lower
    /// than one half because a wall cell is also crossed by beams that graze the wall and end
    /// in its neighbours; a person who walked through is seen in a few scans and passed through
    /// in all the others, far below it.
    pub const DEFAULT_OCCUPIED_RATIO: f64 = 0.25;

    /// An empty map of square cells `resolution_m` a side, laid on the world's lattice (cell
    /// `(i, j)` covers `[i·r, (i+1)·r) × [j·r, (j+1)·r)`). A resolution that is not a positive
    /// number is reported by the first [`MapBuilder::add_beam`].
    pub fn new(resolution_m: f64) -> Self {
        Self {
            resolution_m,
            tile_origin: [0, 0],
            tiles_wide: 0,
            tiles_high: 0,
            index: Vec::new(),
            tile_cells: Vec::new(),
            counts: Vec::new(),
            bounds: None,
        }
    }

    /// The map's resolution, metres.
    #[must_use]
    pub fn resolution_m(&self) -> f64 {
        self.resolution_m
    }

    /// Adds a beam from `origin` to `end` (world metres). With `hit`, it ended on something in
    /// `end`'s cell, and passed through every cell before; without (no return within range,
    /// `end` at its maximum range), it passed through every cell up to `end`.
    ///
    /// # Errors
    /// A coordinate that is not finite, a resolution that is not a positive number, or a map
    /// that would grow past [`MAX_CELLS`] cells in its rectangle or [`MAX_BUILDER_CELLS`] in
    /// its tiles. The map is then as it was before the beam.
    pub fn add_beam(&mut self, origin: [f64; 2], end: [f64; 2], hit: bool) -> Result<(), MapError> {
        let r = self.resolution_m;
        check_geometry(r, [0.0, 0.0], 0, 0)?;
        if !origin.iter().chain(&end).all(|v| v.is_finite()) {
            return Err(MapError::invalid(format!(
                "a beam from {origin:?} to {end:?}: coordinates must be finite"
            )));
        }
        let cell_of = |v: f64| (v / r).floor();
        // One cell of margin: a point on a boundary starts in the cell the beam goes into.
        let lo = [0, 1].map(|a| cell_of(origin[a].min(end[a])) - 1.0);
        let hi = [0, 1].map(|a| cell_of(origin[a].max(end[a])) + 1.0);
        // The tiles the beam may newly need: at most one per tile row and column it crosses.
        let tiles = (0..2)
            .map(|a| ((hi[a] - lo[a]) / TILE_SIDE as f64).ceil() + 1.0)
            .sum::<f64>();
        if self.counts.len() as f64 + tiles * TILE_CELLS as f64 > MAX_BUILDER_CELLS as f64 {
            return Err(MapError::TooLarge {
                message: format!(
                    "the beams so far reach nearly the {MAX_BUILDER_CELLS} cells of {} m a map \
                     may be built from",
                    self.resolution_m
                ),
            });
        }
        self.cover(lo, hi)?;
        let v = [end[0] - origin[0], end[1] - origin[1]];
        let len = v[0].hypot(v[1]);
        if len == 0.0 {
            let cell = [0, 1].map(|a| cell_of(origin[a]) as i64);
            self.count(cell, hit);
            return Ok(());
        }
        let d = [v[0] / len, v[1] / len];
        let mut tr = Traversal::new(origin, d, r);
        loop {
            let (exit, axis, _) = tr.exit();
            if exit >= len {
                self.count(tr.cell, hit);
                return Ok(());
            }
            self.count(tr.cell, false);
            tr.cross(axis);
        }
    }

    /// Turns the counts into a map over the rectangle of cells any beam touched: a cell is
    /// [`Cell::Occupied`] when at least `min_hits` beams ended in it and they are at least
    /// `occupied_ratio` of the beams that reached it (`hits / (hits + passes)`), else
    /// [`Cell::Free`] when a beam passed through it, else [`Cell::Unknown`]. See
    /// [`MapBuilder::DEFAULT_MIN_HITS`] and [`MapBuilder::DEFAULT_OCCUPIED_RATIO`] for the usual
    /// values and why. A builder given no beam gives a map of no cells.
    #[must_use]
    pub fn finish(self, min_hits: u32, occupied_ratio: f64) -> OccupancyMap {
        let touched = |c: &Counts| c.hits > 0 || c.passes > 0;
        let mut lo = [i64::MAX; 2];
        let mut hi = [i64::MIN; 2];
        for (tile, cells) in self.tile_cells.iter().zip(self.counts.chunks(TILE_CELLS)) {
            for (i, _) in cells.iter().enumerate().filter(|(_, c)| touched(c)) {
                let cell = [
                    tile[0] + (i as i64 & (TILE_SIDE - 1)),
                    tile[1] + (i as i64 >> TILE_BITS),
                ];
                for a in 0..2 {
                    lo[a] = lo[a].min(cell[a]);
                    hi[a] = hi[a].max(cell[a]);
                }
            }
        }
        let r = self.resolution_m;
        let empty = || OccupancyMap {
            resolution_m: r,
            origin: [0.0, 0.0],
            width: 0,
            height: 0,
            cells: Vec::new(),
            tables: CastTables::default(),
        };
        if lo[0] > hi[0] {
            return empty();
        }
        // `add_beam` kept the rectangle within MAX_CELLS.
        let (width, height) = ((hi[0] - lo[0] + 1) as usize, (hi[1] - lo[1] + 1) as usize);
        let mut map = OccupancyMap {
            resolution_m: r,
            origin: [lo[0] as f64 * r, lo[1] as f64 * r],
            width,
            height,
            cells: vec![Cell::Unknown; width * height],
            tables: CastTables::default(),
        };
        for (tile, cells) in self.tile_cells.iter().zip(self.counts.chunks(TILE_CELLS)) {
            for (i, c) in cells.iter().enumerate().filter(|(_, c)| touched(c)) {
                let x = tile[0] + (i as i64 & (TILE_SIDE - 1)) - lo[0];
                let y = tile[1] + (i as i64 >> TILE_BITS) - lo[1];
                let hits = f64::from(c.hits);
                let reached = hits + f64::from(c.passes);
                let cell = if u32::from(c.hits) >= min_hits && hits >= occupied_ratio * reached {
                    Cell::Occupied
                } else if c.passes > 0 {
                    Cell::Free
                } else {
                    // Only hits, fewer than `min_hits`: never seen through.
                    Cell::Unknown
                };
                map.set_cell(x as usize, y as usize, cell);
            }
        }
        map
    }

    /// Grows the tile index so that it covers cells `lo..=hi`, and the rectangle of touched
    /// cells with it, within the limits.
    fn cover(&mut self, lo: [f64; 2], hi: [f64; 2]) -> Result<(), MapError> {
        let (old_lo, old_hi) = match self.bounds {
            Some([l, h]) => ([l[0] as f64, l[1] as f64], [h[0] as f64, h[1] as f64]),
            None => (lo, hi),
        };
        let new_lo = [lo[0].min(old_lo[0]), lo[1].min(old_lo[1])];
        let new_hi = [hi[0].max(old_hi[0]), hi[1].max(old_hi[1])];
        // In f64, so that no coordinate overflows before the check.
        let (w, h) = (new_hi[0] - new_lo[0] + 1.0, new_hi[1] - new_lo[1] + 1.0);
        if w * h > MAX_CELLS as f64 {
            return Err(MapError::TooLarge {
                message: format!(
                    "the beams so far span {w} × {h} cells of {} m, more than the {MAX_CELLS} \
                     cells a map may have",
                    self.resolution_m
                ),
            });
        }
        let new_lo = new_lo.map(|v| v as i64);
        let new_hi = new_hi.map(|v| v as i64);
        self.bounds = Some([new_lo, new_hi]);
        let tile_lo = new_lo.map(|v| v >> TILE_BITS);
        let tile_hi = new_hi.map(|v| v >> TILE_BITS);
        let [ox, oy] = self.tile_origin;
        let (tw, th) = (self.tiles_wide as i64, self.tiles_high as i64);
        let covered = !self.index.is_empty()
            && tile_lo[0] >= ox
            && tile_lo[1] >= oy
            && tile_hi[0] < ox + tw
            && tile_hi[1] < oy + th;
        if covered {
            return Ok(());
        }
        // Grow by the old size on each side that needs it, so that a robot driving on re-indexes
        // only a logarithmic number of times.
        let (mut lo_t, mut hi_t) = (tile_lo, tile_hi);
        if !self.index.is_empty() {
            let old_hi_t = [ox + tw - 1, oy + th - 1];
            let size = [tw, th];
            for a in 0..2 {
                let old_lo_t = [ox, oy][a];
                lo_t[a] = if tile_lo[a] < old_lo_t {
                    tile_lo[a].min(old_lo_t - size[a])
                } else {
                    old_lo_t
                };
                hi_t[a] = if tile_hi[a] > old_hi_t[a] {
                    tile_hi[a].max(old_hi_t[a] + size[a])
                } else {
                    old_hi_t[a]
                };
            }
        }
        let (ntw, nth) = (
            (hi_t[0] - lo_t[0] + 1) as usize,
            (hi_t[1] - lo_t[1] + 1) as usize,
        );
        let mut index = vec![0u32; ntw * nth];
        for y in 0..th {
            for x in 0..tw {
                let Some(&slot) = self.index.get((y * tw + x) as usize) else {
                    continue;
                };
                let (nx, ny) = (x + ox - lo_t[0], y + oy - lo_t[1]);
                if let Some(new) = index.get_mut(ny as usize * ntw + nx as usize) {
                    *new = slot;
                }
            }
        }
        self.index = index;
        self.tile_origin = lo_t;
        self.tiles_wide = ntw;
        self.tiles_high = nth;
        Ok(())
    }

    /// Counts a beam that ended in `cell` (`hit`) or passed through it.
    #[inline]
    fn count(&mut self, cell: [i64; 2], hit: bool) {
        let tx = (cell[0] >> TILE_BITS) - self.tile_origin[0];
        let ty = (cell[1] >> TILE_BITS) - self.tile_origin[1];
        let slot = ty as usize * self.tiles_wide + tx as usize;
        let tile = match self.index.get(slot) {
            Some(&0) => self.new_tile(slot, cell),
            Some(&k) => k as usize - 1,
            // `cover` made the index hold every cell the beam can reach.
            None => return,
        };
        let within =
            ((cell[1] & (TILE_SIDE - 1)) << TILE_BITS | (cell[0] & (TILE_SIDE - 1))) as usize;
        if let Some(c) = self.counts.get_mut(tile * TILE_CELLS + within) {
            if hit {
                c.hits = c.hits.saturating_add(1);
            } else {
                c.passes = c.passes.saturating_add(1);
            }
        }
    }

    /// Allocates the tile of `cell` at `slot` of the index (`add_beam` checked the limit); its
    /// number.
    #[cold]
    fn new_tile(&mut self, slot: usize, cell: [i64; 2]) -> usize {
        let number = self.tile_cells.len();
        self.tile_cells
            .push(cell.map(|v| (v >> TILE_BITS) << TILE_BITS));
        self.counts
            .resize(self.counts.len() + TILE_CELLS, Counts::default());
        if let Some(entry) = self.index.get_mut(slot) {
            *entry = number as u32 + 1;
        }
        number
    }
}
