//! Occupancy-map rates: rays cast into a map (`cast_ray`) and beams traced into a map being
//! built (`add_beam`), as cells crossed per second (criterion's throughput).
//!
//! `cargo bench -p hilsim-sim --bench occupancy`. A 45-minute log is about 2.5 M beams of
//! 8–50 m: at 5 cm cells, 0.4–2.5 G cells to trace; tens of millions of cells a second keep that
//! to a minute or so.

use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput};
use hilsim_sim::occupancy::{Cell, MapBuilder, OccupancyMap};

const R: f64 = 0.05;
/// The map: 40 m square, a wall around it and none inside, so rays cross it whole.
const SIDE: usize = 800;
const RAYS: usize = 1000;

/// Ray origins and directions of a golden-angle fan from points near the centre.
fn rays() -> Vec<([f64; 2], [f64; 2])> {
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..RAYS)
        .map(|i| {
            let a = golden * i as f64;
            let o = [0.3 * (i % 7) as f64, 0.2 * (i % 5) as f64];
            (o, [a.cos(), a.sin()])
        })
        .collect()
}

fn room() -> OccupancyMap {
    let half = SIDE as f64 * R / 2.0;
    let mut map = OccupancyMap::new(R, [-half, -half], SIDE, SIDE).unwrap();
    for i in 0..SIDE {
        for j in 0..SIDE {
            let edge = i == 0 || j == 0 || i == SIDE - 1 || j == SIDE - 1;
            map.set_cell(i, j, if edge { Cell::Occupied } else { Cell::Free });
        }
    }
    map
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let map = room();
    let rays = rays();
    // Cells crossed: the distance over the cell, times about (|cos| + |sin|) boundaries a cell.
    let cells: f64 = rays
        .iter()
        .map(|&(o, d)| {
            let hit = map.cast_ray(o, d, 100.0).expect("the room's wall");
            hit.distance_m / R * (d[0].abs() + d[1].abs())
        })
        .sum();
    let mut group = c.benchmark_group("occupancy");
    group.throughput(Throughput::Elements(cells as u64));
    group.bench_function("cast_ray (cells crossed)", |b| {
        b.iter(|| {
            for &(o, d) in &rays {
                black_box(map.cast_ray(black_box(o), black_box(d), 100.0));
            }
        });
    });
    // Beams of 8 m from the same origins into a fresh builder (its tiles allocated as it goes,
    // as when a log's first scans arrive) and into one that has seen them all before.
    let beams: Vec<([f64; 2], [f64; 2])> = rays
        .iter()
        .map(|&(o, d)| (o, [o[0] + 8.0 * d[0], o[1] + 8.0 * d[1]]))
        .collect();
    let beam_cells = rays
        .iter()
        .map(|&(_, d)| 8.0 / R * (d[0].abs() + d[1].abs()))
        .sum::<f64>();
    group.throughput(Throughput::Elements(beam_cells as u64));
    let mut warm = MapBuilder::new(R);
    for &(o, e) in &beams {
        warm.add_beam(o, e, true).unwrap();
    }
    group.bench_function("add_beam (cells traced, tiles allocated)", |b| {
        b.iter(|| {
            let mut builder = MapBuilder::new(R);
            for &(o, e) in &beams {
                builder.add_beam(o, e, true).unwrap();
            }
            black_box(builder)
        });
    });
    group.bench_function("add_beam (cells traced)", |b| {
        b.iter_batched_ref(
            || (),
            |()| {
                for &(o, e) in &beams {
                    warm.add_beam(black_box(o), black_box(e), true).unwrap();
                }
            },
            BatchSize::SmallInput,
        );
    });
    group.finish();
    c.final_summary();
}
