//! Each range sensor's error against the true distance: the readings, their binned mean, the
//! bias curve and ±σ band the scenario declares, and each calibration's fitted ones (eq. 2 of
//! both papers: reading = Σ α_i d^i + (Σ β_i d^i) e, so the error is Σ α_i d^i − d ± Σ β_i d^i).

use hilsim_calibrator::Sensor;
use hilsim_lidar_emulator::RangeModel;

use crate::colours;
use crate::svg::{quantile, thin, Chart, Key, Span, Stroke};
use crate::view::{Scored, View};

/// Readings drawn at most per chart (evenly thinned; the binned mean uses them all).
const POINTS: usize = 4000;

/// Bins of the binned mean over the true distance.
const BINS: usize = 40;

/// Readings a bin needs before its mean is drawn: with the XV-11's 1 % noise at 3 m (3 cm), the
/// mean of 20 is good to 7 mm, below what the chart resolves.
const MIN_PER_BIN: usize = 20;

/// The lidar's and the sonar's error charts (those that have readings with true distances).
#[must_use]
pub fn error_charts(view: &View<'_>) -> Vec<String> {
    let scenario = view.inputs.scenario;
    let declared = |sensor: Sensor| {
        let (bias, noise) = match sensor {
            Sensor::Lidar => scenario
                .and_then(|s| s.sensors.lidar.as_ref())
                .map(|l| (l.bias.clone(), l.noise.clone()))?,
            Sensor::Sonar => scenario
                .and_then(|s| s.sensors.sonar.as_ref())
                .map(|l| (l.bias.clone(), l.noise.clone()))?,
            Sensor::Odometer => return None,
        };
        RangeModel::builder().bias(bias).noise(noise).build().ok()
    };
    [(Sensor::Lidar, &view.lidar), (Sensor::Sonar, &view.sonar)]
        .into_iter()
        .filter_map(|(sensor, scored)| chart(view, sensor, scored, declared(sensor)))
        .collect()
}

/// One sensor's chart; `None` without readings whose true distance is known.
fn chart(
    view: &View<'_>,
    sensor: Sensor,
    scored: &[Scored],
    declared: Option<RangeModel>,
) -> Option<String> {
    let known: Vec<(f64, f64)> = scored
        .iter()
        .filter(|s| s.true_m.is_finite() && s.true_m > 0.0)
        .map(|s| (s.true_m, (s.reading_m - s.true_m) * 1000.0))
        .collect();
    if known.is_empty() {
        return None;
    }
    let x = Span::new(
        0.0,
        quantile(&known.iter().map(|p| p.0).collect::<Vec<_>>(), 1.0) * 1.04,
    );
    // The errors' range: their 1st–99th percentiles, the curves, and zero.
    let errors: Vec<f64> = known.iter().map(|p| p.1).collect();
    let grid: Vec<f64> = (0..=100)
        .map(|i| x.lo + (x.hi - x.lo) * i as f64 / 100.0)
        .collect();
    let mut curves: Vec<Curve> = Vec::new();
    if let Some(m) = &declared {
        curves.push((
            "declared bias ± σ (scenario)".into(),
            Stroke::solid(colours::DECLARED, 2.2),
            band(&grid, |d| (m.mean(d), m.std_dev(d))),
        ));
    }
    for c in view.inputs.calibrations {
        if let Some(m) = c.sensors.get(&sensor) {
            let Ok(model) = RangeModel::builder().bias(&m.alpha).noise(&m.beta).build() else {
                continue;
            };
            curves.push((
                format!("fitted bias ± σ ({})", c.method.name()),
                Stroke::dashed(colours::method(c.method), 2.2),
                band(&grid, |d| (model.mean(d), model.std_dev(d))),
            ));
        }
    }
    let mut ys = vec![0.0, quantile(&errors, 0.01), quantile(&errors, 0.99)];
    for (_, _, rows) in &curves {
        ys.extend(rows.iter().flat_map(|r| [r.1, r.2]));
    }
    let y = Span::of(ys).padded(0.08);
    let name = sensor.name();
    let mut chart = Chart::new(&format!("err{name}"), 900.0, 420.0, x, y);
    chart.axes(
        &format!("{name}: error against the true distance"),
        "true distance (m)",
        "reading − true distance (mm)",
    );
    let mut keys = vec![Key::Dots(colours::RAW, format!("{name} readings"))];
    for (label, stroke, rows) in &curves {
        chart.band(rows, stroke.colour, 0.13);
        let mid: Vec<(f64, f64)> = rows.iter().map(|r| (r.0, (r.1 + r.2) / 2.0)).collect();
        chart.line(&mid, *stroke);
        keys.push(Key::Line(*stroke, label.clone()));
    }
    chart.dots(&thin(&known, POINTS), colours::RAW, 1.4, 0.3);
    let means = binned_means(&known, x);
    let stroke = Stroke::solid(colours::TRUTH, 2.0);
    chart.line(&means, stroke);
    // Dots too: a bin between two empty ones is no line.
    chart.dots(&means, colours::TRUTH, 2.5, 1.0);
    keys.push(Key::Line(stroke, "mean of the readings".into()));
    chart.legend(&keys);
    Some(chart.finish())
}

/// A model's curve: its label, its line and its band's rows `(d, lower, upper)`, mm.
type Curve = (String, Stroke, Vec<(f64, f64, f64)>);

/// `(d, lower, upper)` of the error band, mm, over `grid`, from a model's (mean, σ) at d.
fn band(grid: &[f64], model: impl Fn(f64) -> (f64, f64)) -> Vec<(f64, f64, f64)> {
    grid.iter()
        .map(|&d| {
            let (mean, sd) = model(d);
            (d, (mean - d - sd) * 1000.0, (mean - d + sd) * 1000.0)
        })
        .collect()
}

/// The mean error in each of [`BINS`] bins of the true distance (bins with too few readings
/// break the line).
fn binned_means(points: &[(f64, f64)], x: Span) -> Vec<(f64, f64)> {
    let mut sum = [0.0; BINS];
    let mut count = [0usize; BINS];
    for &(d, e) in points {
        let b = (((d - x.lo) / (x.hi - x.lo)) * BINS as f64).floor();
        if (0.0..BINS as f64).contains(&b) {
            sum[b as usize] += e;
            count[b as usize] += 1;
        }
    }
    (0..BINS)
        .map(|b| {
            let centre = x.lo + (b as f64 + 0.5) / BINS as f64 * (x.hi - x.lo);
            if count[b] >= MIN_PER_BIN {
                (centre, sum[b] / count[b] as f64)
            } else {
                (centre, f64::NAN)
            }
        })
        .collect()
}
