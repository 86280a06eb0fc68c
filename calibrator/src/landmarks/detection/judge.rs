//! A segment's verdict: the tests that a cylinder of the landmark radius passes and a wall or
//! clutter does not, then the detection's bearing (edges or circle fit) and range (the central
//! beams; module docs of [`super`]).

use super::{beam, occluded, points, Detection, Reject, Segment, FREE_FIT_MIN_BEAMS};
use crate::landmarks::circle_fit::{dist, fit_free, fit_known_radius, line_rms};
use crate::landmarks::options::DetectionOptions;
use crate::landmarks::scan::{Beam, StopScan};
use hilsim_recording::wrap_angle;

/// A segment's verdict: each test a cylinder of radius `r` passes and a wall or clutter does not,
/// then the detection's bearing and range.
pub(super) fn judge(
    scan: &StopScan,
    seg: Segment,
    stop: usize,
    r: f64,
    opts: &DetectionOptions,
) -> Result<Detection, Reject> {
    if seg.len < opts.min_beams {
        return Err(Reject::Short);
    }
    if occluded(scan, seg) {
        return Err(Reject::Occluded);
    }
    if return_fraction(scan, seg) < opts.min_return_fraction {
        return Err(Reject::Intermittent);
    }
    let (pts, angles) = points(scan, seg);
    let circle = fit_cylinder(scan, seg, &pts, &angles, r, opts)?;
    let free_radius_m = free_radius(scan, seg, &pts, r, opts)?;
    // The edges' bearing, unless it disagrees with the circle fit by more than the fit's own
    // uncertainty allows (a beam spacing plus a quarter of the landmark's angular width): then
    // something else shapes the hit profile.
    let psi_fit = circle.psi;
    let (psi, from_edges) = match edge_bearing(scan, seg, &angles) {
        Some(b)
            if (b - psi_fit).abs()
                < scan.grid.step_deg.to_radians() + circle.half.to_radians() / 2.0 =>
        {
            (b, true)
        }
        _ => (psi_fit, false),
    };
    let range = central_range(scan, seg, &angles, psi, &circle, r, opts)?;
    Ok(Detection {
        stop,
        bearing_rad: wrap_angle(psi),
        fit_bearing_rad: wrap_angle(psi_fit),
        from_edges,
        centre_range_m: circle.d_c,
        range_m: range.range_m,
        count: range.count,
        residuals: range.residuals,
        true_range_m: range.true_range_m,
        first_beam: seg.first,
        beams: seg.len,
        free_radius_m,
    })
}

/// The mean share of the samples that returned, over the segment's interior beams.
///
/// A landmark within range returns in (nearly) every revolution; a surface near the end of the
/// XV-11's range drops out whenever the noise pushes a reading past it, and breaks into
/// fragments that a cylinder's extent can match. The edge beams are excused (beam jitter).
fn return_fraction(scan: &StopScan, seg: Segment) -> f64 {
    let interior: Vec<usize> = if seg.len > 2 {
        (1..seg.len - 1).collect()
    } else {
        (0..seg.len).collect()
    };
    interior
        .iter()
        .map(|&i| {
            let b = beam(scan, seg, i);
            b.readings.len() as f64 / b.samples.max(1) as f64
        })
        .sum::<f64>()
        / interior.len() as f64
}

/// The circle of the landmark radius fitted to a segment.
struct CylinderFit {
    /// Distance of the centre from the lidar, metres.
    d_c: f64,
    /// Bearing of the centre, radians, unwrapped next to the segment's angles.
    psi: f64,
    /// The cylinder's angular half-width, degrees.
    half: f64,
}

/// Fits the circle of radius `r` to the segment's points, rejecting segments too far, too long,
/// with edges misplaced for the radius, or straighter than the circle.
fn fit_cylinder(
    scan: &StopScan,
    seg: Segment,
    pts: &[[f64; 2]],
    angles: &[f64],
    r: f64,
    opts: &DetectionOptions,
) -> Result<CylinderFit, Reject> {
    let n = pts.len();
    let ranges: Vec<f64> = (0..n).map(|i| beam(scan, seg, i).mean_m).collect();
    let near = ranges.iter().copied().fold(f64::INFINITY, f64::min);
    if near > opts.max_range_m {
        return Err(Reject::Far);
    }
    // Beam spacing at the segment's range, plus the noise of the averaged ends.
    let spacing = near * scan.grid.step_deg.to_radians();
    let end_noise = 2.0 * (beam(scan, seg, 0).sem_m() + beam(scan, seg, n - 1).sem_m());
    if dist(pts[0], pts[n - 1]) > 2.0 * r + 2.0 * spacing + end_noise + 0.02 {
        return Err(Reject::TooLong);
    }
    let mid = (angles[0] + angles[n - 1]) / 2.0;
    let init = [(near + r) * mid.cos(), (near + r) * mid.sin()];
    let w = vec![1.0; n];
    let Some(circle) = fit_known_radius(pts, &w, r, init) else {
        return Err(Reject::Fit);
    };
    let d_c = circle.centre[0].hypot(circle.centre[1]);
    if !(d_c > r && d_c > near) {
        return Err(Reject::Fit);
    }
    let psi = circle.centre[1].atan2(circle.centre[0]);
    // Unwrap ψ next to the segment's angles.
    let psi = mid + wrap_angle(psi - mid);
    let half = (r / d_c).asin().to_degrees();
    let lo = (psi - angles[0]).to_degrees();
    let hi = (angles[n - 1] - psi).to_degrees();
    let tol = opts.edge_tolerance_deg;
    let edge_ok = |e: f64| e >= half - 1.0 - tol && e <= half + tol;
    if !(edge_ok(lo) && edge_ok(hi)) {
        return Err(Reject::Edges);
    }
    if n >= 4 && line_rms(pts, &w) < 0.5 * circle.rms {
        return Err(Reject::Straight);
    }
    Ok(CylinderFit { d_c, psi, half })
}

