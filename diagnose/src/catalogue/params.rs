//! An effect's parameter: the range the fit searches and the range the blind self-test draws its
//! true value from.

/// A parameter of an effect and the range the fit searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// Its name (the scenario key of `[effects.NAME]` where there is one).
    pub name: &'static str,
    /// Its unit, for reports.
    pub unit: &'static str,
    /// Lowest value searched.
    pub lo: f64,
    /// Highest value searched.
    pub hi: f64,
    /// Searched on a logarithmic scale (positive ranges spanning decades).
    pub log: bool,
    /// Points of the coarse grid the search starts from.
    pub grid: usize,
    /// Where the self-test draws its true value from.
    pub self_test: SelfTestRange,
    /// Which ends of the search are only where it stops, not ends of the effect: a fit there
    /// is a bound on the size, not an estimate of it.
    pub limits: SearchLimits,
}

/// Which ends of a parameter's search are where the search stops rather than ends the effect
/// itself has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchLimits {
    /// Both: a size searched over a window (a mount's yaw, a wheel's scale).
    Both,
    /// The upper one: a size that starts at zero, the effect's absence (a delay, a slip's
    /// gain).
    Upper,
    /// Neither: the ends of a family of forms (the power of `tan θ`, the braking share, a
    /// warm-up's time constant past the log's length), where a fit is a form it takes.
    Form,
}

impl SearchLimits {
    /// Whether `value` sits at one of `spec`'s search limits: within half a percent of the
    /// searched span (on a log scale, of its logarithm) of a limiting end.
    #[must_use]
    pub fn at_limit(spec: &ParamSpec, value: f64) -> bool {
        let unit = if spec.log {
            (value.max(spec.lo).ln() - spec.lo.ln()) / (spec.hi.ln() - spec.lo.ln())
        } else {
            (value - spec.lo) / (spec.hi - spec.lo)
        };
        const EDGE: f64 = 0.005;
        match spec.limits {
            SearchLimits::Both => unit <= EDGE || unit >= 1.0 - EDGE,
            SearchLimits::Upper => unit >= 1.0 - EDGE,
            SearchLimits::Form => false,
        }
    }
}

/// Searched on a linear scale; the self-test draws it from `self_test`.
pub(super) const fn lin(
    name: &'static str,
    unit: &'static str,
    (lo, hi): (f64, f64),
    grid: usize,
    self_test: SelfTestRange,
) -> ParamSpec {
    ParamSpec {
        name,
        unit,
        lo,
        hi,
        log: false,
        grid,
        self_test,
        limits: SearchLimits::Both,
    }
}

/// Searched on a logarithmic scale; the self-test draws it from `self_test`.
pub(super) const fn log(
    name: &'static str,
    unit: &'static str,
    range: (f64, f64),
    grid: usize,
    self_test: SelfTestRange,
) -> ParamSpec {
    ParamSpec {
        log: true,
        ..lin(name, unit, range, grid, self_test)
    }
}

impl ParamSpec {
    /// Searched from zero, the effect's absence: only its upper end is a search limit.
    #[must_use]
    pub(super) const fn searched_from_zero(self) -> Self {
        Self {
            limits: SearchLimits::Upper,
            ..self
        }
    }

    /// A form's parameter: its ends are forms the effect takes, not search limits.
    #[must_use]
    pub(super) const fn form(self) -> Self {
        Self {
            limits: SearchLimits::Form,
            ..self
        }
    }
}

/// Where a value the self-test draws comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DrawSource {
    /// Uniform in `[lo, hi]`.
    Uniform {
        /// The lowest magnitude.
        lo: f64,
        /// The highest magnitude.
        hi: f64,
    },
    /// Not drawn: the scenario lidar's own revolution period, `60 / rpm`.
    LidarRevolution,
    /// Not drawn: zero (a part of an effect whose size another parameter draws, e.g. the
    /// warm-up's constant term, which the self-test draws as a shape of its quadratic one).
    Zero,
}

/// How the blind self-test draws a parameter's true value (`docs/diagnose.md`'s moderate
/// ranges): a magnitude from `source`, with a random sign when `signed` (the sign drawn first),
/// times the trial's strength when `scaled`, as a departure from `around` when there is one,
/// clamped to `[min, max]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelfTestRange {
    /// Where the magnitude comes from.
    pub source: DrawSource,
    /// A random sign.
    pub signed: bool,
    /// Multiplied by the trial's strength.
    pub scaled: bool,
    /// The value the draw departs from (and that the self-test scores the departure from);
    /// `None`: zero.
    pub around: Option<f64>,
    /// The smallest value drawn.
    pub min: f64,
    /// The largest value drawn.
    pub max: f64,
}

impl SelfTestRange {
    /// A magnitude uniform in `[lo, hi]` times the trial's strength.
    #[must_use]
    pub const fn uniform(lo: f64, hi: f64) -> Self {
        Self {
            source: DrawSource::Uniform { lo, hi },
            signed: false,
            scaled: true,
            around: None,
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
        }
    }

    /// The scenario lidar's own revolution period.
    #[must_use]
    pub const fn lidar_revolution() -> Self {
        Self {
            source: DrawSource::LidarRevolution,
            scaled: false,
            ..Self::uniform(0.0, 0.0)
        }
    }

    /// Zero, not drawn.
    #[must_use]
    pub const fn zero() -> Self {
        Self {
            source: DrawSource::Zero,
            scaled: false,
            ..Self::uniform(0.0, 0.0)
        }
    }

    /// With a random sign.
    #[must_use]
    pub const fn signed(self) -> Self {
        Self {
            signed: true,
            ..self
        }
    }

    /// Not scaled by the trial's strength.
    #[must_use]
    pub const fn unscaled(self) -> Self {
        Self {
            scaled: false,
            ..self
        }
    }

    /// At most `max`.
    #[must_use]
    pub const fn at_most(self, max: f64) -> Self {
        Self { max, ..self }
    }

    /// A departure from `centre`, the value clamped to `[min, max]`.
    #[must_use]
    pub const fn around(self, centre: f64, min: f64, max: f64) -> Self {
        Self {
            around: Some(centre),
            min,
            max,
            ..self
        }
    }

    /// The value the self-test scores the fit by: the departure from `around`, if any.
    #[must_use]
    pub fn scored(&self, value: f64) -> f64 {
        match self.around {
            Some(centre) => value - centre,
            None => value,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_ends_where_a_search_stops_are_its_limits() {
        let window = lin("yaw_deg", "deg", (-8.0, 8.0), 9, SelfTestRange::zero());
        assert!(SearchLimits::at_limit(&window, -7.97));
        assert!(SearchLimits::at_limit(&window, 8.0));
        assert!(!SearchLimits::at_limit(&window, -7.8));
        // From zero: zero is the effect's absence, not a limit.
        let delay = window.searched_from_zero();
        assert!(!SearchLimits::at_limit(&delay, -8.0));
        assert!(SearchLimits::at_limit(&delay, 8.0));
        // A form's ends are forms.
        assert!(!SearchLimits::at_limit(&window.form(), 8.0));
        // On a log scale, half a percent of the decades: 0.5–50 m spans 4.6 in ln, so 2.3 %
        // of the value.
        let ranged = log(
            "half_loss_range_m",
            "m",
            (0.5, 50.0),
            11,
            SelfTestRange::zero(),
        );
        assert!(SearchLimits::at_limit(&ranged, 49.0));
        assert!(!SearchLimits::at_limit(&ranged, 48.0));
        assert!(SearchLimits::at_limit(&ranged, 0.51));
    }
}
