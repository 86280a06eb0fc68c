//! Show: the diagnosis as the JSON object of `interfaces.md`, as text for people, and as
//! evidence for the eye: residuals against the located variable before and after the fix
//! (hand-written SVG, no plotting dependency) and an HTML page that holds them with the verdict.
//! Everything here returns strings; writing files is the caller's business.

use std::fmt::Write as _;

use serde_json::{json, Map, Value};

use crate::catalogue::Sensor;
use crate::diagnosis::{Diagnosis, Verdict};
use crate::explain::CandidateFit;
use crate::locate::Evidence;
use crate::physics::Hypothesis;
use crate::residuals::{fits, Context, Covariate, SensorData};

/// Points a plot shows at most (evenly thinned).
const MAX_POINTS: usize = 2500;

/// Residuals of one sensor's held-out readings against one variable.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotData {
    /// The sensor.
    pub sensor: Sensor,
    /// The variable on the x axis.
    pub variable: Covariate,
    /// Names of the categories, for a categorical variable (indexed by value).
    pub categories: Vec<(f64, String)>,
    /// The variable's values.
    pub x: Vec<f64>,
    /// Residuals under the nominal model, metres.
    pub before: Vec<f64>,
    /// Residuals under the fitted effect, metres (when one is named).
    pub after: Option<Vec<f64>>,
    /// The located range of the variable, when there is one.
    pub highlight: Option<(f64, f64)>,
    /// A title.
    pub title: String,
}

/// The plots of a diagnosis: the located sensor's held-out residuals against the located
/// variable and against time, before and after the fix.
pub(crate) fn plots(
    ctx: &Context<'_>,
    data: &[SensorData],
    located: Option<&Evidence>,
    fitted: Option<&CandidateFit>,
) -> Vec<PlotData> {
    let Some(sensor) = located
        .map(|l| l.sensor)
        .or(fitted.map(|f| f.effect.sensor()))
    else {
        return Vec::new();
    };
    let Some(d) = data.iter().find(|d| d.sensor == sensor) else {
        return Vec::new();
    };
    let held = d.rows(Some(true));
    let stride = held.len().div_ceil(MAX_POINTS).max(1);
    let rows: Vec<usize> = held.into_iter().step_by(stride).collect();
    let before: Vec<f64> = fits(d, &rows, &ctx.predict(d, &Hypothesis::nominal(), &rows))
        .iter()
        .map(|f| f.residual)
        .collect();
    let after = fitted.filter(|f| f.effect.sensor() == sensor).map(|f| {
        let h = Hypothesis::with(f.effect, f.params.clone());
        fits(d, &rows, &ctx.predict(d, &h, &rows))
            .iter()
            .map(|f| f.residual)
            .collect::<Vec<f64>>()
    });
    let mut variables = Vec::new();
    if let Some(c) = located.and_then(|l| l.covariate) {
        variables.push(c);
    }
    if !variables.contains(&Covariate::Time) {
        variables.push(Covariate::Time);
    }
    variables
        .into_iter()
        .filter_map(|c| {
            let values = d.covariate(c)?;
            let categories = if c == Covariate::Object {
                let mut ids: Vec<f64> = rows
                    .iter()
                    .map(|&i| values[i])
                    .filter(|v| v.is_finite())
                    .collect();
                ids.sort_by(f64::total_cmp);
                ids.dedup();
                ids.into_iter()
                    .map(|v| (v, ctx.physics.object_name(v as u32)))
                    .collect()
            } else if c == Covariate::Edge {
                vec![
                    (0.0, "away from edges".into()),
                    (1.0, "near an edge".into()),
                ]
            } else {
                Vec::new()
            };
            Some(PlotData {
                sensor,
                variable: c,
                categories,
                x: rows.iter().map(|&i| values[i]).collect(),
                before: before.clone(),
                after: after.clone(),
                highlight: located
                    .filter(|l| l.covariate == Some(c))
                    .and_then(|l| l.range),
                title: format!("{sensor} residuals against {} (held-out half)", c.name()),
            })
        })
        .collect()
}

