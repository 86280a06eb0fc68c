//! A plot as a standalone SVG document (hand-written, no plotting dependency).

use std::fmt::Write as _;

use super::format::{escape, fmt_sig};
use crate::plot::PlotData;

/// Quantile `q` of the finite values of `v`.
fn quantile(v: &[f64], q: f64) -> f64 {
    let mut f: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if f.is_empty() {
        return 0.0;
    }
    f.sort_by(f64::total_cmp);
    f[((f.len() - 1) as f64 * q).round() as usize]
}

/// "Nice" tick values covering [lo, hi].
fn ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let start = (lo / step).ceil() as i64;
    let end = (hi / step).floor() as i64;
    (start..=end).map(|k| k as f64 * step).collect()
}

/// The plot as a standalone SVG document: residual (mm) against the variable, the held-out
/// readings as dots and their binned means as lines, before (red) and after (blue) the fix.
#[must_use]
pub fn svg(p: &PlotData) -> String {
    let (xs, frame) = Frame::of(p);
    let mut s = String::new();
    frame.axes(&mut s, p);
    let series: Vec<(&[f64], &str)> = std::iter::once((p.before.as_slice(), "#d9534f"))
        .chain(p.after.as_deref().map(|a| (a, "#1f6fd1")))
        .collect();
    frame.dots(&mut s, &xs, &series);
    let nbins = if frame.categorical {
        p.categories.len()
    } else {
        24
    };
    for (values, colour) in &series {
        frame.binned(&mut s, &xs, values, colour, nbins);
    }
    frame.legend(&mut s, p);
    s
}

