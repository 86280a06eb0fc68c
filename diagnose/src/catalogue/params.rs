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
