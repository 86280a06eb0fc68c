//! The diagnosis as the JSON object of `interfaces.md`.

use serde_json::{json, Map, Value};

use crate::outcome::Diagnosis;

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