/// The radius of a free circle fit when the segment has enough beams for one; a segment whose
/// free radius is not `r` within the tolerance is rejected.
fn free_radius(
    scan: &StopScan,
    seg: Segment,
    pts: &[[f64; 2]],
    r: f64,
    opts: &DetectionOptions,
) -> Result<Option<f64>, Reject> {
    let n = pts.len();
    let free = if n >= FREE_FIT_MIN_BEAMS {
        // Weighted by the averaged beams' inverse variances, so the radius's standard error is
        // that of the data: a noisy far segment cannot be told apart by its radius.
        let wv: Vec<f64> = (0..n)
            .map(|i| 1.0 / beam(scan, seg, i).sem_m().max(1e-3).powi(2))
            .collect();
        fit_free(pts, &wv)
    } else {
        None
    };
    if let Some(fr) = free {
        if (fr.radius - r).abs() > opts.radius_tolerance * r + 3.0 * fr.radius_se {
            return Err(Reject::Radius);
        }
    }
    Ok(free.map(|c| c.radius))
}

/// r̃ from the central beams, with what goes with it.
struct CentralRange {
    /// The mean depth-corrected reading, metres.
    range_m: f64,
    /// How many readings it averages.
    count: usize,
    /// Each averaged reading less `range_m`.
    residuals: Vec<f64>,
    /// The same from the simulator's true ranges, when every reading has one.
    true_range_m: Option<f64>,
}

/// The central beams measure the range (module docs): their readings towards bearing `psi`,
/// each less the circle's extra depth at its angle.
fn central_range(
    scan: &StopScan,
    seg: Segment,
    angles: &[f64],
    psi: f64,
    circle: &CylinderFit,
    r: f64,
    opts: &DetectionOptions,
) -> Result<CentralRange, Reject> {
    let (d_c, half) = (circle.d_c, circle.half);
    let window = (opts.central_fraction * half).max(0.5 + 1e-9);
    let (mut sum, mut tsum, mut count, mut tcount) = (0.0, 0.0, 0usize, 0usize);
    let mut corrected = Vec::new();
    for (i, angle) in angles.iter().enumerate() {
        let a = angle - psi;
        if a.to_degrees().abs() > window {
            continue;
        }
        let s = d_c * a.sin();
        if s.abs() >= r {
            continue;
        }
        let depth = d_c * a.cos() - (r * r - s * s).sqrt() - (d_c - r);
        for reading in &beam(scan, seg, i).readings {
            let v = reading.range_m - depth;
            sum += v;
            count += 1;
            corrected.push(v);
            if let Some(t) = reading.true_range_m {
                tsum += t - depth;
                tcount += 1;
            }
        }
    }
    if count == 0 {
        return Err(Reject::Fit);
    }
    let range_m = sum / count as f64;
    Ok(CentralRange {
        range_m,
        count,
        residuals: corrected.iter().map(|v| v - range_m).collect(),
        true_range_m: (tcount == count).then(|| tsum / tcount as f64),
    })
}

/// The bearing as the centroid of the beams' hit fractions: the fraction of a beam's samples
/// that returned from the landmark (nearer than halfway to the background on that side). The
/// hit profile is the cylinder's angular extent blurred by the beam jitter, symmetric about the
/// centre's direction, so its centroid is the bearing, resolved below the beam spacing and free
/// of the range noise that moves a circle fit. `None` when the background on either side is too
/// close behind the landmark to tell a hit from a miss (four single-reading deviations).
fn edge_bearing(scan: &StopScan, seg: Segment, angles: &[f64]) -> Option<f64> {
    let b = &scan.beams;
    let n = seg.len;
    let at = |k: isize| &b[(seg.first as isize + k).rem_euclid(b.len() as isize) as usize];
    let side = |edge: &Beam, out: &Beam| -> Option<f64> {
        if out.valid {
            let gap = out.mean_m - edge.mean_m;
            (gap > 4.0 * edge.sd_m.max(out.sd_m)).then_some(edge.mean_m + gap / 2.0)
        } else {
            // No background return: a reading is a hit if it is near the edge's range.
            Some(edge.mean_m + (4.0 * edge.sd_m).max(0.1))
        }
    };
    let left = side(at(0), at(-1))?;
    let right = side(at(n as isize - 1), at(n as isize))?;
    let step = angles
        .get(1)
        .map_or(scan.grid.step_deg.to_radians(), |a| a - angles[0]);
    let (mut sw, mut swa) = (0.0, 0.0);
    for k in -2..(n as isize + 2) {
        let beam = at(k);
        if beam.samples == 0 {
            continue;
        }
        let tau = if k < (n as isize) / 2 { left } else { right };
        let hits = beam.all_m.iter().filter(|r| **r < tau).count();
        let p = hits as f64 / beam.samples as f64;
        let outside = k < 0 || k >= n as isize;
        if outside && p > 0.5 {
            // Another object next to this one: the profile is no longer this landmark's alone.
            return None;
        }
        let a = angles[0] + k as f64 * step;
        sw += p;
        swa += p * a;
    }
    (sw > 0.0).then(|| swa / sw)
}
