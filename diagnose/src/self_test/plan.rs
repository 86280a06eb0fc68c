//! What a self-test is asked: how many trials, their seed and strength, which class, and what
//! makes the "real" recordings.

/// What a self-test is asked: trials of a nominal scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plan {
    /// Trials.
    pub trials: u64,
    /// The self-test's seed S: trial `i` is a function of (S, i) alone.
    pub seed: u64,
    /// The drawn parameters' scale (1: the documented moderate ranges).
    pub strength: f64,
    /// Draw only this class (0: none; 1..=16: the catalogue in order; 17, the independent
    /// reality only: the effect outside the catalogue), or any.
    pub only: Option<usize>,
    /// What makes the "real" recordings.
    pub reality: Reality,
    /// Whether the "real" recordings lose their `truth.csv` before they are diagnosed, as a
    /// robot's log without motion capture (the trajectory is then estimated from the lidar).
    pub without_truth: bool,
}

/// What makes a self-test's "real" recordings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reality {
    /// hilsim's own simulator with the drawn effect switched on (its own noise seed).
    #[default]
    Hilsim,
    /// `hilsim-reality`, which shares no model code with the simulator, with random
    /// nuisances, two effects at once in a fifth of the trials and an effect outside the
    /// catalogue.
    Independent,
    /// The independent reality with each concealed mechanism in a form the catalogue does not
    /// write: a random smooth monotone curve of its variable on a fair coin, else one of the
    /// physical forms of `hilsim_reality::form` other than the catalogue's.
    Varied,
}

impl Reality {
    /// Its name on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Hilsim => "hilsim",
            Self::Independent => "independent",
            Self::Varied => "varied",
        }
    }

    /// Whether it is the independent generator (with its nuisances, two effects at once and an
    /// effect outside the catalogue), in the catalogue's forms or varied ones.
    #[must_use]
    pub fn independent(self) -> bool {
        self != Self::Hilsim
    }
}
