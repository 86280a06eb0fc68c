//! A self-test's plan as the command line names it: the flags checked into a plan, `--only
//! NAME`'s class, and the command that reproduces the self-test.

use std::path::Path;

use super::{Plan, Reality, MAX_TRIALS, OUTSIDE};
use crate::{Effect, MismatchError};

/// A self-test as typed: `--self-test N` and the flags that shape it, before any check.
#[derive(Debug, Clone, Copy)]
pub struct Flags<'a> {
    /// `--self-test N`: the trials, as typed (any integer).
    pub trials: i128,
    /// `--seed S` (default 1).
    pub seed: Option<u64>,
    /// `--strength`.
    pub strength: f64,
    /// `--only NAME`.
    pub only: Option<&'a str>,
    /// `--reality`: `independent`, else hilsim's own.
    pub reality: &'a str,
    /// `--without-truth`.
    pub without_truth: bool,
    /// `--trial I`: one trial's diagnosis.
    pub trial: Option<u64>,
    /// `--report DIR` given: it is of one trial, so it needs `--trial`.
    pub report: bool,
}

impl Plan {
    /// The plan the flags ask for, each checked before any trial is run.
    ///
    /// # Errors
    /// [`MismatchError::Input`] naming the flag that is out of range or unknown.
    pub fn from_flags(flags: &Flags<'_>) -> Result<Plan, MismatchError> {
        let input = |message: String| Err(MismatchError::Input(message));
        let n = flags.trials;
        if n < 1 {
            return input(format!(
                "--self-test: expected at least one trial, found {n}"
            ));
        }
        let Some(n) = u64::try_from(n).ok().filter(|n| *n <= MAX_TRIALS) else {
            return input(format!(
                "--self-test: expected at most {MAX_TRIALS} trials, found {n}"
            ));
        };
        let strength = flags.strength;
        if !(strength.is_finite() && strength > 0.0 && strength <= 5.0) {
            return input(format!(
                "--strength: expected a factor in (0, 5], found {strength:?}"
            ));
        }
        if flags.report && flags.trial.is_none() {
            return input(
                "--report with --self-test needs --trial I: the report is of one trial".into(),
            );
        }
        let reality = match flags.reality {
            "independent" => Reality::Independent,
            "varied" => Reality::Varied,
            _ => Reality::Hilsim,
        };
        let only = match flags.only {
            None => None,
            Some(name) => match Plan::class_named(name, reality) {
                Some(class) => Some(class),
                None => {
                    return input(format!(
                        "--only: expected `none` or a catalogued effect, found `{name}`"
                    ))
                }
            },
        };
        if let Some(i) = flags.trial.filter(|i| *i >= n) {
            return input(format!(
                "--trial: expected a trial below --self-test {n}, found {i}"
            ));
        }
        Ok(Plan {
            trials: n,
            seed: flags.seed.unwrap_or(1),
            strength,
            only,
            reality,
            without_truth: flags.without_truth,
        })
    }

    /// The class `--only NAME` draws: `none`, a catalogued effect, or (independent reality
    /// only) the effect outside the catalogue; `None` for any other name.
    #[must_use]
    pub fn class_named(name: &str, reality: Reality) -> Option<usize> {
        let entries = Effect::entries();
        match name {
            "none" => Some(0),
            _ if name == OUTSIDE && reality.independent() => Some(1 + entries.len()),
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
