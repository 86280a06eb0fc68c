//! The sensors over time, on one time axis: the wheel speeds commanded and measured, the
//! distance ahead as the lidar's forward beam and the sonar read it (and the truth), and the
//! valid lidar readings per revolution.

use hilsim_recording::wrap_angle;

use crate::colours;
use crate::svg::{quantile, thin, Chart, Key, Span, Stroke};
use crate::view::View;

/// Points a line shows at most.
const POINTS: usize = 3000;

/// The window the odometry's speed is measured over, seconds: long enough that encoder noise
/// of a few millimetres moves the speed by under 0.01 m/s, short enough to show a stop of 1 s.
const SPEED_WINDOW_S: f64 = 0.5;

/// The timeline charts (those the recording has data for).
#[must_use]
pub fn timelines(view: &View<'_>) -> Vec<String> {
    let rec = view.inputs.recording;
    let t = Span::new(0.0, rec.duration_s().max(1e-3));
    let mut out = Vec::new();
    if let Some(chart) = wheel_speeds(view, t) {
        out.push(chart);
    }
    if let Some(chart) = distance_ahead(view, t) {
        out.push(chart);
    }
    if let Some(chart) = readings_per_revolution(view, t) {
        out.push(chart);
    }
    out
}

/// Commanded and measured (odometry) wheel speeds.
fn wheel_speeds(view: &View<'_>, t: Span) -> Option<String> {
    let rec = view.inputs.recording;
    let mut left = Vec::new();
    let mut right = Vec::new();
    // Commands hold until the next one: drawn as steps.
    for (i, c) in rec.commands.iter().enumerate() {
        if i > 0 {
            let prev = &rec.commands[i - 1];
            left.push((c.t_s, prev.left_mps));
            right.push((c.t_s, prev.right_mps));
        }
        left.push((c.t_s, c.left_mps));
        right.push((c.t_s, c.right_mps));
    }
    let mut measured_left = Vec::new();
    let mut measured_right = Vec::new();
    if let Some(odo) = rec.odometry.as_deref() {
        let mut j = 0;
        for o in odo {
            while j < odo.len() && odo[j].t_s < o.t_s - SPEED_WINDOW_S {
                j += 1;
            }
            let a = &odo[j.min(odo.len() - 1)];
            let dt = o.t_s - a.t_s;
            if dt >= SPEED_WINDOW_S / 2.0 {
                let mid = (o.t_s + a.t_s) / 2.0;
                measured_left.push((mid, (o.left_m - a.left_m) / dt));
                measured_right.push((mid, (o.right_m - a.right_m) / dt));
            }
        }
    }
    if left.is_empty() && measured_left.is_empty() {
        return None;
    }
    let y = Span::of(
        left.iter()
            .chain(&right)
            .chain(&measured_left)
            .chain(&measured_right)
            .map(|p| p.1)
            .chain([0.0]),
    )
    .padded(0.1);
    let mut chart = Chart::new("wheels", 900.0, 260.0, t, y);
    chart.axes("Wheel speeds", "time (s)", "speed (m/s)");
    let mut keys = Vec::new();
    let series = [
        (
            &measured_left,
            Stroke::solid("#9cc3f0", 1.2),
            "left, odometry",
        ),
        (
            &measured_right,
            Stroke::solid("#f0a9a7", 1.2),
            "right, odometry",
        ),
        (&left, Stroke::solid(colours::LEFT, 2.0), "left, commanded"),
        (
            &right,
            Stroke::dashed(colours::RIGHT, 2.0),
            "right, commanded",
        ),
    ];
    for (points, stroke, label) in series {
        if !points.is_empty() {
            chart.line(&thin(points, POINTS), stroke);
            keys.push(Key::Line(stroke, label.into()));
        }
    }
    chart.legend(&keys);
    Some(chart.finish())
}

