//! The lidar's mount yaw that a log's own scans, placed at its truth's poses, agree on. A map
//! built from a log's scans takes in a turned lidar: each scan is turned about the place the
//! robot saw it from, so a wall seen from two places lands twice, a little apart, and the walls
//! smear. Judged against that map, the turn is partly the map's and is not told apart. Turned
//! back by the right yaw, the scans land on one another again and the map is at its crispest:
//! the scans' points are then most concentrated, measured as their quadratic Rényi entropy's
//! argument (the sum over cells of the squared share of points in each), the criterion of
//! extrinsic lidar self-calibration (Sheehan, Harrison and Newman, "Self-calibration for a 3D
//! laser", IJRR 31(5), 2012; Maddern, Harrison and Newman, "Lost in translation (and rotation):
//! rapid extrinsic calibration for 2D and 3D LIDARs", ICRA 2012).

use hilsim_recording::{Mount, Recording};

use crate::trajectory::Trajectory;

/// The mount yaws searched, degrees either side of the declared one: the catalogue's mount
/// search (`LidarMountOffset`'s yaw, ±8°).
const SEARCH_DEG: f64 = 8.0;
/// The search's first grid step, degrees: narrower than the crispness's peak (about a degree
/// wide at half its height on an indoor log), so the grid lands on the peak's slope.
const GRID_STEP_DEG: f64 = 0.25;
/// The yaw's resolution once refined, degrees: a tenth of the mount's least named yaw
/// (`Effect::departs`, 0.15°).
const RESOLUTION_DEG: f64 = 0.015;
/// The cells points are counted in, metres: a few times an indoor SICK's or Hokuyo's
/// centimetre noise, so a wall's points share their cells; each point is shared between its
/// four nearest cell centres (bilinearly), so the count moves smoothly with the yaw.
const CELL_M: f64 = 0.05;
/// The most readings counted: every k-th valid reading beyond it (an hour's log holds
/// millions; a few hundred thousand points fix a yaw to hundredths of a degree).
const MAX_POINTS: usize = 400_000;
/// The most cells the count may take (32 MB of `f64`): a larger world is counted in coarser
/// cells.
const MAX_CELLS: usize = 4_000_000;

