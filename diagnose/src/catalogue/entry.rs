//! What every catalogue entry says about its effect: one [`Entry`] per effect (in
//! `entries/`), reached as a `&'static dyn Entry` through [`super::Effect::entry`].

use hilsim_sim::scenario::Effects;

use super::params::ParamSpec;
use super::sensor::Sensor;
use crate::residuals::Covariate;

/// An explanatory variable an effect's mechanism acts through: what its error grows, shrinks or
/// appears with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Variable {
    /// The distance the beam or the echo travels to the surface.
    Range,
    /// The angle between the beam and the surface's normal.
    IncidenceAngle,
    /// The surface's reflectivity: how much of the beam's light it returns.
    Reflectivity,
    /// How near the beam passes to an edge between a near surface and a far one.
    NearnessToEdge,
    /// When within the lidar head's revolution a reading is taken.
    TimeInRevolution,
    /// The time since the unit was switched on, while it warms up.
    TimeSincePowerOn,
    /// The surfaces within the sonar's cone off its axis, the nearest of which echoes first.
    EchoCone,
    /// The air's temperature, which sets the speed of sound.
    AirTemperature,
    /// A wheel's change of speed.
    WheelAcceleration,
    /// A wheel's speed: how far the robot moves while a reading waits for its stamp.
    WheelSpeed,
    /// The wheels' commanded speeds and their changes.
    Command,
    /// The beam's direction in the lidar's frame.
    Bearing,
    /// The sensor's stamps against the instants it measured.
    Time,
    /// The distance a wheel rolls.
    WheelTravel,
    /// The robot's turning.
    Turn,
}

impl Variable {
    /// The variable the residuals are tested against that it is, where it is one.
    #[must_use]
    pub(crate) fn covariate(self) -> Option<Covariate> {
        match self {
            Variable::Range => Some(Covariate::Range),
            Variable::IncidenceAngle => Some(Covariate::Incidence),
            Variable::Bearing => Some(Covariate::Bearing),
            Variable::TimeSincePowerOn => Some(Covariate::Time),
            Variable::WheelSpeed => Some(Covariate::WheelSpeed),
            Variable::NearnessToEdge => Some(Covariate::Edge),
            Variable::EchoCone => Some(Covariate::OffAxisNearer),
            Variable::Reflectivity
            | Variable::TimeInRevolution
            | Variable::AirTemperature
            | Variable::WheelAcceleration
            | Variable::Command
            | Variable::Time
            | Variable::WheelTravel
            | Variable::Turn => None,
        }
    }

    /// Its name in reports.
    ///
    /// ```
    /// use hilsim_diagnose::Variable;
    /// assert_eq!(Variable::IncidenceAngle.name(), "incidence angle");
    /// ```
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Variable::Range => "range",
            Variable::IncidenceAngle => "incidence angle",
            Variable::Reflectivity => "reflectivity",
            Variable::NearnessToEdge => "nearness to an edge",
            Variable::TimeInRevolution => "time in the revolution",
            Variable::TimeSincePowerOn => "time since power-on",
            Variable::EchoCone => "echoes in the cone",
            Variable::AirTemperature => "air temperature",
            Variable::WheelAcceleration => "wheel acceleration",
            Variable::WheelSpeed => "wheel speed",
            Variable::Command => "command",
            Variable::Bearing => "bearing",
            Variable::Time => "time stamps",
            Variable::WheelTravel => "wheel travel",
            Variable::Turn => "turn",
        }
    }
}

/// One catalogued effect: its name, the sensor it shows in, its parameters and their absence,
/// the departure from that absence that names it, the scenario table that switches it on and
/// the sentence its verdict is told in. Each entry is a unit value behind a `&'static dyn
/// Entry`, so that the diagnosis asks an effect instead of matching on it.
pub trait Entry: Sync {
    /// The catalogue name.
    fn name(&self) -> &'static str;

    /// The name with the sensor where one entry is fitted in several (`sensor_latency
    /// (lidar)`), for reports that list the effects one by one; else the name.
    fn label(&self) -> String {
        self.name().to_string()
    }

    /// The sensor it is fitted and named in. Where an effect shows in two, the one whose data
    /// tell it apart from its neighbours.
    fn sensor(&self) -> Sensor;

