//! `hilsim diagnose --self-test N --seed S`: the proof, blind. Each trial draws an effect (or
//! none, each of the ten with probability 1/10) and its parameters from the documented moderate
//! ranges (`docs/diagnose.md`), records a "real" run of the nominal scenario with that effect
//! switched on (its own noise seed), diagnoses it against the nominal scenario without being
//! told, and scores the answer. Trial `i` is a function of (S, i) alone.

use std::io::Write;
use std::process::ExitCode;
use std::time::Instant;

use anyhow::Result;
use hilsim_calibrator::mismatch::{self, Effect, Options, Verdict};
use hilsim_lidar_emulator::Emulation;
use hilsim_sim::scenario::{self, Effects};
use hilsim_sim::Scenario;
use rayon::prelude::*;
use serde_json::json;

use super::SimPhysics;

/// The goals of issue 7.
const GOAL_CORRECT: f64 = 0.95;
const GOAL_FALSE_ALARMS: f64 = 0.05;
const GOAL_PARAM_ERROR: f64 = 0.20;
const GOAL_HELDOUT_RATIO: f64 = 1.2;

/// SplitMix64: the trial's draws, from (S, i) alone.
struct Draws(u64);

impl Draws {
    fn new(seed: u64, trial: u64) -> Self {
        Self(seed ^ trial.wrapping_mul(0xd1b5_4a32_d192_ed03).rotate_left(17))
    }
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn sign(&mut self) -> f64 {
        if self.next() & 1 == 0 {
            1.0
        } else {
            -1.0
        }
    }
}

/// A drawn effect: the scenario tables to switch it on, and the parameter scored (its value).
struct Drawn {
    effect: Option<Effect>,
    effects: Effects,
    /// The scored parameter's true value (`None`: nothing to recover).
    truth: Option<f64>,
    /// Every parameter drawn, for the report.
    params: Vec<(String, f64)>,
}

/// Draws trial `i`'s effect. The moderate ranges (× `strength`):
/// incidence κ ±[0.01, 0.03]; reflectivity c ±[0.008, 0.02] m; mixed pixels half-width
/// [0.5, 1.5]°; motion skew (the head's own period); warm-up k ±[0.004, 0.01] /m with τ in
/// [5, 20] s; sonar cone [8, 20]°; air temperature 20 °C ± [15, 30] °C; slip gain
/// [0.03, 0.1] s; motor lag τ [0.1, 0.4] s.
fn draw(d: &mut Draws, strength: f64, nominal: &Scenario, only: Option<usize>) -> Drawn {
    let drawn_class = (d.unit() * 10.0).floor() as usize;
    // 0: none; 1..=9: the catalogue in order.
    let k = only.unwrap_or(drawn_class);
    let mut effects = nominal.effects.clone();
    let s = strength;
    let (effect, truth, params): (Option<Effect>, Option<f64>, Vec<(String, f64)>) = match k {
        1 => {
            let v = d.sign() * d.between(0.01, 0.03) * s;
            effects.lidar_incidence_angle = Some(scenario::LidarIncidenceAngle { coefficient: v });
            (
                Some(Effect::LidarIncidenceAngle),
                Some(v),
                vec![("coefficient".into(), v)],
            )
        }
        2 => {
            let v = d.sign() * d.between(0.008, 0.02) * s;
            effects.lidar_reflectivity = Some(scenario::LidarReflectivity {
                coefficient_m: v,
                reference: 0.8,
            });
            (
                Some(Effect::LidarReflectivity),
                Some(v),
                vec![("coefficient_m".into(), v)],
            )
        }
        3 => {
            let v = (d.between(0.5, 1.5) * s).min(5.0);
            effects.lidar_mixed_pixels = Some(scenario::LidarMixedPixels { half_width_deg: v });
            (
                Some(Effect::LidarMixedPixels),
                Some(v),
                vec![("half_width_deg".into(), v)],
            )
        }
        4 => {
            effects.lidar_motion_skew = Some(scenario::LidarMotionSkew {});
            let rpm = nominal.sensors.lidar.as_ref().map_or(300.0, |l| l.rpm);
            let period = 60.0 / rpm;
            (
                Some(Effect::LidarMotionSkew),
                Some(period),
                vec![("revolution_s".into(), period)],
            )
        }
        5 => {
            let v = d.sign() * d.between(0.004, 0.01) * s;
            let tau = d.between(5.0, 20.0);
            effects.lidar_warmup_drift = Some(scenario::LidarWarmupDrift {
                coefficient_per_m: v,
                time_constant_s: tau,
            });
            (
                Some(Effect::LidarWarmupDrift),
                Some(v),
                vec![
                    ("coefficient_per_m".into(), v),
                    ("time_constant_s".into(), tau),
                ],
            )
        }
        6 => {
            let v = (d.between(8.0, 20.0) * s).min(60.0);
            effects.sonar_beam_width = Some(scenario::SonarBeamWidth { half_angle_deg: v });
            (
                Some(Effect::SonarBeamWidth),
                Some(v),
                vec![("half_angle_deg".into(), v)],
            )
        }
        7 => {
            let dt = d.sign() * d.between(15.0, 30.0) * s;
            let t = (20.0 + dt).clamp(-50.0, 60.0);
            effects.sonar_speed_of_sound = Some(scenario::SonarSpeedOfSound {
                air_temperature_c: t,
                calibrated_at_c: 20.0,
            });
            // Scored: the departure from the calibration temperature.
            (
                Some(Effect::SonarSpeedOfSound),
                Some(t - 20.0),
                vec![("air_temperature_c".into(), t)],
            )
        }
        8 => {
            let v = d.between(0.03, 0.1) * s;
            effects.odometer_wheel_slip = Some(scenario::OdometerWheelSlip { gain_s: v });
            (
                Some(Effect::OdometerWheelSlip),
                Some(v),
                vec![("gain_s".into(), v)],
            )
        }
        9 => {
            let v = (d.between(0.1, 0.4) * s).min(10.0);
            effects.drive_motor_lag = Some(scenario::DriveMotorLag { time_constant_s: v });
            (
                Some(Effect::DriveMotorLag),
                Some(v),
                vec![("time_constant_s".into(), v)],
            )
        }
        _ => (None, None, Vec::new()),
    };
    Drawn {
        effect,
        effects,
        truth,
        params,
    }
}