/// The mount yaw, degrees from the declared one, at which `recording`'s valid readings within
/// `max_range_m`, placed at its truth's poses through its declared mount, are most
/// concentrated (module docs); `None` without a truth, a lidar or enough readings (a hundred).
#[must_use]
pub(crate) fn crispest_mount_yaw_deg(recording: &Recording, max_range_m: f64) -> Option<f64> {
    let truth = recording.truth.as_deref()?;
    let path = Trajectory::new(truth).ok()?;
    let mount: Mount = recording.meta.lidar.unwrap_or_default();
    let valid: Vec<_> = recording
        .lidar
        .as_deref()?
        .iter()
        .filter(|s| !s.invalid && s.range_m > 0.0 && s.range_m <= max_range_m)
        .filter(|s| s.t_s >= path.times()[0] && s.t_s <= path.end_s())
        .collect();
    if valid.len() < 100 {
        return None;
    }
    let stride = valid.len().div_ceil(MAX_POINTS);
    // Each reading as the lidar's place and the beam's heading in the world at the declared
    // mount, and its range.
    let beams: Vec<[f64; 4]> = valid
        .iter()
        .step_by(stride)
        .map(|s| {
            let lidar = mount.in_world(&path.pose_at(s.t_s));
            [
                lidar.x,
                lidar.y,
                lidar.yaw + s.angle_deg.to_radians(),
                s.range_m,
            ]
        })
        .collect();
    let grid = Grid::around(&beams)?;
    let mut scratch = Scratch {
        counts: vec![0.0; grid.cells()],
        touched: Vec::with_capacity(4 * beams.len()),
        ends: Vec::with_capacity(beams.len()),
    };
    let mut crispness = |yaw_deg: f64| grid.crispness(&beams, yaw_deg.to_radians(), &mut scratch);
    // The grid, then a golden-section search about its best.
    let steps = (SEARCH_DEG / GRID_STEP_DEG).round() as i32;
    let (mut best, mut best_value) = (0.0, f64::NEG_INFINITY);
    for k in -steps..=steps {
        let yaw = f64::from(k) * GRID_STEP_DEG;
        let value = crispness(yaw);
        if value > best_value {
            (best, best_value) = (yaw, value);
        }
    }
    let golden = (5.0_f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (best - GRID_STEP_DEG, best + GRID_STEP_DEG);
    let (mut a, mut b) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
    let (mut fa, mut fb) = (crispness(a), crispness(b));
    while hi - lo > RESOLUTION_DEG {
        if fa > fb {
            (hi, b, fb) = (b, a, fa);
            a = hi - golden * (hi - lo);
            fa = crispness(a);
        } else {
            (lo, a, fa) = (a, b, fb);
            b = lo + golden * (hi - lo);
            fb = crispness(b);
        }
    }
    Some(0.5 * (lo + hi))
}

/// What one count of the points needs, kept between counts: each cell's count (zero but
/// where `touched` says), the cells touched, and the points' ends.
struct Scratch {
    counts: Vec<f64>,
    touched: Vec<usize>,
    ends: Vec<[f64; 2]>,
}

/// The cells the points may fall in at any yaw searched.
struct Grid {
    origin: [f64; 2],
    cell_m: f64,
    /// Cells a row, and rows.
    wide: usize,
    high: usize,
}

impl Grid {
    /// A grid holding every beam's end at the declared mount, widened by as far as the
    /// search's turn moves the farthest one (the chord of its range over the search's span);
    /// `None` for a world so large its cells would be coarser than a metre.
    fn around(beams: &[[f64; 4]]) -> Option<Self> {
        let longest = beams.iter().map(|b| b[3]).fold(0.0, f64::max);
        let reach = 2.0
            * longest
            * SEARCH_DEG
                .to_radians()
                .min(std::f64::consts::FRAC_PI_2)
                .sin()
            + 2.0 * CELL_M;
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for &[x, y, heading, range] in beams {
            let end = [x + range * heading.cos(), y + range * heading.sin()];
            for a in 0..2 {
                lo[a] = lo[a].min(end[a] - reach);
                hi[a] = hi[a].max(end[a] + reach);
            }
        }
        let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
        let cell_m = CELL_M.max((area / MAX_CELLS as f64).sqrt());
        if !(cell_m.is_finite() && cell_m <= 1.0) {
            return None;
        }
        let wide = ((hi[0] - lo[0]) / cell_m).ceil() as usize + 1;
        let high = ((hi[1] - lo[1]) / cell_m).ceil() as usize + 1;
        Some(Self {
            origin: lo,
            cell_m,
            wide,
            high,
        })
    }

    fn cells(&self) -> usize {
        self.wide * self.high
    }

    /// The sum over cells of the squared share of `beams`' end points in each, the beams
    /// turned by `yaw_rad`, averaged over the grid laid at four offsets half a cell apart: on
    /// one grid a straight wall's points share one column of cells or split between two as
    /// the wall happens to fall, and the average over offsets is nearly the same wherever it
    /// falls (a kernel's sum over pairs of points, which the entropy is). `scratch`'s counts
    /// are [`Grid::cells`] long.
    fn crispness(&self, beams: &[[f64; 4]], yaw_rad: f64, scratch: &mut Scratch) -> f64 {
        scratch.ends.clear();
        scratch
            .ends
            .extend(beams.iter().map(|&[x, y, heading, range]| {
                let a = heading + yaw_rad;
                [x + range * a.cos(), y + range * a.sin()]
            }));
        [[0.0, 0.0], [0.5, 0.0], [0.0, 0.5], [0.5, 0.5]]
            .iter()
            .map(|offset| self.concentration(*offset, scratch))
            .sum::<f64>()
            / 4.0
    }

    /// The sum over cells of the squared share of `scratch`'s ends in each, the grid moved by
    /// `offset` cells. Only the cells the ends touch are read and cleared again: the grid
    /// spans the whole log's world, the ends' cells a small part of it.
    fn concentration(&self, offset: [f64; 2], scratch: &mut Scratch) -> f64 {
        let Scratch {
            counts,
            touched,
            ends,
        } = scratch;
        touched.clear();
        for &[x, y] in ends.iter() {
            let u = (x - self.origin[0]) / self.cell_m + offset[0];
            let v = (y - self.origin[1]) / self.cell_m + offset[1];
            let (i, j) = (u.floor(), v.floor());
            let (fu, fv) = (u - i, v - j);
            let (i, j) = (i as usize, j as usize);
            if i + 1 >= self.wide || j + 1 >= self.high {
                continue;
            }
            let k = j * self.wide + i;
            for (cell, share) in [
                (k, (1.0 - fu) * (1.0 - fv)),
                (k + 1, fu * (1.0 - fv)),
                (k + self.wide, (1.0 - fu) * fv),
                (k + self.wide + 1, fu * fv),
            ] {
                counts[cell] += share;
                touched.push(cell);
            }
        }
        // A cell touched twice is read once: cleared as it is read, it reads 0 again.
        let mut sum = 0.0;
        for &cell in touched.iter() {
            sum += counts[cell] * counts[cell];
            counts[cell] = 0.0;
        }
        let n = ends.len() as f64;
        sum / (n * n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_recording::{LidarSample, TruthSample};
    use rand_xoshiro::rand_core::{RngCore, SeedableRng};
    use rand_xoshiro::SplitMix64;

    /// A robot driving a loop in a 6 × 4 m room shifted by `shifted_m` in x and y, its lidar
    /// turned `turned_deg` from the declared mount (its readings' angles that much smaller),
    /// one scan of 360 beams a second with a centimetre's range noise (without any, every point
    /// of a straight wall crosses a cell's edge at once, and the count jumps with the room's
    /// place on the cells by a few tenths of a degree). The crispest yaw is to be the turn
    /// within 0.1°, two-thirds of the least mount yaw the catalogue names: over 0.1° a wall 3 m
    /// away moves 5 mm, a tenth of a cell, which this short log's 7,200 points barely resolve.
    fn room_seen_turned(turned_deg: f64, shifted_m: f64) -> Recording {
        let mut recording = Recording::default();
        let pose = |t: f64| {
            let a = 0.4 * t;
            (
                shifted_m + 1.5 * a.cos(),
                shifted_m + 1.0 * a.sin(),
                a + std::f64::consts::FRAC_PI_2,
            )
        };
        recording.truth = Some(
            (0..=200)
                .map(|k| {
                    let t = 0.1 * f64::from(k);
                    let (x_m, y_m, yaw_rad) = pose(t);
                    TruthSample {
                        t_s: t,
                        x_m,
                        y_m,
                        yaw_rad,
                    }
                })
                .collect(),
        );
        // A centimetre's range noise, as a SICK's or a Hokuyo's (Box–Muller on a fixed stream).
        let mut stream = SplitMix64::seed_from_u64(7);
        let mut unit = || (stream.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let mut noise_m = || {
            let (u, v) = (unit().max(f64::MIN_POSITIVE), unit());
            0.01 * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        let mut lidar = Vec::new();
        for scan in 0..20_u32 {
            let t = f64::from(scan);
            let (x, y, yaw) = pose(t);
            for beam in 0..360 {
                let world = yaw + f64::from(beam).to_radians();
                let (c, s) = (world.cos(), world.sin());
                // The nearest of the four walls x = ±3, y = ±2 along the beam.
                let (x, y) = (x - shifted_m, y - shifted_m);
                let range = [(3.0 - x) / c, (-3.0 - x) / c, (2.0 - y) / s, (-2.0 - y) / s]
                    .into_iter()
                    .filter(|d| d.is_finite() && *d > 0.0)
                    .fold(f64::INFINITY, f64::min);
                lidar.push(LidarSample {
                    t_s: t,
                    rev: u64::from(scan),
                    angle_deg: (f64::from(beam) - turned_deg).rem_euclid(360.0),
                    range_m: range + noise_m(),
                    strength: 0,
                    invalid: false,
                    warning: false,
                    true_range_m: None,
                });
            }
        }
        recording.lidar = Some(lidar);
        recording
    }

    /// Wherever the room lies on the cells (shifted by fractions of one), the same yaw.
    #[test]
    fn the_crispest_yaw_is_the_lidars_turn() {
        for turned in [0.0, 1.7, -2.6] {
            for shifted in [0.0, 0.017, 0.031] {
                let recording = room_seen_turned(turned, shifted);
                let yaw = crispest_mount_yaw_deg(&recording, 30.0).expect("a yaw");
                assert!(
                    (yaw - turned).abs() < 0.1,
                    "turned {turned}°, shifted {shifted} m, found {yaw}°"
                );
            }
        }
    }

    #[test]
    fn without_a_truth_there_is_no_yaw() {
        let mut recording = room_seen_turned(1.0, 0.0);
        recording.truth = None;
        assert!(crispest_mount_yaw_deg(&recording, 30.0).is_none());
    }
}
