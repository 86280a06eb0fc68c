//! The report page: the verdict, the evidence, the fit and the plots.

use std::fmt::Write as _;

use super::format::{
    escape, fit_metric, fit_value, fmt_sig, heldout_unit, mm, rmse_of, without_error,
};
use crate::locate::Evidence;
use crate::outcome::{Diagnosis, Verdict};

/// The report page: the verdict, the evidence, the map, the fit and the plots (`plot_files[i]`
/// is where the caller wrote `svg(&d.plots[i])`, `map_file` where it wrote the world's map with
/// the located readings marked, relative to the page).
#[must_use]
pub fn html(d: &Diagnosis, title: &str, plot_files: &[String], map_file: Option<&str>) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        r##"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="generator" content="{generator}"><title>{t}</title>
<style>
body {{ font-family: sans-serif; max-width: 62em; margin: 2em auto; color: #222; line-height: 1.45; }}
h1 {{ font-size: 1.5em; }} .verdict {{ font-size: 1.3em; padding: .6em 1em; border-radius: 6px; }}
.none {{ background: #e6f4e6; }} .effect {{ background: #fdf0d8; }} .unexplained {{ background: #f9dede; }}
table {{ border-collapse: collapse; margin: .8em 0; }} td, th {{ border: 1px solid #ccc; padding: .25em .6em; text-align: left; }}
th {{ background: #f3f3f3; }} code {{ background: #f3f3f3; padding: 0 .2em; }} img {{ max-width: 100%; border: 1px solid #ddd; margin: .5em 0; }}
</style></head><body>
<h1>{t}</h1>
"##,
        t = escape(title),
        generator = hilsim_report::GENERATOR
    );
    let class = match d.verdict {
        Verdict::None => "none",
        Verdict::Effect(_) => "effect",
        Verdict::Unexplained | Verdict::WorldMismatch => "unexplained",
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
    if let Some(file) = map_file {
        let _ = writeln!(
            s,
            r##"<img src="{}" alt="the world, the real path and where the mismatch was located">"##,
            escape(file)
        );
    }
    fix(&mut s, d);
    for (p, file) in d.plots.iter().zip(plot_files) {
        let _ = writeln!(
            s,
            r##"<img src="{}" alt="{}">"##,
            escape(file),
            escape(&p.title)
        );
    }
    candidates(&mut s, d);
    sensors(&mut s, d);
    evidence(&mut s, d);
    let _ = writeln!(s, "<p>Aligned by {}.</p>", escape(d.alignment.name()));
    for n in &d.notes {
        let _ = writeln!(s, "<p>Note: {}</p>", escape(n));
    }
    let _ = writeln!(s, "</body></html>");
    s
}

/// The named effect's fitted parameters and its held-out RMSE before and after.
fn fix(s: &mut String, d: &Diagnosis) {
    // Every effect named beyond the first, and what no named effect explains.
    if d.effects.len() > 1 {
        let _ = writeln!(
            s,
            "<h2>Every effect named</h2><table><tr><th>effect</th><th>where</th><th>parameters</th><th>held-out RMSE before → after</th></tr>"
        );
        for e in &d.effects {
            let f = &e.fit;
            let params: Vec<String> = f
                .effect
                .params()
                .iter()
                .zip(&f.params)
                .map(|(spec, v)| format!("{} = {} {}", spec.name, fmt_sig(*v), spec.unit))
                .collect();
            let _ = writeln!(
                s,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{} → {}</td></tr>",
                f.effect,
                e.located.as_ref().map_or_else(String::new, |l| format!(
                    "{}, {}",
                    l.sensor,
                    escape(&l.place)
                )),
                escape(&params.join(", ")),
                fit_value(f, f.rmse_before),
                fit_value(f, f.rmse_after)
            );
        }
        let _ = writeln!(s, "</table>");
    }
    evidence_table(
        s,
        &d.world,
        "Within the world's error",
        "Mismatches the world's own error (its map's cells) can make: the map as likely off there as the sensor.",
        true,
    );
    evidence_table(
        s,
        &d.unexplained,
        "Unexplained",
        "Mismatches located above their sensor's floor that no named effect explains.",
        false,
    );
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
                if f.param_sd[i] == 0.0 {
                    without_error(f, i).to_string()
                } else {
                    fmt_sig(f.param_sd[i])
                },
                spec.unit
            );
        }
        let _ = writeln!(
            s,
            "</table><p>Held-out {} {}{}: <b>{}</b> before, <b>{}</b> after; the noise floor is {} ({} {} the fit never saw).</p>",
            f.sensor,
            escape(fit_metric(f)),
            rmse_of(f),
            fit_value(f, f.rmse_before),
            fit_value(f, f.rmse_after),
            fit_value(f, f.noise_floor),
            f.heldout_n,
            heldout_unit(f)
        );
    }
}

/// Every candidate's held-out and BIC gains and parameters.
fn candidates(s: &mut String, d: &Diagnosis) {
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
}

/// Each sensor's held-out residuals under the nominal model.
fn sensors(s: &mut String, d: &Diagnosis) {
    let _ = writeln!(
        s,
        "<h2>Sensors</h2><table><tr><th>sensor</th><th>readings</th><th>held-out RMSE (nominal)</th><th>noise floor</th><th>strongest test</th><th>judged against</th></tr>"
    );
    for x in &d.sensors {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.1}σ</td><td>{}</td></tr>",
            x.sensor,
            x.readings,
            mm(x.heldout_rmse_m),
            mm(x.noise_floor_m),
            x.strongest,
            escape(x.reference)
        );
    }
    let _ = writeln!(s, "</table>");
}

/// The significant evidence (the strongest twelve).
fn evidence(s: &mut String, d: &Diagnosis) {
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
}

/// A table of located mismatches under `title` (nothing when there are none); with
/// `world_reach`, a column of how far the map's cells can move the readings there.
fn evidence_table(s: &mut String, rows: &[Evidence], title: &str, what: &str, world_reach: bool) {
    if rows.is_empty() {
        return;
    }
    let reach_head = if world_reach {
        "<th>the map's reach there</th>"
    } else {
        ""
    };
    let _ = writeln!(
        s,
        "<h2>{title}</h2><p>{what}</p><table><tr><th>sensor</th><th>where</th><th>size</th>{reach_head}<th>evidence</th></tr>"
    );
    for e in rows {
        let reach = if world_reach {
            format!("<td>{}</td>", mm(e.world_m))
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td>{reach}<td>{}</td></tr>",
            e.sensor,
            escape(&e.place),
            mm(e.size_m),
            escape(&e.detail)
        );
    }
    let _ = writeln!(s, "</table>");
}
