//! A self-test's plan as the command line names it: `--only NAME`'s class, and the command
//! that reproduces the self-test.

use std::path::Path;

use super::{Plan, Reality, OUTSIDE};
use crate::Effect;

impl Plan {
    /// The class `--only NAME` draws: `none`, a catalogued effect, or (independent reality
    /// only) the effect outside the catalogue; `None` for any other name.
    #[must_use]
    pub fn class_named(name: &str, reality: Reality) -> Option<usize> {
        let entries = Effect::entries();
        match name {
            "none" => Some(0),
            _ if name == OUTSIDE && reality == Reality::Independent => Some(1 + entries.len()),
            _ => entries.iter().position(|x| *x == name).map(|k| 1 + k),
        }
    }

    /// The name of class `only` ([`Plan::class_named`]'s inverse).
    fn class_name(only: usize) -> &'static str {
        match only.checked_sub(1) {
            None => "none",
            Some(k) => Effect::entries().get(k).copied().unwrap_or(OUTSIDE),
        }
    }

    /// The command that reproduces this self-test (`sim`: the nominal scenario's file, when
    /// not the built-in one).
    #[must_use]
    pub fn command(&self, sim: Option<&Path>) -> String {
        let mut command = format!(
            "hilsim diagnose --self-test {} --seed {}",
            self.trials, self.seed
        );
        if let Some(sim) = sim {
            command += &format!(" --sim {}", sim.display());
        }
        if let Some(only) = self.only {
            command += &format!(" --only {}", Self::class_name(only));
        }
        if self.strength != 1.0 {
            command += &format!(" --strength {}", self.strength);
        }
        if self.reality != Reality::Hilsim {
            command += &format!(" --reality {}", self.reality.name());
        }
        if self.without_truth {
            command += " --without-truth";
        }
        command
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_class_name_reads_back() {
        for only in 0..=Effect::entries().len() + 1 {
            let name = Plan::class_name(only);
            assert_eq!(
                Plan::class_named(name, Reality::Independent),
                Some(only),
                "{name}"
            );
        }
        assert_eq!(Plan::class_named(OUTSIDE, Reality::Hilsim), None);
    }
}
