//! The diagnosis as the JSON object of `interfaces.md`.

use serde_json::{json, Map, Value};

use crate::explain::CandidateFit;
use crate::locate::Evidence;
use crate::outcome::Diagnosis;

/// A finite number as JSON, anything else as `null`: no NaN ever reaches a user.
fn num(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

/// A located departure: where, the numbers behind it, its score and its size.
fn evidence(l: &Evidence) -> Value {
    json!({
        "sensor": l.sensor.name(),
        "where": l.place,
        "evidence": l.detail,
        "score": num(l.score),
        "size_m": num(l.size_m),
    })
}

/// An effect's parameters and their standard errors, by name.
fn params_of(f: &CandidateFit) -> (Map<String, Value>, Map<String, Value>) {
    let mut params = Map::new();
    let mut param_sd = Map::new();
    for (i, spec) in f.effect.params().iter().enumerate() {
        params.insert(spec.name.to_string(), num(f.params[i]));
        param_sd.insert(spec.name.to_string(), num(f.param_sd[i]));
    }
    (params, param_sd)
}

/// An effect's held-out fit: its sensor's RMSE without it (the others named in the sensor in
/// place) and with it.
fn fit_of(f: &CandidateFit) -> Value {
    json!({
        // The dropout moves no reading: its before and after are of the losses (1 lost, 0
        // read) less their chances.
        "metric": if f.effect.moves_readings() { "heldout_rmse_m" } else { "heldout_loss_rms" },
        "sensor": f.sensor.name(),
        "before": num(f.rmse_before),
        "after": num(f.rmse_after),
        "noise_floor_m": num(f.noise_floor),
        "readings": f.heldout_n,
    })
}

/// The diagnosis as the `hilsim diagnose --json` object of `interfaces.md` (plus `param_sd`,
/// `fit.sensor`, `fit.noise_floor_m`, `fit.readings`, `located.score`, `located.size_m`,
/// `effects[].heldout_gain`, `effects[].size_m`, `unexplained[].score`, `alignment`,
/// `references` and `notes`).
#[must_use]
pub fn to_json(d: &Diagnosis) -> Value {
    let located = d.located.as_ref().map_or(Value::Null, evidence);
    let (params, param_sd) = d
        .fitted
        .as_ref()
        .map_or_else(|| (Map::new(), Map::new()), params_of);
    let fit = match &d.fitted {
        Some(f) => fit_of(f),
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
    let effects: Vec<Value> = d
        .effects
        .iter()
        .map(|e| {
            let (params, param_sd) = params_of(&e.fit);
            json!({
                "effect": e.fit.effect.name(),
                "params": params,
                "param_sd": param_sd,
                "located": e.located.as_ref().map_or(Value::Null, evidence),
                "fit": fit_of(&e.fit),
                "heldout_gain": num(e.fit.heldout_gain),
                "size_m": num(e.fit.size_m),
            })
        })
        .collect();
    let unexplained: Vec<Value> = d
        .unexplained
        .iter()
        .map(|u| {
            json!({
                "sensor": u.sensor.name(),
                "where": u.place,
                "size_m": num(u.size_m),
                "world_m": num(u.world_m),
                "beyond_world_m": num(u.beyond_world_m),
                "evidence": u.detail,
                "score": num(u.score),
            })
        })
        .collect();
    let world: Vec<Value> = d
        .world
        .iter()
        .map(|w| {
            json!({
                "sensor": w.sensor.name(),
                "where": w.place,
                "size_m": num(w.size_m),
                "world_m": num(w.world_m),
                "evidence": w.detail,
                "score": num(w.score),
            })
        })
        .collect();
    json!({
        "mismatch": d.mismatch(),
        "located": located,
        "effect": d.verdict.name(),
        "explanation": d.explanation,
        "params": params,
        "param_sd": param_sd,
        "fit": fit,
        "effects": effects,
        "unexplained": unexplained,
        "world": world,
        "candidates": candidates,
        "alignment": d.alignment.name(),
        "references": d
            .sensors
            .iter()
            .map(|s| (s.sensor.name().to_string(), json!(s.reference)))
            .collect::<Map<String, Value>>(),
        "notes": d.notes,
    })
}
