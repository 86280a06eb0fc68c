//! The diagnosis as text for people.

use std::fmt::Write as _;

use super::format::{
    fit_metric, fit_size, fit_value, fmt_sig, heldout_unit, mm, rmse_of, without_error,
};
use crate::outcome::Diagnosis;

/// The diagnosis for people: a few lines.
#[must_use]
pub fn summary(d: &Diagnosis) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "verdict: {}", d.verdict.name());
    let _ = writeln!(s, "  {}", d.explanation);
    for (k, e) in d.effects.iter().enumerate() {
        let f = &e.fit;
        let params: Vec<String> = f
            .effect
            .params()
            .iter()
            .enumerate()
            .map(|(i, spec)| {
                let sd = f.param_sd[i];
                // A standard error of exactly 0: held, or a form without one.
                if sd == 0.0 {
                    return format!("{} = {} {}", spec.name, fmt_sig(f.params[i]), spec.unit)
                        .trim_end()
                        .to_string()
                        + &format!(" ({})", without_error(f, i));
                }
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
        let role = if k == 0 { "effect" } else { "also" };
        let _ = writeln!(s, "{role}: {} ({})", f.effect, params.join(", "));
        if let Some(l) = &e.located {
            let _ = writeln!(s, "  located: {} — {} ({:.1}σ)", l.sensor, l.place, l.score);
            let _ = writeln!(s, "    {}", l.detail);
        }
        let _ = writeln!(
            s,
            "  held-out {} {}{}: {} before, {} after (noise floor {}, {} {}; gain {:.1} nats; \
             changes the readings by {})",
            f.sensor,
            fit_metric(f),
            rmse_of(f),
            fit_value(f, f.rmse_before),
            fit_value(f, f.rmse_after),
            fit_value(f, f.noise_floor),
            f.heldout_n,
            heldout_unit(f),
            f.heldout_gain,
            fit_size(f)
        );
    }
    for w in &d.world {
        let _ = writeln!(
            s,
            "within the world's error: {} — {} ({}; the map's cells can move a reading {} there; \
             {:.1}σ)",
            w.sensor,
            w.place,
            mm(w.size_m),
            mm(w.world_m),
            w.score
        );
        let _ = writeln!(s, "  {}", w.detail);
    }
    for u in &d.unexplained {
        let _ = writeln!(
            s,
            "unexplained: {} — {} ({}, {:.1}σ)",
            u.sensor,
            u.place,
            mm(u.size_m),
            u.score
        );
        let _ = writeln!(s, "  {}", u.detail);
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
    for x in &d.sensors {
        let _ = writeln!(s, "{} judged against {}", x.sensor, x.reference);
    }
    for n in &d.notes {
        let _ = writeln!(s, "note: {n}");
    }
    s
}
