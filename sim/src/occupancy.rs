//! An occupancy-grid map: the world of a real robot's run as a map_server map (a PGM or PNG image
//! and its YAML) or as a map built from the run's own scans, and rays cast into it.
//!
//! Cells are square, `resolution_m` on a side; cell `(0, 0)` has its lower-left corner at
//! `origin` and cell `(ix, iy)` covers `[ox + ix·r, ox + (ix+1)·r) × [oy + iy·r, oy + (iy+1)·r)`,
//! `y` up (an image's last row is the map's row 0, as map_server reads it).
//!
//! ```
//! use hilsim_sim::occupancy::{Cell, MapBuilder};
//! // A wall 2 m ahead seen from the origin along +x: the beam's cells are free, its end occupied.
//! let mut builder = MapBuilder::new(0.05);
//! for _ in 0..3 {
//!     builder.add_beam([0.0, 0.01], [2.01, 0.01], true).unwrap();
//! }
//! let map = builder.finish(2, 0.25);
//! assert_eq!(map.cell_at([1.0, 0.01]), Cell::Free);
//! assert_eq!(map.cell_at([2.02, 0.01]), Cell::Occupied);
//! let hit = map.cast_ray([0.0, 0.01], [1.0, 0.0], 10.0).unwrap();
//! assert!((hit.distance_m - 2.0).abs() < 1e-9);
//! assert_eq!(hit.normal, [-1.0, 0.0]);
//! ```

mod builder;
mod cast;
mod cast_tables;
mod error;
mod files;
mod map;
mod pgm;
mod pixels;
mod png_image;
mod traverse;
mod yaml;

pub use builder::{MapBuilder, MAX_BUILDER_CELLS};
pub use cast::MapHit;
pub use error::MapError;
pub use files::{MAP_PGM, MAP_YAML};
pub use map::{Cell, OccupancyMap, MAX_CELLS};
