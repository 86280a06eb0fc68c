//! Charts as inline SVG: the project's one plotting module (the run report and the diagnosis
//! draw with it). Hand-written because what the pages need is small (axes with "nice" ticks,
//! lines, dots, bands, shapes to scale, a legend) and `plotters` would add a text-layout
//! dependency for less control over a map's equal aspect.

use std::fmt::Write as _;

/// `s` escaped for HTML and SVG text and attributes.
#[must_use]
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A number with about three significant figures ("—" when not finite).
#[must_use]
pub fn fmt_sig(v: f64) -> String {
    if !v.is_finite() {
        return "—".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
    format!("{v:.digits$}")
}

/// "Nice" tick values (1, 2 or 5 × 10^k apart) covering [lo, hi], about `n` of them.
#[must_use]
pub fn ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / n.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let start = (lo / step).ceil() as i64;
    let end = (hi / step).floor() as i64;
    // Multiplying (not accumulating) keeps 0.1 × 3 from printing as 0.30000000000000004.
    (start..=end).map(|k| k as f64 * step).collect()
}

/// Decimals that print every tick of `ticks` (evenly spaced) exactly and alike: 0.25 apart
/// needs two, 5 apart none.
fn decimals(ticks: &[f64]) -> usize {
    let step = match ticks {
        [a, b, ..] => (b - a).abs(),
        _ => return 0,
    };
    (0..6)
        .find(|&d| {
            let scaled = step * 10f64.powi(d);
            (scaled - scaled.round()).abs() < 1e-6 * scaled.max(1.0)
        })
        .unwrap_or(6) as usize
}

/// Quantile `q` (0..=1) of the finite values of `v` (0 when there are none).
#[must_use]
pub fn quantile(v: &[f64], q: f64) -> f64 {
    let mut f: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if f.is_empty() {
        return 0.0;
    }
    f.sort_by(f64::total_cmp);
    f[((f.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize]
}

/// Every `k`-th item so that at most `max` remain (evenly thinned, deterministic).
#[must_use]
pub fn thin<T: Copy>(items: &[T], max: usize) -> Vec<T> {
    let stride = items.len().div_ceil(max.max(1)).max(1);
    items.iter().step_by(stride).copied().collect()
}

/// A closed interval of data values along one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    /// Lowest value.
    pub lo: f64,
    /// Highest value.
    pub hi: f64,
}

impl Span {
    /// The span of `lo..=hi`, widened to a unit around `lo` when it is empty or not finite.
    #[must_use]
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo.is_finite() && hi.is_finite() && hi > lo {
            Self { lo, hi }
        } else if lo.is_finite() {
            Self {
                lo: lo - 0.5,
                hi: lo + 0.5,
            }
        } else {
            Self { lo: 0.0, hi: 1.0 }
        }
    }

    /// The span of the finite values of `values` (a unit span when there are none).
    #[must_use]
    pub fn of(values: impl IntoIterator<Item = f64>) -> Self {
        let (lo, hi) = values
            .into_iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        Self::new(lo, hi)
    }

    /// The span grown by `fraction` of its width on each side.
    #[must_use]
    pub fn padded(self, fraction: f64) -> Self {
        let pad = (self.hi - self.lo) * fraction;
        Self::new(self.lo - pad, self.hi + pad)
    }

    /// The span that also covers `other`.
    #[must_use]
    pub fn union(self, other: Span) -> Self {
        Self::new(self.lo.min(other.lo), self.hi.max(other.hi))
    }

    fn width(self) -> f64 {
        self.hi - self.lo
    }
}

/// How a line is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stroke {
    /// CSS colour.
    pub colour: &'static str,
    /// Width in pixels.
    pub width: f64,
    /// SVG dash pattern (`"6,3"`), none for solid.
    pub dash: Option<&'static str>,
}

impl Stroke {
    /// A solid line.
    #[must_use]
    pub const fn solid(colour: &'static str, width: f64) -> Self {
        Self {
            colour,
            width,
            dash: None,
        }
    }

    /// A dashed line.
    #[must_use]
    pub const fn dashed(colour: &'static str, width: f64) -> Self {
        Self {
            colour,
            width,
            dash: Some("6,4"),
        }
    }