/// The lidar's forward beam (the reading nearest 0° of each revolution) and the sonar, with
/// their true distances when known.
fn distance_ahead(view: &View<'_>, t: Span) -> Option<String> {
    let mut forward: Vec<(u64, f64, f64, f64, f64)> = Vec::new(); // rev, |angle|, t, reading, true
    for s in &view.lidar {
        let off = wrap_angle(s.angle_deg.to_radians()).abs();
        match forward.last_mut() {
            Some(f) if f.0 == s.rev => {
                if off < f.1 {
                    *f = (s.rev, off, s.t_s, s.reading_m, s.true_m);
                }
            }
            _ => forward.push((s.rev, off, s.t_s, s.reading_m, s.true_m)),
        }
    }
    // Only revolutions whose nearest reading is within 2° of the axis.
    forward.retain(|f| f.1 <= 2f64.to_radians());
    let lidar: Vec<(f64, f64)> = forward.iter().map(|f| (f.2, f.3)).collect();
    let lidar_true: Vec<(f64, f64)> = forward.iter().map(|f| (f.2, f.4)).collect();
    let sonar: Vec<(f64, f64)> = view.sonar.iter().map(|s| (s.t_s, s.reading_m)).collect();
    let sonar_true: Vec<(f64, f64)> = view.sonar.iter().map(|s| (s.t_s, s.true_m)).collect();
    if lidar.is_empty() && sonar.is_empty() {
        return None;
    }
    let all: Vec<f64> = lidar
        .iter()
        .chain(&lidar_true)
        .chain(&sonar)
        .chain(&sonar_true)
        .map(|p| p.1)
        .filter(|v| v.is_finite())
        .collect();
    let y = Span::new(0.0, quantile(&all, 0.995) * 1.08);
    let mut chart = Chart::new("ahead", 900.0, 300.0, t, y);
    chart.axes("The distance ahead", "time (s)", "range (m)");
    let mut keys = Vec::new();
    let truth_known = |p: &[(f64, f64)]| p.iter().any(|q| q.1.is_finite());
    let series = [
        (
            &lidar,
            Stroke::solid(colours::RAW, 1.6),
            "lidar, forward beam",
        ),
        (&sonar, Stroke::solid(colours::SONAR, 1.6), "sonar"),
    ];
    for (points, stroke, label) in series {
        if !points.is_empty() {
            chart.line(&thin(points, POINTS), stroke);
            keys.push(Key::Line(stroke, label.into()));
        }
    }
    let truths = [
        (
            &lidar_true,
            Stroke::solid(colours::TRUTH, 1.2),
            "true distance, lidar beam",
        ),
        (
            &sonar_true,
            Stroke::dashed(colours::TRUTH, 1.2),
            "true distance, sonar axis",
        ),
    ];
    for (points, stroke, label) in truths {
        if truth_known(points) {
            chart.line(&thin(points, POINTS), stroke);
            keys.push(Key::Line(stroke, label.into()));
        }
    }
    chart.legend(&keys);
    Some(chart.finish())
}

/// How many valid readings each revolution holds: dropped packets and out-of-range beams show.
fn readings_per_revolution(view: &View<'_>, t: Span) -> Option<String> {
    let revs = view.revolutions.as_deref()?;
    if revs.is_empty() {
        return None;
    }
    let valid: Vec<(f64, f64)> = revs.iter().map(|r| (r.t_s, r.valid as f64)).collect();
    let all: Vec<(f64, f64)> = revs.iter().map(|r| (r.t_s, r.readings as f64)).collect();
    let y = Span::new(
        0.0,
        revs.iter().map(|r| r.readings).max().unwrap_or(1) as f64 * 1.1,
    );
    let mut chart = Chart::new("perrev", 900.0, 220.0, t, y);
    chart.axes("Lidar readings per revolution", "time (s)", "readings");
    let all_stroke = Stroke::solid("#9a9a9a", 1.2);
    let valid_stroke = Stroke::solid(colours::RAW, 1.6);
    chart.line(&thin(&all, POINTS), all_stroke);
    chart.line(&thin(&valid, POINTS), valid_stroke);
    chart.legend(&[
        Key::Line(all_stroke, "readings".into()),
        Key::Line(valid_stroke, "valid readings".into()),
    ]);
    Some(chart.finish())
}
