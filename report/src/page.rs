//! The page: one self-contained HTML document (inline SVG and CSS, nothing loaded from the
//! network) that puts the charts in order with what a reader needs to read them.

use std::fmt::Write as _;

use crate::map::{map, Overlay};
use crate::svg::{escape, fmt_sig};
use crate::view::{Inputs, View};
use crate::{errors, table, timelines};

/// The `generator` every report's page names in its head: how a later report knows that an
/// `index.html` it would replace is a previous report (and not the user's page).
pub const GENERATOR: &str = "hilsim report";

/// Whether `html` is a page this module wrote (a previous report that may be replaced).
#[must_use]
pub fn is_report(html: &str) -> bool {
    html.contains(&format!(r#"<meta name="generator" content="{GENERATOR}">"#))
}

const STYLE: &str = "body{font-family:system-ui,-apple-system,'Segoe UI',sans-serif;max-width:960px;margin:24px auto;padding:0 16px;color:#1b1b1b;line-height:1.45}
h1{font-size:1.5em;margin-bottom:4px}h2{margin-top:32px;border-bottom:1px solid #ddd;padding-bottom:4px}h3{margin-bottom:6px}
.muted{color:#666;font-weight:normal}.facts{color:#444}.figure{margin:12px 0 4px}figcaption{color:#555;font-size:.92em;margin-bottom:18px}
table{border-collapse:collapse;margin:8px 0 12px;font-size:.93em}td,th{border:1px solid #ddd;padding:4px 8px;vertical-align:top;text-align:left}th{background:#f5f5f5}
.pass{color:#237a3b}.fail{color:#b3261e;font-weight:600}.missing{background:#fff8e1;border:1px solid #f0d98c;padding:8px 12px}
svg{max-width:100%;height:auto}";

/// The map alone (the world, the paths, a few scans, `overlay`) as an SVG document.
#[must_use]
pub fn map_svg(inputs: Inputs<'_>, overlay: Option<&Overlay>) -> String {
    map(&View::new(inputs), overlay).0
}

/// The report's HTML page.
#[must_use]
pub fn render(inputs: Inputs<'_>) -> String {
    render_with(inputs, None)
}

/// The report's HTML page, with extra marks on the map.
#[must_use]
pub fn render_with(inputs: Inputs<'_>, overlay: Option<&Overlay>) -> String {
    let view = View::new(inputs);
    let rec = inputs.recording;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="generator" content="{GENERATOR}">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title><style>{STYLE}</style></head><body>
<h1>{title}</h1>"#,
        title = escape(inputs.title)
    );
    let revolutions = view.revolutions.as_ref().map(Vec::len);
    let mut facts = vec![format!("{} s", fmt_sig(rec.duration_s()))];
    if let (Some(l), Some(revs)) = (&rec.lidar, revolutions) {
        facts.push(format!("{} lidar readings in {revs} revolutions", l.len()));
    }
    if let Some(s) = &rec.sonar {
        facts.push(format!("{} sonar readings", s.len()));
    }
    if let Some(o) = &rec.odometry {
        facts.push(format!("{} odometry readings", o.len()));
    }
    facts.push(format!("{} wheel commands", rec.commands.len()));
    if let Some(t) = &rec.truth {
        facts.push(format!("{} true poses", t.len()));
    }
    let _ = writeln!(
        s,
        r#"<p class="facts">Recording <code>{}</code>: {}.{}</p>"#,
        escape(inputs.recording_name),
        facts.join(", "),
        inputs.scenario.map_or(String::new(), |sc| format!(
            " Scenario <code>{}</code>, seed {}.",
            escape(&sc.name),
            sc.seed
        ))
    );
    let mut missing = Vec::new();
    if inputs.scenario.is_none() {
        missing.push("no scenario was given (<code>--scenario FILE</code>): the world is not drawn and the declared sensor models are not shown");
    }
    if rec.truth.is_none() {
        missing.push("the recording has no truth: the scans are placed on the path dead-reckoned from the odometry, and errors against the true distance need <code>true_range_m</code> columns");
    }
    if inputs.calibrations.is_empty() {
        missing.push("no calibration, so no fitted curves or calibrated scans (a run calibrates with the methods its scenario's <code>[calibration]</code> names; <code>hilsim report --calibration FILE</code> takes the JSON of <code>hilsim calibrate --json</code> or a run's <code>results.json</code>)");
    }
    if !missing.is_empty() {
        let _ = writeln!(
            s,
            r#"<div class="missing">{}</div>"#,
            missing
                .iter()
                .map(|m| format!("Not shown: {m}."))
                .collect::<Vec<_>>()
                .join("<br>")
        );
    }

    let _ = writeln!(s, "<h2>The world and the paths</h2>");
    let (svg, revs) = map(&view, overlay);
    let _ = writeln!(s, r#"<div class="figure">{svg}</div>"#);
    let scans = if revs.is_empty() {
        "No lidar revolution is drawn (no lidar, or no path to place it on).".to_string()
    } else {
        format!(
            "Lidar revolutions {} in the world frame, each reading from the {} pose at its own time: raw readings in red{}.",
            revs.iter().map(u64::to_string).collect::<Vec<_>>().join(", "),
            match (view.reference, inputs.truth_estimated) {
                ("truth", false) => "true",
                ("truth", true) => "estimated",
                _ => "dead-reckoned",
            },
            if view.calibrated(hilsim_calibrator::Sensor::Lidar).is_some() {
                ", and with the calibrated lidar model's bias inverted in blue: calibrated readings should lie on the walls and objects"
            } else {
                ""
            }
        )
    };
    let _ = writeln!(
        s,
        "<figcaption>Metres, the same scale on both axes. {scans}</figcaption>"
    );

    let _ = writeln!(s, "<h2>Each sensor's error against the true distance</h2>");
    let charts = errors::error_charts(&view);
    if charts.is_empty() {
        let _ = writeln!(
            s,
            "<p>No reading has a known true distance: they come from a recording's <code>true_range_m</code> columns, or from rays cast in the scenario's world along <code>truth.csv</code>'s path.</p>"
        );
    } else {
        for c in charts {
            let _ = writeln!(s, r#"<div class="figure">{c}</div>"#);
        }
        let _ = writeln!(
            s,
            "<figcaption>Each valid reading's error (reading − true distance) against the true distance; true distances from {}. The bands are ±1 σ of the declared and of the fitted noise around their bias curves; a good calibration's curve follows the readings' mean.</figcaption>",
            view.true_distance_source
        );
    }

    let _ = writeln!(s, "<h2>Timelines</h2>");
    for c in timelines::timelines(&view) {
        let _ = writeln!(s, r#"<div class="figure">{c}</div>"#);
    }

    let _ = writeln!(s, "<h2>Calibration</h2>");
    if inputs.calibrations.is_empty() {
        let _ = writeln!(s, "<p>None given.</p>");
    } else {
        s.push_str(&table::calibration_tables(inputs.calibrations));
    }
    let _ = writeln!(
        s,
        r#"<p class="muted">Written by hilsim {}.</p></body></html>"#,
        env!("CARGO_PKG_VERSION")
    );
    s
}
