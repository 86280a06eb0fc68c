//! TEMPORARY STUB (replaced by the occupancy branch).
#![allow(missing_docs, clippy::all, unused)]
use std::path::Path;
#[derive(Debug, Clone, PartialEq)]
pub struct OccupancyMap {
    res: f64,
}
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Cell {
    Free,
    Occupied,
    Unknown,
}
pub struct MapHit {
    pub distance_m: f64,
    pub normal: [f64; 2],
}
#[derive(Debug)]
pub struct MapError(String);
impl std::fmt::Display for MapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}
impl OccupancyMap {
    pub fn load(yaml: &Path) -> Result<Self, MapError> {
        Err(MapError("stub".into()))
    }
    pub fn write(&self, yaml: &Path) -> Result<(), MapError> {
        Err(MapError("stub".into()))
    }
    pub fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_m: f64) -> Option<MapHit> {
        None
    }
    pub fn resolution_m(&self) -> f64 {
        self.res
    }
}
pub struct MapBuilder;
impl MapBuilder {
    pub fn new(resolution_m: f64) -> Self {
        MapBuilder
    }
    pub fn add_beam(&mut self, origin: [f64; 2], end: [f64; 2], hit: bool) -> Result<(), MapError> {
        Ok(())
    }
    pub fn finish(self, min_hits: u32, occupied_ratio: f64) -> OccupancyMap {
        OccupancyMap { res: 0.05 }
    }
}