    fn attributes(&self) -> String {
        let dash = self
            .dash
            .map(|d| format!(r#" stroke-dasharray="{d}""#))
            .unwrap_or_default();
        format!(
            r#"fill="none" stroke="{}" stroke-width="{}"{dash} stroke-linejoin="round""#,
            self.colour, self.width
        )
    }
}

/// One entry of a chart's legend.
#[derive(Debug, Clone, PartialEq)]
pub enum Key {
    /// A line.
    Line(Stroke, String),
    /// Dots.
    Dots(&'static str, String),
    /// A shaded band.
    Band(&'static str, String),
}

/// A chart: a frame with axes in data units, drawn into an SVG element. Everything drawn is
/// clipped to the frame.
#[derive(Debug, Clone)]
pub struct Chart {
    id: String,
    width: f64,
    height: f64,
    left: f64,
    right: f64,
    top: f64,
    bottom: f64,
    x: Span,
    y: Span,
    back: String,
    body: String,
    front: String,
    keys: Vec<Key>,
}

/// Margins around the frame, pixels: room for tick labels and axis titles.
const MARGINS: (f64, f64, f64, f64) = (64.0, 16.0, 34.0, 48.0);

impl Chart {
    /// A `width` × `height` pixel chart of `x` against `y`. `id` is unique within the page
    /// (it names the clipping path).
    #[must_use]
    pub fn new(id: &str, width: f64, height: f64, x: Span, y: Span) -> Self {
        let (left, right, top, bottom) = MARGINS;
        Self {
            id: id.chars().filter(char::is_ascii_alphanumeric).collect(),
            width,
            height,
            left,
            right,
            top,
            bottom,
            x,
            y,
            back: String::new(),
            body: String::new(),
            front: String::new(),
            keys: Vec::new(),
        }
    }

    /// A chart `width` pixels wide whose axes have the same scale (a map): the height follows
    /// from the spans, within `max_height`, and the narrower span is widened to fill the frame.
    #[must_use]
    pub fn to_scale(id: &str, width: f64, max_height: f64, x: Span, y: Span) -> Self {
        let (left, right, top, bottom) = MARGINS;
        let frame_w = width - left - right;
        let wanted_h = frame_w * y.width() / x.width();
        let frame_h = wanted_h.clamp(120.0, max_height - top - bottom);
        // Metres per pixel: the larger of the two, so both spans fit.
        let scale = (x.width() / frame_w).max(y.width() / frame_h);
        let grow = |s: Span, pixels: f64| {
            let mid = (s.lo + s.hi) / 2.0;
            Span::new(mid - scale * pixels / 2.0, mid + scale * pixels / 2.0)
        };
        Self::new(
            id,
            width,
            frame_h + top + bottom,
            grow(x, frame_w),
            grow(y, frame_h),
        )
    }

    /// The chart with `pixels` below the frame instead of the usual margin (room for long
    /// category names). Call before drawing.
    #[must_use]
    pub fn with_bottom_margin(mut self, pixels: f64) -> Self {
        self.bottom = pixels;
        self
    }

    /// The page's x coordinate of data `x`.
    #[must_use]
    pub fn sx(&self, x: f64) -> f64 {
        self.left + (x - self.x.lo) / self.x.width() * (self.width - self.left - self.right)
    }

    /// The page's y coordinate of data `y` (up is up).
    #[must_use]
    pub fn sy(&self, y: f64) -> f64 {
        self.top + (self.y.hi - y) / self.y.width() * (self.height - self.top - self.bottom)
    }

    /// Pixels per data unit along x.
    fn x_scale(&self) -> f64 {
        (self.width - self.left - self.right) / self.x.width()
    }

    /// The grid, the ticks, the frame, the title and the axes' labels.
    pub fn axes(&mut self, title: &str, x_label: &str, y_label: &str) {
        self.frame(title, x_label, y_label, None);
    }

    /// As [`Chart::axes`] for a categorical x axis: category `i` at x = i, its name written
    /// slanted below the frame.
    pub fn axes_categorical(&mut self, title: &str, categories: &[String], y_label: &str) {
        self.frame(title, "", y_label, Some(categories));
    }

    fn frame(&mut self, title: &str, x_label: &str, y_label: &str, categories: Option<&[String]>) {
        let (w, h) = (self.width, self.height);
        let (l, r, t, b) = (self.left, self.right, self.top, self.bottom);
        // Grid lines behind the data (clipped to the frame), their labels outside it.
        let y_ticks = ticks(self.y.lo, self.y.hi, 6);
        let y_digits = decimals(&y_ticks);
        for v in y_ticks {
            let y = self.sy(v);
            let _ = writeln!(
                self.back,
                r##"<line x1="{l}" x2="{:.1}" y1="{y:.1}" y2="{y:.1}" stroke="{}"/>"##,
                w - r,
                if v == 0.0 { "#9a9a9a" } else { "#e6e6e6" },
            );
            let _ = writeln!(
                self.front,
                r##"<text x="{:.1}" y="{:.1}" text-anchor="end">{v:.y_digits$}</text>"##,
                l - 6.0,
                y + 4.0,
            );
        }
        if let Some(names) = categories {
            for (i, name) in names.iter().enumerate() {
                let x = self.sx(i as f64);
                let y = h - b + 14.0;
                let _ = writeln!(
                    self.front,
                    r##"<text x="{x:.1}" y="{y:.1}" text-anchor="end" transform="rotate(-35 {x:.1} {y:.1})">{}</text>"##,
                    escape(name)
                );
            }
        } else {
            let x_ticks = ticks(self.x.lo, self.x.hi, 8);
            let x_digits = decimals(&x_ticks);
            for v in x_ticks {
                let x = self.sx(v);
                let _ = writeln!(
                    self.back,
                    r##"<line x1="{x:.1}" x2="{x:.1}" y1="{t}" y2="{:.1}" stroke="{}"/>"##,
                    h - b,
                    if v == 0.0 { "#9a9a9a" } else { "#e6e6e6" },
                );
                let _ = writeln!(
                    self.front,
                    r##"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{v:.x_digits$}</text>"##,
                    h - b + 16.0,
                );
            }
        }
        let _ = writeln!(
            self.front,
            r##"<rect x="{l}" y="{t}" width="{:.1}" height="{:.1}" fill="none" stroke="#444"/>
<text x="{l}" y="20" font-size="14" font-weight="600">{}</text>
<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>
<text x="16" y="{:.1}" text-anchor="middle" transform="rotate(-90 16 {:.1})">{}</text>"##,
            w - l - r,
            h - t - b,
            escape(title),
            (l + w - r) / 2.0,
            h - 12.0,
            escape(x_label),
            (t + h - b) / 2.0,
            (t + h - b) / 2.0,
            escape(y_label)
        );
    }

    /// A line through `points`, broken wherever a coordinate is not finite.
    pub fn line(&mut self, points: &[(f64, f64)], stroke: Stroke) {
        let attributes = stroke.attributes();
        for run in points.split(|(x, y)| !(x.is_finite() && y.is_finite())) {
            if run.len() < 2 {
                continue;
            }
            let pts: Vec<String> = run
                .iter()
                .map(|&(x, y)| format!("{:.1},{:.1}", self.sx(x), self.sy(y)))
                .collect();
            let _ = writeln!(
                self.body,
                r#"<polyline points="{}" {attributes}/>"#,
                pts.join(" ")
            );
        }
    }

    /// Dots of `radius` pixels at `points` (the non-finite ones skipped).
    pub fn dots(&mut self, points: &[(f64, f64)], colour: &str, radius: f64, opacity: f64) {
        let _ = write!(self.body, r#"<g fill="{colour}" fill-opacity="{opacity}">"#);
        for &(x, y) in points {
            if x.is_finite() && y.is_finite() {
                let _ = write!(
                    self.body,
                    r#"<circle cx="{:.1}" cy="{:.1}" r="{radius}"/>"#,
                    self.sx(x),
                    self.sy(y)
                );
            }
        }
        let _ = writeln!(self.body, "</g>");
    }

    /// A cross (×) of 6 pixels at each of `points`, drawn above the data.
    pub fn crosses(&mut self, points: &[(f64, f64)], colour: &str) {
        for &(x, y) in points {
            if x.is_finite() && y.is_finite() {
                let (px, py) = (self.sx(x), self.sy(y));
                let _ = writeln!(
                    self.front,
                    r#"<path d="M{:.1},{:.1}L{:.1},{:.1}M{:.1},{:.1}L{:.1},{:.1}" stroke="{colour}" stroke-width="2.5"/>"#,
                    px - 6.0,
                    py - 6.0,
                    px + 6.0,
                    py + 6.0,
                    px - 6.0,
                    py + 6.0,
                    px + 6.0,
                    py - 6.0
                );
            }
        }
    }

    /// A shaded band between `lower` and `upper` over the same x values (`(x, lower, upper)`).
    pub fn band(&mut self, rows: &[(f64, f64, f64)], colour: &str, opacity: f64) {
        let rows: Vec<&(f64, f64, f64)> = rows
            .iter()
            .filter(|(x, a, b)| x.is_finite() && a.is_finite() && b.is_finite())
            .collect();
        if rows.len() < 2 {
            return;
        }
        let pts: Vec<String> = rows
            .iter()
            .map(|(x, _, hi)| format!("{:.1},{:.1}", self.sx(*x), self.sy(*hi)))
            .chain(
                rows.iter()
                    .rev()
                    .map(|(x, lo, _)| format!("{:.1},{:.1}", self.sx(*x), self.sy(*lo))),
            )
            .collect();
        let _ = writeln!(
            self.back,
            r#"<polygon points="{}" fill="{colour}" fill-opacity="{opacity}" stroke="none"/>"#,
            pts.join(" ")
        );
    }

    /// A closed polygon in data units.
    pub fn polygon(&mut self, points: &[(f64, f64)], fill: &str, stroke: Stroke) {
        let pts: Vec<String> = points
            .iter()
            .map(|&(x, y)| format!("{:.1},{:.1}", self.sx(x), self.sy(y)))
            .collect();
        let _ = writeln!(
            self.body,
            r#"<polygon points="{}" {} fill="{fill}"/>"#,
            pts.join(" "),
            stroke.attributes().replace(r#"fill="none" "#, "")
        );
    }

    /// Axis-aligned rectangles `(x0, y0, x1, y1)` in data units, filled, as one path (a map's
    /// occupied cells: thousands of them cost one element).
    pub fn rects(&mut self, rects: &[(f64, f64, f64, f64)], fill: &str) {
        if rects.is_empty() {
            return;
        }
        let mut d = String::with_capacity(rects.len() * 24);
        for &(x0, y0, x1, y1) in rects {
            let (left, right) = (self.sx(x0), self.sx(x1));
            let (top, bottom) = (self.sy(y1), self.sy(y0));
            let _ = write!(d, "M{left:.1} {top:.1}H{right:.1}V{bottom:.1}H{left:.1}Z",);
        }
        let _ = writeln!(self.body, r#"<path d="{d}" fill="{fill}" stroke="none"/>"#);
    }

    /// A circle of data radius `radius` (meaningful on a chart [`Chart::to_scale`]).
    pub fn circle(&mut self, centre: (f64, f64), radius: f64, fill: &str, stroke: Stroke) {
        let _ = writeln!(
            self.body,
            r#"<circle cx="{:.1}" cy="{:.1}" r="{:.2}" {} fill="{fill}"/>"#,
            self.sx(centre.0),
            self.sy(centre.1),
            (radius * self.x_scale()).max(1.0),
            stroke.attributes().replace(r#"fill="none" "#, "")
        );
    }

    /// A small marker with a label at a data point (drawn above everything).
    pub fn marker(&mut self, at: (f64, f64), colour: &str, label: &str) {
        let (x, y) = (self.sx(at.0), self.sy(at.1));
        let _ = writeln!(
            self.front,
            r##"<circle cx="{x:.1}" cy="{y:.1}" r="4.5" fill="{colour}" stroke="white" stroke-width="1.5"/><text x="{:.1}" y="{:.1}" font-size="11" fill="#222">{}</text>"##,
            x + 7.0,
            y - 6.0,
            escape(label)
        );
    }

    /// A shaded vertical strip over `from..to` of x (a region of interest).
    pub fn strip(&mut self, from: f64, to: f64, colour: &str) {
        let (a, b) = (self.sx(from.max(self.x.lo)), self.sx(to.min(self.x.hi)));
        let _ = writeln!(
            self.back,
            r#"<rect x="{a:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="{colour}"/>"#,
            self.top,
            (b - a).max(2.0),
            self.height - self.top - self.bottom
        );
    }

    /// The legend: drawn below the chart, in rows, so it never hides data.
    pub fn legend(&mut self, keys: &[Key]) {
        self.keys.extend_from_slice(keys);
    }

    /// The legend's rows below the x axis's title, and the height they take.
    fn legend_rows(&self) -> (String, f64) {
        if self.keys.is_empty() {
            return (String::new(), 0.0);
        }
        let mut s = String::new();
        let (mut x, mut y) = (self.left, self.height + 4.0);
        for key in &self.keys {
            let text = match key {
                Key::Line(_, t) | Key::Dots(_, t) | Key::Band(_, t) => t,
            };
            // 6.4 px per character: a 12 px sans-serif's mean advance, with room to spare.
            let width = 30.0 + text.chars().count() as f64 * 6.4 + 18.0;
            if x + width > self.width - self.right && x > self.left {
                x = self.left;
                y += 18.0;
            }
            let swatch = match key {
                Key::Line(stroke, _) => format!(
                    r#"<line x1="{x:.1}" x2="{:.1}" y1="{:.1}" y2="{:.1}" {}/>"#,
                    x + 22.0,
                    y - 4.0,
                    y - 4.0,
                    stroke.attributes()
                ),
                Key::Dots(colour, _) => format!(
                    r#"<circle cx="{:.1}" cy="{:.1}" r="3.5" fill="{colour}"/>"#,
                    x + 11.0,
                    y - 4.0
                ),
                Key::Band(colour, _) => format!(
                    r#"<rect x="{x:.1}" y="{:.1}" width="22" height="10" fill="{colour}" fill-opacity="0.3"/>"#,
                    y - 9.0
                ),
            };
            let _ = writeln!(
                s,
                r#"{swatch}<text x="{:.1}" y="{y:.1}">{}</text>"#,
                x + 28.0,
                escape(text)
            );
            x += width;
        }
        (s, y - self.height + 10.0)
    }

    /// The chart as an SVG element.
    #[must_use]
    pub fn finish(self) -> String {
        let (legend, legend_h) = self.legend_rows();
        let (w, h) = (self.width, self.height + legend_h);
        let (l, r, t, b) = (self.left, self.right, self.top, self.bottom);
        format!(
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" font-family="sans-serif" font-size="12" role="img">
<defs><clipPath id="clip-{id}"><rect x="{l}" y="{t}" width="{:.1}" height="{:.1}"/></clipPath></defs>
<rect width="{w:.0}" height="{h:.0}" fill="white"/>
<g clip-path="url(#clip-{id})">
{}{}</g>
{}{legend}</svg>
"##,
            w - l - r,
            self.height - t - b,
            self.back,
            self.body,
            self.front,
            id = self.id,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_cover_the_span() {
        let t = ticks(0.0, 1.0, 5);
        assert_eq!(t.len(), 6);
        assert_eq!(decimals(&t), 1);
        assert_eq!(decimals(&ticks(0.0, 100.0, 5)), 0);
        assert_eq!(decimals(&ticks(0.0, 0.1, 4)), 2);
        let t = ticks(-3.7, 12.2, 8);
        assert_eq!(t.first(), Some(&-2.0));
        assert_eq!(t.last(), Some(&12.0));
        assert!(t.windows(2).all(|w| (w[1] - w[0] - 2.0).abs() < 1e-12));
    }

    #[test]
    fn a_chart_to_scale_has_equal_metres_per_pixel_on_both_axes() {
        let c = Chart::to_scale("m", 800.0, 900.0, Span::new(0.0, 10.0), Span::new(0.0, 2.0));
        let per_x = (c.sx(1.0) - c.sx(0.0)).abs();
        let per_y = (c.sy(0.0) - c.sy(1.0)).abs();
        assert!((per_x - per_y).abs() < 1e-9, "{per_x} vs {per_y}");
        // A tall world is limited by the height and widened in x instead.
        let c = Chart::to_scale("n", 800.0, 500.0, Span::new(0.0, 1.0), Span::new(0.0, 20.0));
        let per_x = (c.sx(1.0) - c.sx(0.0)).abs();
        let per_y = (c.sy(0.0) - c.sy(1.0)).abs();
        assert!((per_x - per_y).abs() < 1e-9);
        assert!(c.height <= 500.0);
    }

    #[test]
    fn a_line_breaks_at_missing_values_and_text_is_escaped() {
        let mut c = Chart::new("t", 400.0, 300.0, Span::new(0.0, 4.0), Span::new(0.0, 4.0));
        c.axes("a <b> & c", "x (m)", "y (m)");
        c.line(
            &[
                (0.0, 0.0),
                (1.0, 1.0),
                (f64::NAN, 0.0),
                (2.0, 2.0),
                (3.0, 3.0),
            ],
            Stroke::solid("#000", 1.0),
        );
        let svg = c.finish();
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert!(svg.contains("a &lt;b&gt; &amp; c"));
        assert!(!svg.contains("NaN"));
    }
}