    /// Whether it moves the drive too, beside its own sensor (the wheels' radius and base).
    fn shows_in_drive(&self) -> bool {
        false
    }

    /// Whether it changes what `sensor` reads (or where the drive goes): its own sensor and,
    /// where [`Entry::shows_in_drive`], the drive too. The drive's data are diagnosed on top of
    /// the effects named elsewhere that show in it, so that their mismatch there is theirs,
    /// not another effect's.
    fn shows_in(&self, sensor: Sensor) -> bool {
        self.sensor() == sensor || (sensor == Sensor::Drive && self.shows_in_drive())
    }

    /// Whether it changes the values its sensor reads (or where the drive goes), rather than
    /// which readings there are.
    fn moves_readings(&self) -> bool {
        true
    }

    /// Whether a second cause of it adds its scored size to the first's (two delays add, two
    /// radius errors multiply to about their sum), rather than composing otherwise.
    fn sizes_add(&self) -> bool {
        true
    }

    /// The explanatory variables its mechanism acts through.
    fn variables(&self) -> &'static [Variable];

    /// Whether a world's own error (a map's cell off by up to its size) can move the readings
    /// as it does, so that its size counts only beyond that reach. A map is the same at every
    /// instant: an effect that changes with the time since power-on changes the readings of
    /// one place between visits, which no error of the map does.
    fn mimicked_by_the_world(&self) -> bool {
        !self.variables().contains(&Variable::TimeSincePowerOn)
    }

    /// Whether its size (its first parameter, seconds) is a delay of its sensor against the
    /// path, or the mirror of one: a path whose own timing is off by as much passes for it.
    fn sized_as_a_delay(&self) -> bool {
        false
    }

    /// Whether it is its sensor's calibration of the range (a polynomial in the range alone),
    /// which fitted to an error of its own shape leaves nothing against the range.
    fn is_range_calibration(&self) -> bool {
        false
    }

    /// Whether a fit of `params` settles within `span_s`: an effect that settles with a time
    /// constant does where that is at most `span_s`; any other does.
    fn settles_within(&self, params: &[f64], span_s: f64) -> bool {
        let _ = (params, span_s);
        true
    }

    /// Whether, taken up by a path estimated from the lidar, it shows in the sensors that look
    /// from the robot (the sonar, the encoders) on a path whose headings span
    /// `heading_span_rad`, and is fitted through them.
    fn seen_through_path(&self, heading_span_rad: f64) -> bool {
        let _ = heading_span_rad;
        false
    }

    /// Its parameters, in the order a [`crate::Hypothesis`] holds them.
    ///
    /// The fit's ranges are wide enough for any plausible unit (several times the self-test's
    /// draws) and the grids fine enough that the likelihood is unimodal between neighbouring
    /// points. The self-test draws each from its moderate range, × its strength unless said.
    fn params(&self) -> &'static [ParamSpec];

