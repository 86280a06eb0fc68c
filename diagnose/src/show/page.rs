//! A diagnosis's report as files: its residual plots, the map of where the mismatch was
//! located, and the page that holds them with the verdict.

use std::path::Path;

use hilsim_recording::Recording;
use hilsim_sim::Scenario;

use crate::Diagnosis;

/// The map's file beside a diagnosis's page.
pub const MAP_FILE: &str = "map.svg";

/// The files of the report of a diagnosis of the recording at `real` against the scenario at
/// `sim`, as [`report_files`] makes them, titled by both.
#[must_use]
pub fn report_files_of(
    d: &Diagnosis,
    (sim, scenario): (&Path, &Scenario),
    (real, recording): (&Path, &Recording),
) -> Vec<(String, String)> {
    let title = format!(
        "hilsim diagnose: {} against {}",
        real.display(),
        sim.display()
    );
    report_files(d, &title, scenario, recording, &real.display().to_string())
}

/// The files of a diagnosis's report, by name: a residual plot per variable (SVG), the map
/// ([`MAP_FILE`]) and `index.html`, last.
#[must_use]
pub fn report_files(
    d: &Diagnosis,
    title: &str,
    scenario: &Scenario,
    recording: &Recording,
    recording_name: &str,
) -> Vec<(String, String)> {
    let mut files: Vec<(String, String)> = d
        .plots
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let name = format!(
                "residuals-{}-{}.svg",
                i + 1,
                p.variable.name().replace(' ', "-")
            );
            (name, super::svg(p))
        })
        .collect();
    let plots: Vec<String> = files.iter().map(|(name, _)| name.clone()).collect();
    // Without truth.csv the map draws the path the diagnosis estimated from the lidar (the
    // sensors were judged against it) and places the scans on it, not on dead reckoning.
    let with_estimate = d.estimated_path.as_ref().map(|path| Recording {
        truth: Some(path.clone()),
        ..recording.clone()
    });
    let map = hilsim_report::map_svg(
        hilsim_report::Inputs {
            title,
            recording: with_estimate.as_ref().unwrap_or(recording),
            recording_name,
            scenario: Some(scenario),
            calibrations: &[],
            truth_estimated: with_estimate.is_some(),
        },
        located_overlay(d).as_ref(),
    );
    files.push((MAP_FILE.to_string(), map));
    let page = super::html(d, title, &plots, Some(MAP_FILE));
    files.push(("index.html".to_string(), page));
    files
}

/// The held-out readings where the mismatch was located, in the world, for the map: those of
/// the first plot (the located variable's) inside its highlighted range.
fn located_overlay(d: &Diagnosis) -> Option<hilsim_report::Overlay> {
    let located = d.located.as_ref()?;
    let plot = d.plots.first()?;
    let (lo, hi) = plot.highlight?;
    let points: Vec<(f64, f64)> = plot
        .x
        .iter()
        .zip(&plot.positions)
        .filter(|(x, p)| (lo..=hi).contains(*x) && p[0].is_finite() && p[1].is_finite())
        .map(|(_, p)| (p[0], p[1]))
        .collect();
    (!points.is_empty()).then(|| hilsim_report::Overlay {
        points,
        label: format!(
            "{} readings where the mismatch was located ({})",
            located.sensor, located.place
        ),
    })
}
