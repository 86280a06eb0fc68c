//! The world to scale, in metres: walls, boards and cylinders, the true and the dead-reckoned
//! paths, and a few lidar revolutions in the world frame, raw and calibrated.

use hilsim_calibrator::{groundtruth::invert, Sensor};
use hilsim_recording::{LidarSample, Pose, TimedPath};
use hilsim_sim::occupancy::{Cell, OccupancyMap};
use hilsim_sim::Scenario;

use crate::colours;
use crate::svg::{thin, Chart, Key, Span, Stroke};
use crate::view::{beam_rad, View};

/// Revolutions drawn on the map: a few, spread over the run, so the page stays readable.
const SCANS: usize = 3;

/// Points of a path drawn at most.
const PATH_POINTS: usize = 4000;

/// Extra marks on the map (the diagnosis's located readings, say).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overlay {
    /// World points to mark.
    pub points: Vec<(f64, f64)>,
    /// What they are, for the legend.
    pub label: String,
}

/// The map as an SVG element, and the revolutions it shows.
#[must_use]
pub fn map(view: &View<'_>, overlay: Option<&Overlay>) -> (String, Vec<u64>) {
    let scenario = view.inputs.scenario;
    // The world and the true (or estimated) path frame the page; the odometry's dead reckoning,
    // which drifts without bound over a long log (tens of metres over a building's 45 minutes),
    // is drawn clipped to them. Without either it frames the page itself.
    let framed_by_odometry = view.truth.is_empty() && scenario.is_none();
    let odometry_points = || {
        view.odometry
            .poses()
            .iter()
            .chain(view.calibrated_odometry.poses())
            .map(|p| (p.x, p.y))
    };
    let mut paths: Vec<(f64, f64)> = view.truth.poses().iter().map(|p| (p.x, p.y)).collect();
    if framed_by_odometry {
        paths.extend(odometry_points());
    }
    let revs = chosen_revolutions(view);
    let scans: Vec<Scan> = revs.iter().map(|&rev| scan(view, rev)).collect();
    let mut xs: Vec<f64> = paths.iter().map(|p| p.0).collect();
    let mut ys: Vec<f64> = paths.iter().map(|p| p.1).collect();
    if let Some(s) = scenario {
        let (wx, wy) = world_extent(s);
        xs.extend(wx);
        ys.extend(wy);
    } else {
        // No world to frame the page: the scans set the extent.
        for s in &scans {
            xs.extend(s.raw.iter().map(|p| p.0));
            ys.extend(s.raw.iter().map(|p| p.1));
        }
    }
    let x = Span::of(xs).padded(0.06);
    let y = Span::of(ys).padded(0.06);
    let inside = |(px, py): (f64, f64)| (x.lo..=x.hi).contains(&px) && (y.lo..=y.hi).contains(&py);
    let clipped = if odometry_points().all(inside) {
        ""
    } else {
        ", clipped to the frame"
    };
    let mut chart = Chart::to_scale("map", 900.0, 760.0, x, y);
    chart.axes("The world, the paths and the scans", "x (m)", "y (m)");
    if let Some(s) = scenario {
        draw_world(&mut chart, s);
    }
    let mut keys = Vec::new();
    if let Some(o) = overlay {
        chart.dots(&o.points, "#f2b400", 4.0, 0.55);
        keys.push(Key::Dots("#f2b400", o.label.clone()));
    }
    for s in &scans {
        chart.dots(&thin(&s.raw, 1500), colours::RAW, 1.6, 0.75);
        chart.dots(&thin(&s.calibrated, 1500), colours::CALIBRATED, 1.6, 0.75);
    }
    if !scans.is_empty() {
        keys.push(Key::Dots(colours::RAW, "lidar, raw readings".into()));
        if scans.iter().any(|s| !s.calibrated.is_empty()) {
            keys.push(Key::Dots(
                colours::CALIBRATED,
                "lidar, calibrated (bias inverted)".into(),
            ));
        }
    }
    let line = |path: &TimedPath| -> Vec<(f64, f64)> {
        thin(path.poses(), PATH_POINTS)
            .iter()
            .map(|p| (p.x, p.y))
            .collect()
    };
    if !view.odometry.is_empty() {
        let stroke = Stroke::dashed(colours::ODOMETRY, 2.0);
        chart.line(&line(&view.odometry), stroke);
        keys.push(Key::Line(
            stroke,
            format!("path from the odometry{clipped}"),
        ));
    }
    if !view.calibrated_odometry.is_empty() {
        let stroke = Stroke::dashed(colours::CALIBRATED_ODOMETRY, 2.0);
        chart.line(&line(&view.calibrated_odometry), stroke);
        keys.push(Key::Line(
            stroke,
            format!("path from the odometry, wheels calibrated{clipped}"),
        ));
    }
    if !view.truth.is_empty() {
        let stroke = Stroke::solid(colours::TRUTH, 1.8);
        chart.line(&line(&view.truth), stroke);
        let name = if view.inputs.truth_estimated {
            "path estimated from the lidar"
        } else {
            "true path"
        };
        keys.push(Key::Line(stroke, name.into()));
    }
    // Landmarks a calibration found, given in the frame of the robot's start pose.
    let start = view.truth.first().or(view.odometry.first()).map(|p| p.1);
    if let Some(origin) = start {
        let found: Vec<(f64, f64)> = view
            .inputs
            .calibrations
            .iter()
            .filter_map(|c| c.landmarks.as_ref())
            .flatten()
            .map(|p| {
                let w = origin.transform(*p);
                (w[0], w[1])
            })
            .collect();
        if !found.is_empty() {
            chart.crosses(
                &found,
                colours::method(hilsim_calibrator::Method::Landmarks),
            );
            keys.push(Key::Dots(
                colours::method(hilsim_calibrator::Method::Landmarks),
                "landmarks the calibration found (×)".into(),
            ));
        }
        chart.marker((origin.x, origin.y), "#2a9d4b", "start");
    }
    for s in &scans {
        if let Some(p) = s.pose {
            chart.marker((p.x, p.y), colours::TRUTH, &format!("rev {}", s.rev));
        }
    }
    chart.legend(&keys);
    (chart.finish(), revs)
}