/// A finite number as JSON, anything else as `null`: no NaN ever reaches a user.
fn num(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

/// The diagnosis as the `hilsim diagnose --json` object of `interfaces.md` (plus `param_sd`,
/// `fit.sensor`, `fit.noise_floor_m`, `fit.readings`, `located.score`, `alignment` and `notes`).
#[must_use]
pub fn to_json(d: &Diagnosis) -> Value {
    let located = d.located.as_ref().map_or(Value::Null, |l| {
        json!({
            "sensor": l.sensor.name(),
            "where": l.place,
            "evidence": l.detail,
            "score": num(l.score),
        })
    });
    let mut params = Map::new();
    let mut param_sd = Map::new();
    if let Some(f) = &d.fitted {
        for (i, spec) in f.effect.params().iter().enumerate() {
            params.insert(spec.name.to_string(), num(f.params[i]));
            param_sd.insert(spec.name.to_string(), num(f.param_sd[i]));
        }
    }
    let fit = match &d.fitted {
        Some(f) => json!({
            "metric": "heldout_rmse_m",
            "sensor": f.effect.sensor().name(),
            "before": num(f.rmse_before),
            "after": num(f.rmse_after),
            "noise_floor_m": num(f.noise_floor),
            "readings": f.heldout_n,
        }),
        None => {
            // No fix: the located sensor's (or the first sensor's) nominal fit, unchanged.
            let s = d
                .located
                .as_ref()
                .and_then(|l| d.sensors.iter().find(|s| s.sensor == l.sensor))
                .or(d.sensors.first());
            match s {
                Some(s) => json!({
                    "metric": "heldout_rmse_m",
                    "sensor": s.sensor.name(),
                    "before": num(s.heldout_rmse_m),
                    "after": num(s.heldout_rmse_m),
                    "noise_floor_m": num(s.noise_floor_m),
                }),
                None => json!({"metric": "heldout_rmse_m", "before": null, "after": null}),
            }
        }
    };
    let mut candidates: Vec<Value> = d
        .candidates
        .iter()
        .map(|c| {
            let params: Map<String, Value> = c
                .effect
                .params()
                .iter()
                .zip(&c.params)
                .map(|(s, v)| (s.name.to_string(), num(*v)))
                .collect();
            json!({
                "effect": c.effect.name(),
                "score": num(c.heldout_gain),
                "bic": num(c.bic_gain),
                "params": params,
            })
        })
        .collect();
    let none_at = candidates
        .iter()
        .position(|c| c["score"].as_f64().is_some_and(|s| s < 0.0))
        .unwrap_or(candidates.len());
    candidates.insert(none_at, json!({"effect": "none", "score": 0.0}));
    json!({
        "mismatch": d.mismatch(),
        "located": located,
        "effect": d.verdict.name(),
        "explanation": d.explanation,
        "params": params,
        "param_sd": param_sd,
        "fit": fit,
        "candidates": candidates,
        "alignment": d.alignment.name(),
        "notes": d.notes,
    })
}

fn mm(v: f64) -> String {
    if v.is_finite() {
        format!("{:.1} mm", v * 1000.0)
    } else {
        "—".to_string()
    }
}

/// The diagnosis for people: a few lines.
#[must_use]
pub fn summary(d: &Diagnosis) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "verdict: {}", d.verdict.name());
    let _ = writeln!(s, "  {}", d.explanation);
    if let Some(l) = &d.located {
        let _ = writeln!(s, "located: {} — {}", l.sensor, l.place);
        let _ = writeln!(s, "  {} ({:.1}σ)", l.detail, l.score);
    }
    if let Some(f) = &d.fitted {
        let params: Vec<String> = f
            .effect
            .params()
            .iter()
            .enumerate()
            .map(|(i, spec)| {
                let sd = f.param_sd[i];
                let sd = if sd.is_finite() {
                    format!(" ± {}", fmt_sig(sd))
                } else {
                    String::new()
                };
                format!("{} = {}{sd} {}", spec.name, fmt_sig(f.params[i]), spec.unit)
                    .trim_end()
                    .to_string()
            })
            .collect();
        let _ = writeln!(s, "fitted: {}", params.join(", "));
        let _ = writeln!(
            s,
            "held-out {} RMSE: {} before, {} after (noise floor {}, {} readings)",
            f.effect.sensor(),
            mm(f.rmse_before),
            mm(f.rmse_after),
            mm(f.noise_floor),
            f.heldout_n
        );
    }
    if !d.candidates.is_empty() {
        let top: Vec<String> = d
            .candidates
            .iter()
            .take(4)
            .map(|c| format!("{} {:+.1}", c.effect, c.heldout_gain))
            .collect();
        let _ = writeln!(
            s,
            "candidates (held-out log-likelihood gain over none): {}",
            top.join(", ")
        );
    }
    let _ = writeln!(s, "aligned by {}", d.alignment.name());
    for n in &d.notes {
        let _ = writeln!(s, "note: {n}");
    }
    s
}

