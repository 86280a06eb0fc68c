//! A range error of another shape than the catalogue's polynomial (a periodic one,
//! `A sin(2π d/λ)`, outside the catalogue) is `unexplained`, not a `lidar_range_bias` whose
//! polynomial follows its slow part: the bias leaves the lidar's error clustered by range.

use hilsim_diagnose::{diagnose, Effect, Options, Sensor, SimPhysics, Verdict};
use hilsim_reality::{Concealed, Nuisances};

use crate::catalogue::{of, room};

#[test]
fn a_periodic_range_error_is_unexplained_not_a_range_bias() {
    let nominal = room();
    // The self-test's independent reality, no nuisances: 35 mm over a 0.31 m period.
    let periodic = Concealed::LidarPeriodicRange {
        amplitude_m: 0.035,
        period_m: 0.31,
    };
    let recording = hilsim_reality::record(&nominal, &[periodic], Nuisances::default(), 21);
    let physics = SimPhysics::new(&nominal).expect("the physics");
    let options = Options {
        effects: of(Sensor::Lidar),
        ..Options::default()
    };
    let d = diagnose(&physics, &recording, &options).expect("a diagnosis");
    let names: Vec<Effect> = d.effects.iter().map(|e| e.fit.effect).collect();
    assert!(!names.contains(&Effect::LidarRangeBias), "{names:?}");
    assert_eq!(d.verdict, Verdict::Unexplained, "{names:?}");
}