/// The plot's geometry: the page, its margins and the data ranges on the axes.
struct Frame {
    categorical: bool,
    w: f64,
    h: f64,
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl Frame {
    /// The x values to draw (a category's index for a categorical variable) and the frame.
    fn of(p: &PlotData) -> (Vec<f64>, Frame) {
        let categorical = !p.categories.is_empty();
        let (w, h) = (760.0, if categorical { 480.0 } else { 420.0 });
        let (left, right, top, bottom) = (70.0, 20.0, 40.0, if categorical { 120.0 } else { 60.0 });
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
        let (x0, x1) = if categorical {
            (-0.5, p.categories.len() as f64 - 0.5)
        } else {
            let lo = quantile(&xs, 0.0);
            let hi = quantile(&xs, 1.0);
            if hi > lo {
                (lo, hi)
            } else {
                (lo - 1.0, lo + 1.0)
            }
        };
        let lim = residual_limit(p, &xs, categorical) * 1.15;
        let (y0, y1) = (-lim * 1000.0, lim * 1000.0);
        let frame = Frame {
            categorical,
            w,
            h,
            left,
            right,
            top,
            bottom,
            x0,
            x1,
            y0,
            y1,
        };
        (xs, frame)
    }

    /// The page's x coordinate of `x`.
    fn sx(&self, x: f64) -> f64 {
        self.left + (x - self.x0) / (self.x1 - self.x0) * (self.w - self.left - self.right)
    }

    /// The page's y coordinate of `y` (mm), clamped to the frame.
    fn sy(&self, y: f64) -> f64 {
        self.top
            + (self.y1 - y.clamp(self.y0, self.y1)) / (self.y1 - self.y0)
                * (self.h - self.top - self.bottom)
    }

    /// The document's head, the located range, the grid, the ticks and the axes' labels.
    fn axes(&self, s: &mut String, p: &PlotData) {
        let Frame {
            w,
            h,
            left,
            right,
            top,
            bottom,
            x0,
            x1,
            y0,
            y1,
            ..
        } = *self;
        let _ = write!(
            s,
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">
<rect width="{w}" height="{h}" fill="white"/>
<text x="{}" y="22" text-anchor="middle" font-size="14">{}</text>
"##,
            w / 2.0,
            escape(&p.title)
        );
        if let Some((a, b)) = p.highlight {
            let (ha, hb) = (self.sx(a.max(x0)), self.sx(b.min(x1)));
            let _ = writeln!(
                s,
                r##"<rect x="{ha:.1}" y="{top}" width="{:.1}" height="{}" fill="#fff3c4"/>"##,
                (hb - ha).max(2.0),
                h - top - bottom
            );
        }
        // Axes and grid.
        for t in ticks(y0, y1, 6) {
            let y = self.sy(t);
            let _ = writeln!(
                s,
                r##"<line x1="{left}" x2="{}" y1="{y:.1}" y2="{y:.1}" stroke="{}" stroke-width="1"/><text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
                w - right,
                if t == 0.0 { "#555" } else { "#e4e4e4" },
                left - 6.0,
                y + 4.0,
                fmt_sig(t)
            );
        }
        self.x_ticks(s, p);
        let _ = writeln!(
            s,
            r##"<rect x="{left}" y="{top}" width="{}" height="{}" fill="none" stroke="#333"/>"##,
            w - left - right,
            h - top - bottom
        );
        let _ = writeln!(
            s,
            r##"<text x="{}" y="{}" text-anchor="middle">{} {}</text>"##,
            (left + w - right) / 2.0,
            h - 18.0,
            escape(p.variable.name()),
            if p.variable.unit().is_empty() {
                String::new()
            } else {
                format!("({})", p.variable.unit())
            }
        );
        let _ = writeln!(
            s,
            r##"<text x="18" y="{}" text-anchor="middle" transform="rotate(-90 18 {})">residual (mm)</text>"##,
            (top + h - bottom) / 2.0,
            (top + h - bottom) / 2.0
        );
    }

    /// The x axis's labels: the categories' names, or ticks with their grid lines.
    fn x_ticks(&self, s: &mut String, p: &PlotData) {
        let (h, top, bottom) = (self.h, self.top, self.bottom);
        if self.categorical {
            for (i, (_, name)) in p.categories.iter().enumerate() {
                let x = self.sx(i as f64);
                let y = h - bottom + 14.0;
                let _ = writeln!(
                    s,
                    r##"<text x="{x:.1}" y="{y:.1}" text-anchor="end" transform="rotate(-35 {x:.1} {y:.1})">{}</text>"##,
                    escape(name)
                );
            }
        } else {
            for t in ticks(self.x0, self.x1, 8) {
                let x = self.sx(t);
                let _ = writeln!(
                    s,
                    r##"<line x1="{x:.1}" x2="{x:.1}" y1="{top}" y2="{}" stroke="#eeeeee"/><text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"##,
                    h - bottom,
                    h - bottom + 18.0,
                    fmt_sig(t)
                );
            }
        }
    }

    /// Each series' readings as dots (jittered within a category).
    fn dots(&self, s: &mut String, xs: &[f64], series: &[(&[f64], &str)]) {
        let categorical = self.categorical;
        let jitter = |i: usize| {
            if categorical {
                ((i as f64 * 0.618_034).fract() - 0.5) * 0.5
            } else {
                0.0
            }
        };
        for (values, colour) in series {
            let _ = write!(s, r##"<g fill="{colour}" fill-opacity="0.25">"##);
            for (i, (&x, &r)) in xs.iter().zip(values.iter()).enumerate() {
                if x.is_finite() && r.is_finite() {
                    let _ = write!(
                        s,
                        r##"<circle cx="{:.1}" cy="{:.1}" r="1.6"/>"##,
                        self.sx(x + jitter(i)),
                        self.sy(r * 1000.0)
                    );
                }
            }
            let _ = writeln!(s, "</g>");
        }
    }

    /// One series' binned means (a line, or a bar per category) and, for a continuous
    /// variable, its binned RMS dashed above and below zero.
    fn binned(&self, s: &mut String, xs: &[f64], values: &[f64], colour: &str, nbins: usize) {
        let categorical = self.categorical;
        let (x0, x1) = (self.x0, self.x1);
        let mut sum = vec![0.0; nbins];
        let mut sumsq = vec![0.0; nbins];
        let mut cnt = vec![0usize; nbins];
        for (&x, &r) in xs.iter().zip(values.iter()) {
            if !(x.is_finite() && r.is_finite()) {
                continue;
            }
            let b = if categorical {
                x as usize
            } else {
                (((x - x0) / (x1 - x0)) * nbins as f64)
                    .floor()
                    .clamp(0.0, nbins as f64 - 1.0) as usize
            };
            sum[b] += r;
            sumsq[b] += r * r;
            cnt[b] += 1;
        }
        let centre = |b: usize| {
            if categorical {
                b as f64
            } else {
                x0 + (b as f64 + 0.5) / nbins as f64 * (x1 - x0)
            }
        };
        // The binned RMS, dashed, above and below zero: the spread a mean line cannot show.
        if !categorical {
            for sign in [1.0, -1.0] {
                let rms: Vec<String> = (0..nbins)
                    .filter(|&b| cnt[b] >= 5)
                    .map(|b| {
                        let v = sign * (sumsq[b] / cnt[b] as f64).sqrt() * 1000.0;
                        format!("{:.1},{:.1}", self.sx(centre(b)), self.sy(v))
                    })
                    .collect();
                if rms.len() > 1 {
                    let _ = writeln!(
                        s,
                        r##"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="1.2" stroke-dasharray="5,3"/>"##,
                        rms.join(" ")
                    );
                }
            }
        }
        let pts: Vec<String> = (0..nbins)
            .filter(|&b| cnt[b] >= 5)
            .map(|b| {
                format!(
                    "{:.1},{:.1}",
                    self.sx(centre(b)),
                    self.sy(sum[b] / cnt[b] as f64 * 1000.0)
                )
            })
            .collect();
        if categorical {
            for pt in &pts {
                let (x, y) = pt.split_once(',').unwrap_or(("0", "0"));
                let _ = writeln!(
                    s,
                    r##"<rect x="{}" y="{}" width="16" height="5" fill="{colour}"/>"##,
                    x.parse::<f64>().unwrap_or(0.0) - 8.0,
                    y.parse::<f64>().unwrap_or(0.0) - 2.5
                );
            }
        } else if pts.len() > 1 {
            let _ = writeln!(
                s,
                r##"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="2.5"/>"##,
                pts.join(" ")
            );
        }
    }

    /// The legend, and the document's end.
    fn legend(&self, s: &mut String, p: &PlotData) {
        let (left, top) = (self.left, self.top);
        let _ = writeln!(
            s,
            r##"<g font-size="12"><rect x="{}" y="{}" width="12" height="4" fill="#d9534f"/><text x="{}" y="{}">before (nominal simulation): mean, and ± RMS dashed</text>"##,
            left + 10.0,
            top + 10.0,
            left + 28.0,
            top + 15.0
        );
        if p.after.is_some() {
            let _ = write!(
                s,
                r##"<rect x="{}" y="{}" width="12" height="4" fill="#1f6fd1"/><text x="{}" y="{}">after (effect fitted)</text>"##,
                left + 10.0,
                top + 26.0,
                left + 28.0,
                top + 31.0
            );
        }
        let _ = writeln!(s, "</g>\n</svg>");
    }
}

/// The residuals' half range, metres: their 98th percentile of |r| and every category's mean
/// (before the margin).
fn residual_limit(p: &PlotData, xs: &[f64], categorical: bool) -> f64 {
    let mut all: Vec<f64> = p.before.clone();
    if let Some(a) = &p.after {
        all.extend(a);
    }
    // The range: the residuals' 98th percentile of |r|, and every category's mean.
    let mut lim = quantile(&all.iter().map(|v| v.abs()).collect::<Vec<_>>(), 0.98).max(1e-4);
    if categorical {
        for (values, _) in [
            (p.before.as_slice(), 0),
            (p.after.as_deref().unwrap_or(&[]), 1),
        ] {
            for (k, _) in p.categories.iter().enumerate() {
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