/// A number with about three significant figures.
fn fmt_sig(v: f64) -> String {
    if !v.is_finite() {
        return "—".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
    format!("{v:.digits$}")
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

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
    let lim = lim * 1.15;
    let (y0, y1) = (-lim * 1000.0, lim * 1000.0);
    let sx = |x: f64| left + (x - x0) / (x1 - x0) * (w - left - right);
    let sy = |y: f64| top + (y1 - y.clamp(y0, y1)) / (y1 - y0) * (h - top - bottom);
    let mut s = String::new();
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
        let (ha, hb) = (sx(a.max(x0)), sx(b.min(x1)));
        let _ = writeln!(
            s,
            r##"<rect x="{ha:.1}" y="{top}" width="{:.1}" height="{}" fill="#fff3c4"/>"##,
            (hb - ha).max(2.0),
            h - top - bottom
        );
    }
    // Axes and grid.
    for t in ticks(y0, y1, 6) {
        let y = sy(t);
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
    if categorical {
        for (i, (_, name)) in p.categories.iter().enumerate() {
            let x = sx(i as f64);
            let y = h - bottom + 14.0;
            let _ = writeln!(
                s,
                r##"<text x="{x:.1}" y="{y:.1}" text-anchor="end" transform="rotate(-35 {x:.1} {y:.1})">{}</text>"##,
                escape(name)
            );
        }
    } else {
        for t in ticks(x0, x1, 8) {
            let x = sx(t);
            let _ = writeln!(
                s,
                r##"<line x1="{x:.1}" x2="{x:.1}" y1="{top}" y2="{}" stroke="#eeeeee"/><text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"##,
                h - bottom,
                h - bottom + 18.0,
                fmt_sig(t)
            );
        }
    }
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
    // Dots, then binned means.
    let jitter = |i: usize| {
        if categorical {
            ((i as f64 * 0.618_034).fract() - 0.5) * 0.5
        } else {
            0.0
        }
    };
    let series: Vec<(&[f64], &str)> = std::iter::once((p.before.as_slice(), "#d9534f"))
        .chain(p.after.as_deref().map(|a| (a, "#1f6fd1")))
        .collect();
    for (values, colour) in &series {
        let _ = write!(s, r##"<g fill="{colour}" fill-opacity="0.25">"##);
        for (i, (&x, &r)) in xs.iter().zip(values.iter()).enumerate() {
            if x.is_finite() && r.is_finite() {
                let _ = write!(
                    s,
                    r##"<circle cx="{:.1}" cy="{:.1}" r="1.6"/>"##,
                    sx(x + jitter(i)),
                    sy(r * 1000.0)
                );
            }
        }
        let _ = writeln!(s, "</g>");
    }
    let nbins = if categorical { p.categories.len() } else { 24 };
    for (values, colour) in &series {
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
                        format!("{:.1},{:.1}", sx(centre(b)), sy(v))
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
                    sx(centre(b)),
                    sy(sum[b] / cnt[b] as f64 * 1000.0)
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
    // Legend.
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
    s
}

/// The report page: the verdict, the evidence, the fit and the plots (`plot_files[i]` is where
/// the caller wrote `svg(&d.plots[i])`, relative to the page).
#[must_use]
pub fn html(d: &Diagnosis, title: &str, plot_files: &[String]) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        r##"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{t}</title>
<style>
body {{ font-family: sans-serif; max-width: 62em; margin: 2em auto; color: #222; line-height: 1.45; }}
h1 {{ font-size: 1.5em; }} .verdict {{ font-size: 1.3em; padding: .6em 1em; border-radius: 6px; }}
.none {{ background: #e6f4e6; }} .effect {{ background: #fdf0d8; }} .unexplained {{ background: #f9dede; }}
table {{ border-collapse: collapse; margin: .8em 0; }} td, th {{ border: 1px solid #ccc; padding: .25em .6em; text-align: left; }}
th {{ background: #f3f3f3; }} code {{ background: #f3f3f3; padding: 0 .2em; }} img {{ max-width: 100%; border: 1px solid #ddd; margin: .5em 0; }}
</style></head><body>
<h1>{t}</h1>
"##,
        t = escape(title)
    );
    let class = match d.verdict {
        Verdict::None => "none",
        Verdict::Effect(_) => "effect",
        Verdict::Unexplained => "unexplained",
    };
    let _ = writeln!(
        s,
        r##"<p class="verdict {class}"><b>{}</b>: {}</p>"##,
        escape(d.verdict.name()),
        escape(&d.explanation)
    );
    if let Some(l) = &d.located {
        let _ = writeln!(
            s,
            "<h2>Where</h2><p><b>{}</b>, {} ({:.1}σ; a test counts above {:.1}σ).</p><p>{}</p>",
            l.sensor,
            escape(&l.place),
            l.score,
            d.threshold,
            escape(&l.detail)
        );
    }
    if let Some(f) = &d.fitted {
        let _ = writeln!(
            s,
            "<h2>The fix</h2><table><tr><th>parameter</th><th>fitted</th><th>± (1 s.e.)</th><th>unit</th></tr>"
        );
        for (i, spec) in f.effect.params().iter().enumerate() {
            let _ = writeln!(
                s,
                "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td></tr>",
                spec.name,
                fmt_sig(f.params[i]),
                fmt_sig(f.param_sd[i]),
                spec.unit
            );
        }
        let _ = writeln!(
            s,
            "</table><p>Held-out {} RMSE: <b>{}</b> before, <b>{}</b> after; the noise floor is {} ({} readings the fit never saw).</p>",
            f.effect.sensor(),
            mm(f.rmse_before),
            mm(f.rmse_after),
            mm(f.noise_floor),
            f.heldout_n
        );
    }
    for (p, file) in d.plots.iter().zip(plot_files) {
        let _ = writeln!(
            s,
            r##"<img src="{}" alt="{}">"##,
            escape(file),
            escape(&p.title)
        );
    }
    if !d.candidates.is_empty() {
        let _ = writeln!(
            s,
            "<h2>Candidates</h2><p>Each effect fitted by maximum likelihood on the training half; score: the log-likelihood gain over the nominal simulation on the held-out half (nats); BIC gain on the training half.</p><table><tr><th>effect</th><th>held-out gain</th><th>BIC gain</th><th>parameters</th></tr>"
        );
        for c in &d.candidates {
            let params: Vec<String> = c
                .effect
                .params()
                .iter()
                .zip(&c.params)
                .map(|(spec, v)| format!("{} = {}", spec.name, fmt_sig(*v)))
                .collect();
            let _ = writeln!(
                s,
                "<tr><td><code>{}</code></td><td>{:+.1}</td><td>{:+.1}</td><td>{}</td></tr>",
                c.effect,
                c.heldout_gain,
                c.bic_gain,
                escape(&params.join(", "))
            );
        }
        let _ = writeln!(s, "</table>");
    }
    let _ = writeln!(
        s,
        "<h2>Sensors</h2><table><tr><th>sensor</th><th>readings</th><th>held-out RMSE (nominal)</th><th>noise floor</th><th>strongest test</th></tr>"
    );
    for x in &d.sensors {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.1}σ</td></tr>",
            x.sensor,
            x.readings,
            mm(x.heldout_rmse_m),
            mm(x.noise_floor_m),
            x.strongest
        );
    }
    let _ = writeln!(s, "</table>");
    if !d.evidence.is_empty() {
        let _ = writeln!(
            s,
            "<h2>Evidence</h2><table><tr><th>sensor</th><th>where</th><th>score</th><th>detail</th></tr>"
        );
        for e in d.evidence.iter().take(12) {
            let _ = writeln!(
                s,
                "<tr><td>{}</td><td>{}</td><td>{:.1}σ</td><td>{}</td></tr>",
                e.sensor,
                escape(&e.place),
                e.score,
                escape(&e.detail)
            );
        }
        let _ = writeln!(s, "</table>");
    }
    let _ = writeln!(s, "<p>Aligned by {}.</p>", escape(d.alignment.name()));
    for n in &d.notes {
        let _ = writeln!(s, "<p>Note: {}</p>", escape(n));
    }
    let _ = writeln!(s, "</body></html>");
    s
}