    /// The shapes its fit searches one at a time before (see
    /// [`Entry::shapes_refined_together`]) refining every parameter together: each the
    /// parameters left free (indices into [`Entry::params`]), the others at their
    /// [`Entry::absent`] values. None: all parameters at once.
    fn shapes(&self) -> &'static [&'static [usize]] {
        &[]
    }

    /// Parameters of no shape that the joint refinement of the best of [`Entry::shapes`]
    /// frees as well, against a recorded path (`truth.csv`) only: a form that path shows and
    /// an estimated one takes up. Elsewhere they are held at their [`Entry::absent`] values.
    fn refined_against_recorded_path(&self) -> &'static [usize] {
        &[]
    }

    /// The parameters that set its form, not its size (indices into [`Entry::params`]). A
    /// path estimated from the lidar takes up part of an effect's size, not of its form, so
    /// the realignment follows the size alone to its fixed point.
    fn form_params(&self) -> &'static [usize] {
        &[]
    }

    /// The parameters its fit left free at `params` (indices into [`Entry::params`]): those of
    /// its [`Entry::shapes`] (all with none), and of alternative shapes the one `params` is
    /// in (a parameter of another shape departs from its absence); the rest were held at
    /// their absence and are not estimates.
    fn free(&self, params: &[f64]) -> Vec<usize> {
        let shapes = self.shapes();
        if shapes.is_empty() {
            return (0..self.params().len()).collect();
        }
        let absent = self.absent(0.0);
        let mut free: Vec<usize> = Vec::new();
        let mut chosen: Vec<&[usize]> = shapes.to_vec();
        if !self.shapes_refined_together() {
            let departs = |shape: &[usize]| {
                shape
                    .iter()
                    .any(|&i| params.get(i) != absent.get(i) && !shapes[0].contains(&i))
            };
            chosen = vec![shapes
                .iter()
                .skip(1)
                .find(|s| departs(s))
                .copied()
                .unwrap_or(shapes[0])];
        }
        for shape in chosen {
            for &i in shape {
                if !free.contains(&i) {
                    free.push(i);
                }
            }
        }
        // A parameter refined on its own against a recorded path, where the refinement moved it.
        for &i in self.refined_against_recorded_path() {
            if params.get(i) != absent.get(i) && !free.contains(&i) {
                free.push(i);
            }
        }
        free.sort_unstable();
        free
    }

    /// Whether the best of [`Entry::shapes`] is refined with all parameters free.
    fn shapes_refined_together(&self) -> bool {
        true
    }

    /// Whether, along a path estimated from the lidar, its [`Entry::shapes`] are settled apart
    /// (each from the first fit's size) rather than together.
    fn shapes_settled_apart(&self) -> bool {
        false
    }

    /// The parameter values at which the effect is absent (what the nominal model assumes),
    /// given the declared sonar cone (for the beam width).
    fn absent(&self, declared_half_angle_deg: f64) -> Vec<f64> {
        let _ = declared_half_angle_deg;
        vec![0.0]
    }

    /// The smallest departure of each parameter that describes its size from its absence that
    /// names the effect, as (index into [`Entry::params`], least departure): below it the
    /// fitted model is the nominal one to within what the sensors resolve, so what it
    /// "explains" is noise the fit chased. Each is about one millimetre of range where the
    /// effect acts (or the model's own resolution).
    fn least_departures(&self) -> &'static [(usize, f64)];

    /// Whether `params` depart from the effect's absence by [`Entry::least_departures`]: an
    /// effect of several parameters that all describe its size (the mount, the two wheels, the
    /// warm-up's and the incidence's two terms, the range bias's three) departs when any of
    /// them does.
    fn departs(&self, params: &[f64], declared_half_angle_deg: f64) -> bool {
        let absent = self.absent(declared_half_angle_deg);
        self.least_departures().iter().any(|&(i, least)| {
            params
                .get(i)
                .zip(absent.get(i))
                .is_some_and(|(v, a)| (v - a).abs() >= least)
        })
    }

    /// The parameters that carry its size, each with its weight in the size: its first
    /// parameter unless said.
    fn size_terms(&self) -> &'static [(usize, f64)] {
        &[(0, 1.0)]
    }

    /// The quantity the self-test scores a fit of `params` by: the first parameter's departure
    /// from its [`SelfTestRange::scored`](super::SelfTestRange::scored) centre unless said.
    fn scored(&self, params: &[f64]) -> f64 {
        let p0 = params.first().copied().unwrap_or(0.0);
        self.params()
            .first()
            .map_or(f64::NAN, |spec| spec.self_test.scored(p0))
    }

    /// Switches the effect on in `effects` with `params` (in the order of [`Entry::params`]; a
    /// missing one is 0), replacing its table if the scenario already has one. A parameter at
    /// which the scenario's table cannot exist leaves the effect off.
    fn apply(&self, params: &[f64], effects: &mut Effects);

    /// One sentence: the physics the simulation left out, with the fitted parameters (and the
    /// declared sonar cone the beam width replaces).
    fn explanation(&self, params: &[f64], declared_half_angle_deg: f64) -> String;
}

/// The size of an effect whose size has several terms: each of its [`Entry::size_terms`]'
/// parameters (a missing one 0) times its weight, summed.
pub(super) fn weighted_size(entry: &dyn Entry, params: &[f64]) -> f64 {
    let p = |i: usize| params.get(i).copied().unwrap_or(0.0);
    entry
        .size_terms()
        .iter()
        .map(|&(i, weight)| weight * p(i))
        .sum()
}