/// One trial's outcome.
struct Outcome {
    index: u64,
    truth: Option<Effect>,
    drawn: Vec<(String, f64)>,
    verdict: Result<Verdict, String>,
    /// |fitted − true| / |true| of the scored parameter, when the verdict is right.
    param_error: Option<f64>,
    fitted: Vec<f64>,
    /// Held-out RMSE after the fix over the noise floor, and before over the floor.
    heldout: Option<(f64, f64)>,
    /// The strongest test's score under the nominal model, and the threshold.
    strongest: (f64, f64),
    seconds: f64,
}

/// Trial `i`'s "real" scenario: the nominal one with the drawn effect and its own noise seed.
fn real_scenario(
    nominal: &Scenario,
    seed: u64,
    i: u64,
    strength: f64,
    only: Option<usize>,
) -> (Scenario, Drawn) {
    let mut d = Draws::new(seed, i);
    let drawn = draw(&mut d, strength, nominal, only);
    let mut real = nominal.clone();
    real.effects = drawn.effects.clone();
    real.seed = d.next() >> 1;
    (real, drawn)
}

/// `--trial I`: one trial, its whole diagnosis, and with `report` its report and recording.
#[allow(clippy::too_many_arguments)]
pub fn one(
    nominal: &Scenario,
    seed: u64,
    i: u64,
    strength: f64,
    only: Option<usize>,
    json_out: bool,
    report: Option<&std::path::Path>,
    out: &mut dyn Write,
) -> Result<ExitCode> {
    let (real, drawn) = real_scenario(nominal, seed, i, strength, only);
    let recording = Emulation::new(&real, real.seed)?.run().recording;
    let physics = SimPhysics::new(nominal)?;
    let diagnosis = mismatch::diagnose(&physics, &recording, &Options::default())?;
    if let Some(dir) = report {
        let rec_dir = dir.join("recording");
        recording.write_dir(&rec_dir)?;
        super::write_report(
            dir,
            &diagnosis,
            std::path::Path::new(&format!("<built-in {}>", nominal.name)),
            &rec_dir,
        )?;
    }
    if json_out {
        let mut j = mismatch::show::to_json(&diagnosis);
        j["trial"] = json!({"index": i, "truth": label(drawn.effect), "drawn": drawn.params.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>()});
        writeln!(out, "{j}")?;
    } else {
        let drawn_text: Vec<String> = drawn
            .params
            .iter()
            .map(|(k, v)| format!("{k} = {v:.4}"))
            .collect();
        writeln!(
            out,
            "trial {i} (seed {seed}): concealed {} {}",
            label(drawn.effect),
            drawn_text.join(", ")
        )?;
        out.write_all(mismatch::show::summary(&diagnosis).as_bytes())?;
        for e in diagnosis.evidence.iter().take(8) {
            writeln!(
                out,
                "evidence: {} {} ({:.1}σ): {}",
                e.sensor, e.place, e.score, e.detail
            )?;
        }
        writeln!(out, "threshold: {:.2}σ", diagnosis.threshold)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn trial(nominal: &Scenario, seed: u64, i: u64, strength: f64, only: Option<usize>) -> Outcome {
    let started = Instant::now();
    let (real, drawn) = real_scenario(nominal, seed, i, strength, only);
    let recording = match Emulation::new(&real, real.seed) {
        Ok(e) => e.run().recording,
        Err(err) => {
            return Outcome {
                index: i,
                truth: drawn.effect,
                drawn: drawn.params,
                verdict: Err(err.to_string()),
                param_error: None,
                fitted: Vec::new(),
                heldout: None,
                strongest: (f64::NAN, f64::NAN),
                seconds: started.elapsed().as_secs_f64(),
            }
        }
    };
    // A fresh physics per trial: its beam cache belongs to one trajectory.
    let result = SimPhysics::new(nominal)
        .map_err(|e| format!("{e:#}"))
        .and_then(|physics| {
            mismatch::diagnose(&physics, &recording, &Options::default()).map_err(|e| e.to_string())
        });
    let mut strongest = (f64::NAN, f64::NAN);
    let (verdict, param_error, fitted, heldout) = match result {
        Err(e) => (Err(e), None, Vec::new(), None),
        Ok(diag) => {
            strongest = (
                diag.sensors
                    .iter()
                    .map(|s| s.strongest)
                    .fold(f64::NEG_INFINITY, f64::max),
                diag.threshold,
            );
            let fit = diag.fitted.as_ref();
            let fitted = fit.map(|f| f.params.clone()).unwrap_or_default();
            let param_error = match (diag.verdict, drawn.effect, drawn.truth, fit) {
                (Verdict::Effect(v), Some(e), Some(t), Some(f)) if v == e => {
                    let got = if e == Effect::SonarSpeedOfSound {
                        f.params[0] - 20.0
                    } else {
                        f.params[0]
                    };
                    Some((got - t).abs() / t.abs())
                }
                _ => None,
            };
            let heldout =
                fit.map(|f| (f.rmse_after / f.noise_floor, f.rmse_before / f.noise_floor));
            (Ok(diag.verdict), param_error, fitted, heldout)
        }
    };
    Outcome {
        index: i,
        truth: drawn.effect,
        drawn: drawn.params,
        verdict,
        param_error,
        fitted,
        heldout,
        strongest,
        seconds: started.elapsed().as_secs_f64(),
    }
}

fn label(e: Option<Effect>) -> &'static str {
    e.map_or("none", Effect::name)
}

fn verdict_label(v: &Result<Verdict, String>) -> &'static str {
    match v {
        Ok(v) => v.name(),
        Err(_) => "refused",
    }
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[allow(clippy::too_many_arguments)]
pub fn run(
    nominal: &Scenario,
    n: usize,
    seed: u64,
    strength: f64,
    only: Option<usize>,
    json_out: bool,
    command: &str,
    out: &mut dyn Write,
) -> Result<ExitCode> {
    SimPhysics::new(nominal)?;
    let started = Instant::now();
    let outcomes: Vec<Outcome> = (0..n as u64)
        .into_par_iter()
        .map(|i| trial(nominal, seed, i, strength, only))
        .collect();
    let wall_s = started.elapsed().as_secs_f64();

    // Confusion matrix: rows the truth, columns the verdict.
    let classes: Vec<&str> = std::iter::once("none")
        .chain(Effect::ALL.iter().map(|e| e.name()))
        .collect();
    let columns: Vec<&str> = classes
        .iter()
        .copied()
        .chain(["unexplained", "refused"])
        .collect();
    let mut matrix = vec![vec![0usize; columns.len()]; classes.len()];
    for o in &outcomes {
        let r = classes
            .iter()
            .position(|c| *c == label(o.truth))
            .unwrap_or(0);
        let c = columns
            .iter()
            .position(|c| *c == verdict_label(&o.verdict))
            .unwrap_or(columns.len() - 1);
        matrix[r][c] += 1;
    }
    let with_effect: Vec<&Outcome> = outcomes.iter().filter(|o| o.truth.is_some()).collect();
    let correct = with_effect
        .iter()
        .filter(|o| matches!(o.verdict, Ok(Verdict::Effect(e)) if Some(e) == o.truth))
        .count();
    let without: Vec<&Outcome> = outcomes.iter().filter(|o| o.truth.is_none()).collect();
    let false_alarms = without
        .iter()
        .filter(|o| !matches!(o.verdict, Ok(Verdict::None)))
        .count();
    let mut errors: Vec<f64> = outcomes.iter().filter_map(|o| o.param_error).collect();
    let within = errors.iter().filter(|e| **e <= GOAL_PARAM_ERROR).count();
    let n_errors = errors.len();
    let median_error = median(&mut errors);
    let mut ratios: Vec<f64> = outcomes
        .iter()
        .filter(|o| o.param_error.is_some())
        .filter_map(|o| o.heldout.map(|h| h.0))
        .collect();
    let ratios_ok = ratios.iter().filter(|r| **r <= GOAL_HELDOUT_RATIO).count();
    let n_ratios = ratios.len();
    let median_ratio = median(&mut ratios);
    let share = |a: usize, b: usize| {
        if b == 0 {
            f64::NAN
        } else {
            a as f64 / b as f64
        }
    };
    let correct_share = share(correct, with_effect.len());
    let alarm_share = share(false_alarms, without.len());
    let param_share = share(within, n_errors);
    let ratio_share = share(ratios_ok, n_ratios);
    // A goal with no trial to measure it on (e.g. `--only none`) is not missed.
    let measured = [
        !with_effect.is_empty(),
        !without.is_empty(),
        n_errors > 0,
        n_ratios > 0,
    ];
    let pass = [
        !measured[0] || correct_share >= GOAL_CORRECT,
        !measured[1] || alarm_share <= GOAL_FALSE_ALARMS,
        !measured[2] || param_share >= 0.95,
        !measured[3] || ratio_share >= 0.95,
    ];

    if json_out {
        let trials: Vec<_> = outcomes
            .iter()
            .map(|o| {
                json!({
                    "trial": o.index,
                    "truth": label(o.truth),
                    "drawn": o.drawn.iter().map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
                    "verdict": verdict_label(&o.verdict),
                    "refusal": o.verdict.as_ref().err(),
                    "fitted": o.fitted.iter().copied().filter(|v| v.is_finite()).collect::<Vec<_>>(),
                    "param_error": o.param_error.filter(|v| v.is_finite()),
                    "heldout_after_over_floor": o.heldout.map(|h| h.0).filter(|v| v.is_finite()),
                    "heldout_before_over_floor": o.heldout.map(|h| h.1).filter(|v| v.is_finite()),
                    "strongest_score": o.strongest.0.is_finite().then_some(o.strongest.0),
                    "threshold": o.strongest.1.is_finite().then_some(o.strongest.1),
                    "seconds": o.seconds,
                })
            })
            .collect();
        let finite = |v: f64| v.is_finite().then_some(v);
        writeln!(
            out,
            "{}",
            json!({
                "command": command,
                "scenario": nominal.name,
                "trials": trials,
                "confusion": {"rows": classes, "columns": columns, "counts": matrix},
                "correct": correct, "with_effect": with_effect.len(), "correct_share": finite(correct_share),
                "false_alarms": false_alarms, "without_effect": without.len(), "false_alarm_share": finite(alarm_share),
                "param_within_20pct": within, "param_scored": n_errors, "param_median_error": finite(median_error),
                "heldout_within_1_2": ratios_ok, "heldout_scored": n_ratios, "heldout_median_ratio": finite(median_ratio),
                "pass": pass.iter().all(|p| *p),
                "wall_s": wall_s,
            })
        )?;
    } else {
        writeln!(
            out,
            "self-test: {n} blind trials of `{}`, seed {seed}, strength {strength} ({wall_s:.0} s)",
            nominal.name
        )?;
        writeln!(out, "confusion (rows: concealed effect; columns: verdict)")?;
        // Columns by code (E1…E9 the catalogue in order), rows by name.
        let code = |i: usize, c: &str| -> String {
            match c {
                "none" => "none".into(),
                "unexplained" => "unexpl".into(),
                "refused" => "refused".into(),
                _ => format!("E{i}"),
            }
        };
        write!(out, "{:>26}", "")?;
        for (i, c) in columns.iter().enumerate() {
            write!(out, " {:>7}", code(i, c))?;
        }
        writeln!(out)?;
        for (r, row) in matrix.iter().enumerate() {
            let name = if r == 0 {
                "none".to_string()
            } else {
                format!("E{r} {}", classes[r])
            };
            write!(out, "{name:>26}")?;
            for v in row {
                write!(out, " {v:>7}")?;
            }
            writeln!(out)?;
        }
        let pct = |v: f64| {
            if v.is_finite() {
                format!("{:.1} %", 100.0 * v)
            } else {
                "—".into()
            }
        };
        let verdict = |i: usize| {
            if !measured[i] {
                "not measured (no trial)"
            } else if pass[i] {
                "goal met"
            } else {
                "GOAL MISSED"
            }
        };
        writeln!(
            out,
            "named correctly: {correct}/{} concealed effects ({}; goal ≥ 95 %): {}",
            with_effect.len(),
            pct(correct_share),
            verdict(0)
        )?;
        writeln!(
            out,
            "false alarms: {false_alarms}/{} recordings without an effect ({}; goal ≤ 5 %): {}",
            without.len(),
            pct(alarm_share),
            verdict(1)
        )?;
        writeln!(
            out,
            "parameter recovery: {within}/{n_errors} within 20 % of the truth (median error {}): {}",
            pct(median_error),
            verdict(2)
        )?;
        for e in Effect::ALL {
            let mut errs: Vec<f64> = outcomes
                .iter()
                .filter(|o| o.truth == Some(e))
                .filter_map(|o| o.param_error)
                .collect();
            if errs.is_empty() {
                continue;
            }
            let worst = errs.iter().copied().fold(0.0, f64::max);
            let m = median(&mut errs);
            writeln!(
                out,
                "  {:<22} median {:>7}, worst {:>7} over {}",
                e.name(),
                pct(m),
                pct(worst),
                errs.len()
            )?;
        }
        writeln!(
            out,
            "held-out RMSE after the fix / noise floor: {ratios_ok}/{n_ratios} within 1.2 (median {}): {}",
            if median_ratio.is_finite() {
                format!("{median_ratio:.3}")
            } else {
                "—".to_string()
            },
            verdict(3)
        )?;
        let misses: Vec<String> = outcomes
            .iter()
            .filter(|o| match (&o.verdict, o.truth) {
                (Ok(Verdict::Effect(v)), Some(t)) => *v != t,
                (Ok(Verdict::None), None) => false,
                _ => true,
            })
            .map(|o| {
                format!(
                    "trial {}: {} → {}",
                    o.index,
                    label(o.truth),
                    match &o.verdict {
                        Ok(v) => v.name().to_string(),
                        Err(e) => format!("refused ({e})"),
                    }
                )
            })
            .collect();
        if !misses.is_empty() {
            writeln!(out, "misses: {}", misses.join("; "))?;
        }
        writeln!(out, "reproduce: {command}")?;
    }
    Ok(if pass.iter().all(|p| *p) {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