/// The world's points that frame the map.
fn world_extent(s: &Scenario) -> (Vec<f64>, Vec<f64>) {
    let mut xs = vec![s.robot.start.x];
    let mut ys = vec![s.robot.start.y];
    for w in &s.world.walls {
        xs.extend([w.from[0], w.to[0]]);
        ys.extend([w.from[1], w.to[1]]);
    }
    for c in &s.world.cylinders {
        xs.extend([c.center[0] - c.radius, c.center[0] + c.radius]);
        ys.extend([c.center[1] - c.radius, c.center[1] + c.radius]);
    }
    for b in &s.world.boards {
        for (x, y) in board_corners(b) {
            xs.push(x);
            ys.push(y);
        }
    }
    if let Some(map) = &s.files.map {
        for (x0, y0, x1, y1) in occupied_runs(map, 1) {
            xs.extend([x0, x1]);
            ys.extend([y0, y1]);
        }
    }
    (xs, ys)
}

/// The most rectangles a map is drawn with: beyond it, cells are drawn in blocks (a block
/// occupied when any of its cells is), so the page stays a few megabytes.
const MAX_MAP_RECTS: usize = 60_000;

/// The occupied cells of `map` in blocks of `block × block` cells, as rectangles `(x0, y0, x1,
/// y1)` in metres, each a run of occupied blocks along a row.
fn occupied_runs(map: &OccupancyMap, block: usize) -> Vec<(f64, f64, f64, f64)> {
    let (width, height) = map.size();
    let (r, [ox, oy]) = (map.resolution_m(), map.origin());
    let size = r * block as f64;
    let occupied = |bx: usize, by: usize| {
        (by * block..((by + 1) * block).min(height)).any(|iy| {
            (bx * block..((bx + 1) * block).min(width))
                .any(|ix| map.cell(ix, iy) == Some(Cell::Occupied))
        })
    };
    let (bw, bh) = (width.div_ceil(block), height.div_ceil(block));
    let mut runs = Vec::new();
    for by in 0..bh {
        let mut start = None;
        for bx in 0..=bw {
            match (bx < bw && occupied(bx, by), start) {
                (true, None) => start = Some(bx),
                (false, Some(from)) => {
                    let y0 = oy + by as f64 * size;
                    runs.push((
                        ox + from as f64 * size,
                        y0,
                        ox + bx as f64 * size,
                        y0 + size,
                    ));
                    start = None;
                }
                _ => {}
            }
        }
    }
    runs
}

/// A board's four corners, world frame.
fn board_corners(b: &hilsim_sim::scenario::Board) -> [(f64, f64); 4] {
    let centre = Pose::new(b.center[0], b.center[1], b.yaw_deg.to_radians());
    let (hl, ht) = (b.length / 2.0, b.thickness / 2.0);
    // The board's length runs along `yaw_deg` (its local x axis).
    [(-hl, -ht), (hl, -ht), (hl, ht), (-hl, ht)].map(|(dx, dy)| {
        let p = centre.transform([dx, dy]);
        (p[0], p[1])
    })
}

