//! A plot as a standalone SVG document, drawn with the project's one chart module
//! (`hilsim_report::svg`).

use hilsim_report::svg::{quantile, Chart, Key, Span, Stroke};

use crate::plot::PlotData;

/// Before the fix: the nominal simulation's residuals.
const BEFORE: &str = "#d9534f";
/// After the fix: the residuals under the fitted effect.
const AFTER: &str = "#1f6fd1";
/// The located range of the variable.
const LOCATED: &str = "#fff3c4";

/// Bins of a continuous variable's binned means.
const BINS: usize = 24;

/// Readings a bin needs before its mean and RMS are drawn.
const MIN_PER_BIN: usize = 5;

/// The plot as a standalone SVG document: residual (mm) against the variable, the held-out
/// readings as dots and their binned means as lines (a bar per category), with the binned RMS
/// dashed above and below zero, before (red) and after (blue) the fix.
#[must_use]
pub fn svg(p: &PlotData) -> String {
    let categorical = !p.categories.is_empty();
    let xs: Vec<f64> = if categorical {
        p.x.iter()
            .map(|v| {
                p.categories
                    .iter()
                    .position(|(c, _)| c == v)
                    .map_or(f64::NAN, |i| i as f64)
            })
            .collect()
    } else {
        p.x.clone()
    };
    let x = if categorical {
        Span::new(-0.5, p.categories.len() as f64 - 0.5)
    } else {
        Span::of(xs.iter().copied())
    };
    let lim = residual_limit(p, &xs, categorical) * 1.15 * 1000.0;
    let y = Span::new(-lim, lim);
    let mut chart = Chart::new(
        "residuals",
        760.0,
        if categorical { 480.0 } else { 420.0 },
        x,
        y,
    );
    if categorical {
        chart = chart.with_bottom_margin(120.0);
    }
    let unit = p.variable.unit();
    let x_label = if unit.is_empty() {
        p.variable.name().to_string()
    } else {
        format!("{} ({unit})", p.variable.name())
    };
    if categorical {
        let names: Vec<String> = p.categories.iter().map(|(_, n)| n.clone()).collect();
        chart.axes_categorical(&p.title, &names, "residual (mm)");
    } else {
        chart.axes(&p.title, &x_label, "residual (mm)");
    }
    if let Some((a, b)) = p.highlight {
        chart.strip(a, b, LOCATED);
    }
    let series: Vec<(&[f64], &'static str)> = std::iter::once((p.before.as_slice(), BEFORE))
        .chain(p.after.as_deref().map(|a| (a, AFTER)))
        .collect();
    // Readings as dots, jittered within a category so that they do not pile up on one line.
    for (values, colour) in &series {
        let points: Vec<(f64, f64)> = xs
            .iter()
            .zip(values.iter())
            .enumerate()
            .map(|(i, (&x, &r))| {
                let jitter = if categorical {
                    ((i as f64 * 0.618_034).fract() - 0.5) * 0.5
                } else {
                    0.0
                };
                (x + jitter, r * 1000.0)
            })
            .collect();
        chart.dots(&points, colour, 1.6, 0.25);
    }
    for (values, colour) in &series {
        let bins = binned(&xs, values, x, categorical);
        if categorical {
            for b in &bins {
                let stroke = Stroke::solid(colour, 5.0);
                chart.line(
                    &[(b.centre - 0.2, b.mean), (b.centre + 0.2, b.mean)],
                    stroke,
                );
            }
        } else {
            let dashed = Stroke {
                dash: Some("5,3"),
                ..Stroke::solid(colour, 1.2)
            };
            for sign in [1.0, -1.0] {
                let rms: Vec<(f64, f64)> = bins.iter().map(|b| (b.centre, sign * b.rms)).collect();
                chart.line(&rms, dashed);
            }
            let means: Vec<(f64, f64)> = bins.iter().map(|b| (b.centre, b.mean)).collect();
            chart.line(&means, Stroke::solid(colour, 2.5));
        }
    }
    let mut keys = vec![Key::Line(
        Stroke::solid(BEFORE, 2.5),
        if categorical {
            "before (nominal simulation): mean of each".into()
        } else {
            "before (nominal simulation): mean, and ± RMS dashed".into()
        },
    )];
    if p.after.is_some() {
        keys.push(Key::Line(
            Stroke::solid(AFTER, 2.5),
            "after (effect fitted)".into(),
        ));
    }
    if p.highlight.is_some() {
        keys.push(Key::Band(
            "#f2c94c",
            "where the mismatch was located".into(),
        ));
    }
    chart.legend(&keys);
    chart.finish()
}

/// One bin's residual statistics, mm.
struct Bin {
    centre: f64,
    mean: f64,
    rms: f64,
}

/// The binned means and RMS of `values` over `xs` (a bin per category, or [`BINS`] equal
/// bins), for bins with at least [`MIN_PER_BIN`] readings; a gap leaves a NaN, which breaks
/// the lines.
fn binned(xs: &[f64], values: &[f64], x: Span, categorical: bool) -> Vec<Bin> {
    let n = if categorical {
        (x.hi - x.lo).round() as usize
    } else {
        BINS
    };
    let mut sum = vec![0.0; n];
    let mut sumsq = vec![0.0; n];
    let mut count = vec![0usize; n];
    for (&x_i, &r) in xs.iter().zip(values) {
        if !(x_i.is_finite() && r.is_finite()) {
            continue;
        }
        let b = if categorical {
            x_i.round() as usize
        } else {
            (((x_i - x.lo) / (x.hi - x.lo)) * n as f64)
                .floor()
                .clamp(0.0, n as f64 - 1.0) as usize
        };
        if b < n {
            sum[b] += r * 1000.0;
            sumsq[b] += (r * 1000.0).powi(2);
            count[b] += 1;
        }
    }
    (0..n)
        .map(|b| {
            let centre = if categorical {
                b as f64
            } else {
                x.lo + (b as f64 + 0.5) / n as f64 * (x.hi - x.lo)
            };
            if count[b] >= MIN_PER_BIN {
                Bin {
                    centre,
                    mean: sum[b] / count[b] as f64,
                    rms: (sumsq[b] / count[b] as f64).sqrt(),
                }
            } else {
                Bin {
                    centre,
                    mean: f64::NAN,
                    rms: f64::NAN,
                }
            }
        })
        .filter(|b| !categorical || b.mean.is_finite())
        .collect()
}

/// The residuals' half range, metres: their 98th percentile of |r| and every category's mean
/// (before the margin).
fn residual_limit(p: &PlotData, xs: &[f64], categorical: bool) -> f64 {
    let mut all: Vec<f64> = p.before.clone();
    if let Some(a) = &p.after {
        all.extend(a);
    }
    let mut lim = quantile(&all.iter().map(|v| v.abs()).collect::<Vec<_>>(), 0.98).max(1e-4);
    if categorical {
        for values in [p.before.as_slice(), p.after.as_deref().unwrap_or(&[])] {
            for k in 0..p.categories.len() {
                let v: Vec<f64> = xs
                    .iter()
                    .zip(values)
                    .filter(|(x, r)| **x == k as f64 && r.is_finite())
                    .map(|(_, r)| *r)
                    .collect();
                if !v.is_empty() {
                    lim = lim.max((v.iter().sum::<f64>() / v.len() as f64).abs());
                }
            }
        }
    }
    lim
}
