//! `hilsim report` and `hilsim run --report`: the page, what it refuses to replace, and what a
//! browser draws of it (headless Chromium).

use std::path::Path;
use std::process::Command;

use super::common::*;

/// A recording of the checked-in landmarks scenario with its calibration beside it, made by
/// `run --out` (which writes `results.json`).
fn run_with_results(dir: &Path) {
    let scenario = repo_file("scenarios/landmarks-5.toml");
    let out = hilsim(
        dir,
        &[
            "run",
            scenario.to_str().unwrap(),
            "--out",
            "run",
            "--report",
            "run-report",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("report: run-report/index.html"),
        "{}",
        stdout(&out)
    );
}

#[test]
fn report_draws_the_world_the_paths_the_errors_and_the_calibration() {
    let tmp = tempfile::tempdir().unwrap();
    run_with_results(tmp.path());
    let scenario = repo_file("scenarios/landmarks-5.toml");
    let out = hilsim(
        tmp.path(),
        &[
            "report",
            "run",
            "--scenario",
            scenario.to_str().unwrap(),
            "--out",
            "rep",
        ],
    );
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let html = std::fs::read_to_string(tmp.path().join("rep/index.html")).unwrap();
    // Self-contained: nothing fetched (the SVG namespace is a name, not a fetch).
    let without_namespace = html.replace("xmlns=\"http://www.w3.org/2000/svg\"", "");
    for fetch in ["http://", "https://", "<script", "<link", "<img", "@import"] {
        assert!(!without_namespace.contains(fetch), "the page loads {fetch}");
    }
    // The map (five cylinders drawn as circles of the world), the error charts of both range
    // sensors, the timelines and the calibration table with the results' methods.
    assert!(html.contains("The world, the paths and the scans"));
    assert!(html.matches("<circle cx=").count() >= 5);
    assert!(html.contains("lidar: error against the true distance"));
    assert!(html.contains("Wheel speeds"));
    assert!(
        html.contains("fitted bias ± σ (landmarks)"),
        "the calibration from results.json"
    );
    assert!(html.contains("α<sub>1</sub>"));
    assert!(!html.contains("Not shown"), "everything was given");
    // The page `run --report` wrote shows the same run.
    let run_page = std::fs::read_to_string(tmp.path().join("run-report/index.html")).unwrap();
    assert!(run_page.contains("fitted bias ± σ (landmarks)"));
}

#[test]
fn report_without_scenario_or_truth_says_what_it_cannot_show() {
    let tmp = tempfile::tempdir().unwrap();
    run_with_results(tmp.path());
    std::fs::remove_file(tmp.path().join("run/truth.csv")).unwrap();
    std::fs::remove_file(tmp.path().join("run/results.json")).unwrap();
    let out = hilsim(tmp.path(), &["report", "run", "--out", "rep"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let html = std::fs::read_to_string(tmp.path().join("rep/index.html")).unwrap();
    assert!(html.contains("Not shown: no scenario was given"));
    assert!(html.contains("Not shown: the recording has no truth"));
    assert!(html.contains("Not shown: no calibration"));
    // The path still comes from the odometry, and the scans are placed on it.
    assert!(html.contains("path from the odometry"));
    assert!(html.contains("from the dead-reckoned pose"));
}

#[test]
fn report_never_replaces_a_page_it_did_not_write() {
    let tmp = tempfile::tempdir().unwrap();
    run_with_results(tmp.path());
    std::fs::create_dir(tmp.path().join("site")).unwrap();
    std::fs::write(tmp.path().join("site/index.html"), "<html>my page</html>").unwrap();
    let out = hilsim(tmp.path(), &["report", "run", "--out", "site"]);
    let err = assert_bad_input(&out);
    assert!(
        err.contains("site/index.html") && err.contains("not a hilsim report"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("site/index.html")).unwrap(),
        "<html>my page</html>"
    );
    // `run --report` refuses it too, before running.
    let out = hilsim(tmp.path(), &["run", "--report", "site"]);
    assert_bad_input(&out);
    // A previous report is replaced.
    let out = hilsim(tmp.path(), &["report", "run", "--out", "run-report"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

#[test]
fn report_refuses_bad_inputs_with_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    run_with_results(tmp.path());
    std::fs::write(tmp.path().join("bad.json"), "{\"method\": \"magic\"}").unwrap();
    std::fs::write(tmp.path().join("file"), "x").unwrap();
    for args in [
        &["report", "missing", "--out", "rep"][..],
        &["report", "run", "--calibration", "bad.json", "--out", "rep"],
        &[
            "report",
            "run",
            "--calibration",
            "missing.json",
            "--out",
            "rep",
        ],
        &[
            "report",
            "run",
            "--scenario",
            "missing.toml",
            "--out",
            "rep",
        ],
        &["report", "run", "--out", "file"],
    ] {
        let out = hilsim(tmp.path(), args);
        assert_bad_input(&out);
    }
    assert!(
        !tmp.path().join("rep").exists(),
        "nothing written on bad input"
    );
}

/// Chromium, installed with apt-get when absent and this user may; `None` (and why) where it
/// cannot be had.
fn chromium() -> Result<String, String> {
    for name in ["chromium", "chromium-browser"] {
        if Command::new("which")
            .arg(name)
            .output()
            .is_ok_and(|o| o.status.success())
        {
            return Ok(name.to_string());
        }
    }
    let is_root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if !is_root {
        return Err("chromium is not installed and installing it needs root".into());
    }
    let installed = Command::new("apt-get")
        .args(["install", "-y", "-q", "chromium"])
        .env("DEBIAN_FRONTEND", "noninteractive")
        .output()
        .is_ok_and(|o| o.status.success());
    if installed {
        Ok("chromium".into())
    } else {
        Err("`apt-get install chromium` failed".into())
    }
}

/// A screenshot of `page`, as PNG bytes.
fn screenshot(chromium: &str, page: &Path, png: &Path, profile: &Path) -> Vec<u8> {
    let out = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--window-size=1000,3000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", png.display()))
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read(png).expect("chromium wrote the screenshot")
}

#[test]
fn the_report_renders_in_headless_chromium() {
    let chromium = match chromium() {
        Ok(c) => c,
        Err(why) => {
            eprintln!("SKIPPED the_report_renders_in_headless_chromium: {why}");
            return;
        }
    };
    let tmp = tempfile::tempdir().unwrap();
    run_with_results(tmp.path());
    let page = tmp.path().join("run-report/index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    // The same page with each chart replaced by an empty box of its size: the same layout, so
    // the two screenshots differ only by what the charts draw.
    let attribute = |tag: &str, name: &str| -> String {
        let from = tag.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        tag[from..from + tag[from..].find('"').unwrap()].to_string()
    };
    let mut bare = String::new();
    let mut rest = html.as_str();
    while let Some(start) = rest.find("<svg") {
        bare.push_str(&rest[..start]);
        let tag = &rest[start..start + rest[start..].find('>').unwrap()];
        bare.push_str(&format!(
            r#"<div style="width:{}px;height:{}px"></div>"#,
            attribute(tag, "width"),
            attribute(tag, "height")
        ));
        rest = &rest[start + rest[start..].find("</svg>").unwrap() + "</svg>".len()..];
    }
    bare.push_str(rest);
    let bare_page = tmp.path().join("bare.html");
    std::fs::write(&bare_page, bare).unwrap();
    let profile = tmp.path().join("profile");
    let full = screenshot(&chromium, &page, &tmp.path().join("full.png"), &profile);
    let text_only = screenshot(
        &chromium,
        &bare_page,
        &tmp.path().join("bare.png"),
        &profile,
    );
    assert_eq!(&full[1..4], b"PNG");
    eprintln!(
        "screenshots: {} bytes with the charts, {} with empty boxes in their place",
        full.len(),
        text_only.len()
    );
    // The charts are drawn: dots, lines and shapes compress far worse than a white page with
    // text. Measured here: 427 kB with the charts, 135 kB with empty boxes (3.2×); 2× leaves
    // room for other fonts and Chromium versions.
    assert!(
        full.len() > 2 * text_only.len(),
        "screenshot {} bytes with the charts, {} without: the charts did not render",
        full.len(),
        text_only.len()
    );
}