/// Walls as lines, boards as filled rectangles, cylinders as circles, a map's occupied cells.
fn draw_world(chart: &mut Chart, s: &Scenario) {
    if let Some(map) = &s.files.map {
        let mut block = 1;
        let mut runs = occupied_runs(map, block);
        while runs.len() > MAX_MAP_RECTS && block < 64 {
            block *= 2;
            runs = occupied_runs(map, block);
        }
        chart.rects(&runs, colours::WORLD);
    }
    let wall = Stroke::solid(colours::WORLD, 3.0);
    for w in &s.world.walls {
        chart.line(&[(w.from[0], w.from[1]), (w.to[0], w.to[1])], wall);
    }
    for b in &s.world.boards {
        chart.polygon(
            &board_corners(b),
            "#b9b9b9",
            Stroke::solid(colours::WORLD, 1.0),
        );
    }
    for c in &s.world.cylinders {
        chart.circle(
            (c.center[0], c.center[1]),
            c.radius,
            "#d6d6d6",
            Stroke::solid(colours::WORLD, 1.5),
        );
    }
}

/// One revolution's readings placed in the world.
struct Scan {
    rev: u64,
    pose: Option<Pose>,
    raw: Vec<(f64, f64)>,
    calibrated: Vec<(f64, f64)>,
}

/// A few revolutions spread over the run, among those with the most valid readings.
fn chosen_revolutions(view: &View<'_>) -> Vec<u64> {
    let Some(revs) = view.revolutions.as_deref() else {
        return Vec::new();
    };
    if view.reference == "none" {
        return Vec::new();
    }
    let most = revs.iter().map(|r| r.valid).max().unwrap_or(0);
    // Complete revolutions only: at least half as many valid readings as the best one.
    let full: Vec<u64> = revs
        .iter()
        .filter(|r| r.valid * 2 >= most && r.valid > 0)
        .map(|r| r.rev)
        .collect();
    if full.is_empty() {
        return Vec::new();
    }
    let mut chosen: Vec<u64> = (0..SCANS)
        .map(|k| full[((k as f64 + 0.5) / SCANS as f64 * full.len() as f64) as usize % full.len()])
        .collect();
    chosen.dedup();
    chosen
}

/// Revolution `rev`'s valid readings in the world frame, each from the pose at its own time.
fn scan(view: &View<'_>, rev: u64) -> Scan {
    let rec = view.inputs.recording;
    let mount = rec.meta.lidar.unwrap_or_default();
    let alpha = view.calibrated(Sensor::Lidar).map(|(_, a)| a.to_vec());
    let readings: Vec<&LidarSample> = rec
        .lidar
        .iter()
        .flatten()
        .filter(|s| s.rev == rev && !s.invalid)
        .collect();
    let mut out = Scan {
        rev,
        pose: readings.first().and_then(|s| view.pose_at(s.t_s)),
        raw: Vec::new(),
        calibrated: Vec::new(),
    };
    for s in readings {
        let Some(robot) = view.pose_at(s.t_s) else {
            continue;
        };
        let lidar = mount.in_world(&robot);
        let at = |range: f64| {
            let p = lidar.transform([range * beam_rad(s).cos(), range * beam_rad(s).sin()]);
            (p[0], p[1])
        };
        out.raw.push(at(s.range_m));
        if let Some(d) = alpha.as_deref().and_then(|a| invert(a, s.range_m)) {
            out.calibrated.push(at(d));
        }
    }
    out
}

#[cfg(test)]
mod map_cells {
    use super::*;

    #[test]
    fn a_maps_occupied_cells_are_drawn_as_runs_along_rows_and_in_blocks_when_coarse() {
        let mut map = OccupancyMap::new(0.1, [-1.0, 2.0], 8, 4).unwrap();
        for ix in 2..6 {
            map.set_cell(ix, 1, Cell::Occupied);
        }
        map.set_cell(7, 3, Cell::Occupied);
        let runs = occupied_runs(&map, 1);
        assert_eq!(runs.len(), 2, "{runs:?}");
        let (x0, y0, x1, y1) = runs[0];
        assert!(
            (x0 + 0.8).abs() < 1e-12 && (x1 + 0.4).abs() < 1e-12,
            "{runs:?}"
        );
        assert!(
            (y0 - 2.1).abs() < 1e-12 && (y1 - 2.2).abs() < 1e-12,
            "{runs:?}"
        );
        // In 2 × 2 blocks: the row of four is two blocks, one run; the lone cell its own.
        assert_eq!(occupied_runs(&map, 2).len(), 2);
    }
}
