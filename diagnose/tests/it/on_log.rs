//! The self-test on a log: mechanisms concealed in a recording's own data are named with their
//! sizes, the untouched log's halves agree, and a trial's draws are its own. The "log" here is a
//! run `hilsim` makes of a short room scenario, diagnosed against that scenario (a real log's
//! figures are in docs/diagnose.md, with the commands that make them); each diagnosis tries the
//! concealed mechanism's sensor's effects, which keeps a debug build's test time to a minute.

use std::path::Path;
use std::sync::{Mutex, OnceLock};

use hilsim_diagnose::self_test::on_log::{
    baseline, conceal_and_diagnose, concealments, BuiltWorld, GivenWorld, LogPlan, LogWorld,
};
use hilsim_diagnose::self_test::{not_concealed, Concealment};
use hilsim_diagnose::{Diagnosis, Effect, Options, Sensor};
use hilsim_fixtures::rooms::ROOM_4X3;
use hilsim_lidar_emulator::Emulation;
use hilsim_recording::{OdometrySample, Recording};
use hilsim_sim::Scenario;

use crate::catalogue::{of, room};

/// A faithful run of the room, with truth, its encoders without the scenario's systematic
/// slip (a twin built from a log declares ideal encoders, and names that slip as radii).
/// Recorded once for every test of this module (each takes its own copy).
fn log() -> (Scenario, Recording) {
    static LOG: OnceLock<(Scenario, Recording)> = OnceLock::new();
    LOG.get_or_init(|| {
        let mut room = room();
        if let Some(odometer) = room.sensors.odometer.as_mut() {
            odometer.slip = 0.0;
        }
        let recording = Emulation::new(&room, 11)
            .expect("the emulation")
            .run()
            .recording;
        (room, recording)
    })
    .clone()
}

fn trying(sensor: Sensor) -> Options {
    Options {
        effects: of(sensor),
        ..Options::default()
    }
}

/// In the worlds built from the log and from each of its halves (as `hilsim world` builds
/// them), the faithful run names nothing in its encoders, and its halves agree.
#[test]
fn a_faithful_logs_halves_agree_and_name_nothing() {
    let (_, recording) = log();
    let b = baseline(
        &recording,
        &BuiltWorld::default(),
        &trying(Sensor::Odometer),
    )
    .expect("a baseline");
    assert!(b.whole.named.is_empty(), "{:?}", b.whole);
    assert!(b.halves.is_some() && b.stable(), "{b:?}");
}

/// Encoders rewritten for wheels 2.5 % large on the left and 2 % small on the right, and the
/// lidar stamped 50 ms late: each named with its size within the self-test's 20 %.
#[test]
fn wheels_and_a_late_lidar_concealed_in_the_log_are_named_with_their_sizes() {
    let (room, recording) = log();
    let world = GivenWorld(room);
    for (concealed, sensor) in [
        (
            Concealment::WheelRadius {
                left_scale: 1.025,
                right_scale: 0.98,
            },
            Sensor::Odometer,
        ),
        (
            Concealment::Restamp {
                sensor: Sensor::Lidar,
                delay_s: 0.05,
            },
            Sensor::Lidar,
        ),
    ] {
        let d = conceal_and_diagnose(&recording, &world, &[concealed], &trying(sensor), "t")
            .expect("a diagnosis")
            .diagnosis;
        assert_named_within_a_fifth(&d, concealed);
    }
}

/// A world whose map moves with the lidar's named delay or mount (as one built from the log's
/// own scans at its truth's poses does) is built again under what the first judgement named,
/// and the log judged against it: a lidar stamped 50 ms late is named, the world is asked again
/// under that delay, and the delay is named against it with its size within the self-test's
/// 20 %. A world that does not move (the user's scenario) is judged once.
#[test]
fn a_late_lidar_is_judged_again_in_the_world_rebuilt_under_it() {
    /// The room, rebuilt as the room, counting how often and under which delay.
    struct Rebuilt(Scenario, Mutex<Vec<f64>>);
    impl LogWorld for Rebuilt {
        fn scenario(&self, _: &Recording, _: &str) -> Result<Scenario, String> {
            Ok(self.0.clone())
        }
        fn describe(&self) -> String {
            "the room, rebuilt".to_string()
        }
        fn rebuilt(
            &self,
            _: &Recording,
            _: &str,
            scenario: &Scenario,
            diagnosis: &Diagnosis,
        ) -> Option<Result<Scenario, String>> {
            let delay = diagnosis
                .effects
                .iter()
                .find(|e| e.fit.effect == Effect::SensorLatency(Sensor::Lidar))?;
            self.1.lock().expect("the log").push(delay.fit.params[0]);
            Some(Ok(scenario.clone()))
        }
    }
    let (room, recording) = log();
    let concealed = Concealment::Restamp {
        sensor: Sensor::Lidar,
        delay_s: 0.05,
    };
    let world = Rebuilt(room.clone(), Mutex::new(Vec::new()));
    let run = conceal_and_diagnose(
        &recording,
        &world,
        &[concealed],
        &trying(Sensor::Lidar),
        "t",
    )
    .expect("a diagnosis");
    let asked = world.1.lock().expect("the log").clone();
    assert_eq!(asked.len(), 1, "{asked:?}");
    assert!((asked[0] - 0.05).abs() < 0.01, "{asked:?}");
    let d = &run.diagnosis;
    assert!(
        d.notes
            .iter()
            .any(|n| n.contains("then again with each scan placed under the lidar's delay of")),
        "{:?}",
        d.notes
    );
    assert_named_within_a_fifth(d, concealed);
    let once = conceal_and_diagnose(
        &recording,
        &GivenWorld(room),
        &[concealed],
        &trying(Sensor::Lidar),
        "t",
    )
    .expect("a diagnosis");
    assert!(
        !once
            .diagnosis
            .notes
            .iter()
            .any(|n| n.contains("built again")),
        "{:?}",
        once.diagnosis.notes
    );
}

/// A lidar turned 2° in the log, in the world built from its own scans at its truth's poses:
/// the map is built from the scans turned back by the yaw at which they agree best, a note says
/// so, and the turn shows against it: a mount offset the same way, within 0.7°. In this 4 × 3 m
/// room the beams' lever arm is 1–3 m, where half a degree moves a wall 1–3 cm, within the
/// XV-11's own noise and range bias there, so its scans agree best within about that (a
/// building's log, its walls 5–20 m away, fixes the yaw to a few hundredths: docs/real-logs.md).
#[test]
fn a_turned_lidar_is_named_against_the_crispest_map_of_its_own_scans() {
    let (_, recording) = log();
    let concealed = Concealment::MountYaw { yaw_deg: 2.0 };
    let run = conceal_and_diagnose(
        &recording,
        &BuiltWorld::default(),
        &[concealed],
        &trying(Sensor::Lidar),
        "t",
    )
    .expect("a diagnosis");
    let d = &run.diagnosis;
    assert!(
        d.notes.iter().any(|n| n.contains("the crispest map")),
        "{:?}",
        d.notes
    );
    let mount = d
        .effects
        .iter()
        .find(|e| e.fit.effect == Effect::LidarMountOffset)
        .unwrap_or_else(|| panic!("no mount named: {}", d.explanation));
    let yaw_deg = mount.fit.params[0];
    assert!((yaw_deg - 2.0).abs() < 0.7, "named {yaw_deg}° for 2°");
}

/// `recording`'s truth thinned to a pose every `step_s` seconds, as a logger stores one with
/// each scan.
fn keep_a_pose_every(recording: &mut Recording, step_s: f64) {
    let truth = recording.truth.as_mut().expect("the run's truth");
    let mut next_s = 0.0;
    truth.retain(|s| {
        let keep = s.t_s >= next_s;
        if keep {
            next_s = s.t_s + step_s;
        }
        keep
    });
}

/// `d` names `concealed`'s entry with its size within the self-test's 20 %.
fn assert_named_within_a_fifth(d: &Diagnosis, concealed: Concealment) {
    let effect = concealed.effect();
    let named = d
        .effects
        .iter()
        .find(|e| e.fit.effect == effect)
        .unwrap_or_else(|| panic!("{effect} not named: {}", d.explanation));
    let got = effect.scored(&named.fit.params);
    let error = (got - concealed.scored()).abs() / concealed.scored().abs();
    assert!(
        error < 0.2,
        "{effect}: {got} against {}",
        concealed.scored()
    );
}

/// A truth with a pose only every half second, as a logger stores one with each scan: the
/// path between its poses is filled by the encoders and the encoders are judged over its
/// spans. The faithful run names nothing in them; wheels 5 % large on the left are named with
/// their size within the self-test's 20 % (the run is 17 s: its 33 spans show 3 % at about
/// 6 nats, short of the 10 a name takes).
#[test]
fn against_a_sparse_truth_the_encoders_are_judged_over_its_spans() {
    let (room, mut recording) = log();
    keep_a_pose_every(&mut recording, 0.5);
    let world = GivenWorld(room);
    let concealed = Concealment::WheelRadius {
        left_scale: 1.05,
        right_scale: 1.0,
    };
    let options = trying(Sensor::Odometer);
    let faithful = conceal_and_diagnose(&recording, &world, &[], &options, "t")
        .expect("a diagnosis")
        .diagnosis;
    assert!(faithful.effects.is_empty(), "{}", faithful.explanation);
    assert!(
        faithful
            .notes
            .iter()
            .any(|n| n.contains("sparser than the encoders")),
        "{:?}",
        faithful.notes
    );
    let d = conceal_and_diagnose(&recording, &world, &[concealed], &options, "t")
        .expect("a diagnosis")
        .diagnosis;
    assert_named_within_a_fifth(&d, concealed);
}

#[test]
fn a_trials_draws_are_its_own_and_only_what_the_log_allows() {
    let (_, mut recording) = log();
    let plan = LogPlan {
        trials: 50,
        seed: 3,
        strength: 1.0,
        options: Options::default(),
    };
    let built = BuiltWorld::default();
    let drawn: Vec<Vec<Concealment>> = (0..50)
        .map(|i| concealments(&recording, &built, &plan, i))
        .collect();
    assert_eq!(drawn[17], concealments(&recording, &built, &plan, 17));
    assert!(
        drawn.iter().any(Vec::is_empty),
        "some trials conceal nothing"
    );
    assert!(drawn.iter().any(|c| c.len() == 2), "some conceal two");
    // Without truth the encoders are judged against the lidar: their radii and base are
    // concealed, their slip and delay (only relative to the lidar's) are not, and are listed.
    assert!(drawn
        .iter()
        .flatten()
        .any(|c| c.effect() == Effect::LidarMountOffset));
    recording.truth = None;
    let drawn_in = |world: &dyn LogWorld| -> Vec<Effect> {
        (0..50)
            .flat_map(|i| concealments(&recording, world, &plan, i))
            .map(|c| c.effect())
            .collect()
    };
    let drawn = drawn_in(&built);
    assert!(drawn.contains(&Effect::DriveWheelBase), "{drawn:?}");
    assert!(
        !drawn.contains(&Effect::OdometerWheelSlip)
            && !drawn.contains(&Effect::SensorLatency(Sensor::Odometer)),
        "{drawn:?}"
    );
    // Nor, in a world built from the same scans, a turned lidar: the world and the scans' path
    // turn with it. In a given world it shows.
    assert!(!drawn.contains(&Effect::LidarMountOffset), "{drawn:?}");
    assert!(drawn_in(&GivenWorld(room())).contains(&Effect::LidarMountOffset));
    let listed: Vec<(String, String)> = not_concealed(&recording, 1.0, true);
    let is_listed = |name: &str| listed.iter().any(|(e, _)| e == name);
    assert!(is_listed("odometer_wheel_slip"), "{listed:?}");
    assert!(
        listed
            .iter()
            .any(|(e, why)| e == "lidar_mount_offset" && why.contains("not identifiable")),
        "{listed:?}"
    );
    assert!(!not_concealed(&recording, 1.0, false)
        .iter()
        .any(|(e, _)| e == "lidar_mount_offset"));
}

/// Encoders whose stamps scatter by more than the largest lead drawn (stamped by a logger
/// that delivers them a few tenths of a second off, as a CARMEN log's `ODOM` lines are) have
/// neither their delay nor their slip concealed, and both are listed as not identifiable; at
/// five times the strength the leads drawn reach past the scatter, and both are concealed.
#[test]
fn encoder_leads_within_their_stamps_scatter_are_not_concealed() {
    let (_, mut recording) = log();
    let plan = |strength: f64| LogPlan {
        trials: 60,
        seed: 3,
        strength,
        options: Options::default(),
    };
    let drawn = |recording: &Recording, strength: f64| -> Vec<Effect> {
        (0..60)
            .flat_map(|i| concealments(recording, &BuiltWorld::default(), &plan(strength), i))
            .map(|c| c.effect())
            .collect()
    };
    let leads = [
        Effect::OdometerWheelSlip,
        Effect::SensorLatency(Sensor::Odometer),
    ];
    assert!(leads.iter().all(|e| drawn(&recording, 1.0).contains(e)));
    // Read at 10 Hz, each reading stamped off by a fixed pattern of up to ±0.25 s, and kept in
    // the order of its stamps.
    let odometry = recording.odometry.as_mut().expect("encoders");
    let mut logged: Vec<_> = odometry
        .iter()
        .step_by(5)
        .enumerate()
        .map(|(k, s)| OdometrySample {
            t_s: s.t_s + [0.0, 0.25, -0.2, 0.1, -0.15, 0.2, -0.25][k % 7],
            ..*s
        })
        .collect();
    logged.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    *odometry = logged;
    let listed: Vec<(String, String)> = not_concealed(&recording, 1.0, true);
    for e in leads {
        assert!(!drawn(&recording, 1.0).contains(&e), "{e:?} {listed:?}");
        assert!(
            listed
                .iter()
                .any(|(name, why)| *name == e.label() && why.contains("not identifiable")),
            "{listed:?}"
        );
        assert!(drawn(&recording, 5.0).contains(&e), "{e:?}");
    }
}

/// Six times round a 1.5 m by 1 m loop of the room at 0.3 m/s, with its truth and its
/// commands left out of the recording: a robot's own log, diagnosed along its scans' own
/// matches against the scenario's world.
fn loops() -> (Scenario, Recording) {
    let (loops, mut recording) = loops_with_truth();
    recording.truth = None;
    (loops, recording)
}

/// The loops' run with its truth, its commands left out.
fn loops_with_truth() -> (Scenario, Recording) {
    let side = |m: f64| {
        format!("[[drive]]\nspeed_mps = 0.3\ndistance_m = {m}\n[[drive]]\nturn_deg = 90.0\n")
    };
    let text = format!(
        "name = \"loops\"\nseed = 7\n\n{ROOM_4X3}\n[robot]\nstart = {{ x = 0.8, y = 0.8, yaw_deg = 0.0 }}\n\
         wheel_base_m = 0.23\nturn_rate_deg_s = 60.0\n\n{}\n[sensors.lidar]\n\
         noise = [0.003, 0.0, 0.002]\n[sensors.odometer]\nnoise_m = 0.002\n",
        [side(1.5), side(1.0)].concat().repeat(12)
    );
    let loops = Scenario::from_toml(&text, Path::new("loops.toml")).expect("the test's scenario");
    let mut recording = Emulation::new(&loops, 7)
        .expect("the emulation")
        .run()
        .recording;
    recording.commands.clear();
    (loops, recording)
}

/// Against a truth of a pose every half second (a logger's, stored with its scans), encoders read at
/// 10 Hz whose stamps scatter by up to ±0.1 s about when they counted (a fixed pattern, kept in
/// their stamps' order, as a CARMEN log's are) are judged span by span between the truth's
/// poses: stamped 60 ms late, their delay is named within the self-test's 20 % of what the log
/// without it reads. Judged reading by reading, within that scatter it is not named.
#[test]
fn against_a_sparse_truth_a_late_encoder_is_read_through_its_stamps_scatter() {
    let (loops, mut recording) = loops_with_truth();
    keep_a_pose_every(&mut recording, 0.5);
    let odometry = recording.odometry.as_mut().expect("encoders");
    let step = (0.1 / (odometry[1].t_s - odometry[0].t_s)).round().max(1.0) as usize;
    let mut logged: Vec<_> = odometry
        .iter()
        .step_by(step)
        .enumerate()
        .map(|(k, s)| OdometrySample {
            t_s: s.t_s + [0.0, 0.1, -0.06, 0.04, -0.1, 0.08, -0.02][k % 7],
            ..*s
        })
        .collect();
    logged.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    *odometry = logged;
    let world = GivenWorld(loops);
    let late = Concealment::Restamp {
        sensor: Sensor::Odometer,
        delay_s: 0.06,
    };
    let options = Options {
        effects: vec![
            late.effect(),
            Effect::OdometerWheelSlip,
            Effect::OdometerWheelRadius,
            Effect::DriveWheelBase,
        ],
        ..Options::default()
    };
    // The encoders' lead on the truth: a slip's gain less their delay.
    let lead = |d: &Diagnosis| -> f64 {
        let read = |effect: Effect| {
            d.candidates
                .iter()
                .find(|c| c.effect == effect)
                .map_or(0.0, |c| c.params[0])
        };
        read(Effect::OdometerWheelSlip) - read(late.effect())
    };
    let untouched = conceal_and_diagnose(&recording, &world, &[], &options, "untouched")
        .expect("a diagnosis")
        .diagnosis;
    let d = conceal_and_diagnose(&recording, &world, &[late], &options, "t")
        .expect("a diagnosis")
        .diagnosis;
    assert!(
        d.effects.iter().any(|e| e.fit.effect == late.effect()),
        "not named: {}",
        d.explanation
    );
    let delay = lead(&untouched) - lead(&d);
    assert!(
        (delay - 0.06).abs() < 0.2 * 0.06,
        "{delay} s: {}",
        d.explanation
    );
}

/// A run without truth and without commands is diagnosed along its scans' own matches: a
/// lidar turned 3° on its mount moves that path sideways, and is named from it within the
/// self-test's 20 %. The sideways motion is read over the path's travel (30 m here), in steps
/// of 15 cm.
#[test]
fn without_truth_or_commands_a_turned_lidar_is_named_from_the_path_moving_sideways() {
    let (loops, recording) = loops();
    let concealed = Concealment::MountYaw { yaw_deg: 3.0 };
    let d = conceal_and_diagnose(
        &recording,
        &GivenWorld(loops),
        &[concealed],
        &trying(Sensor::Lidar),
        "t",
    )
    .expect("a diagnosis")
    .diagnosis;
    assert_eq!(
        d.sensors
            .iter()
            .find(|s| s.sensor == Sensor::Odometer)
            .map(|s| s.reference),
        Some("lidar-estimated path (each scan's own match, straight between scans)")
    );
    assert_named_within_a_fifth(&d, concealed);
}

/// Along the scans' own matches the encoders are judged span by span: a lidar stamped 60 ms
/// late turns 60 ms after the encoders do, and wheels 6 % farther apart count 6 % more travel
/// apart for each turn. Both are named, each within the self-test's 20 % of what the log
/// without them reads (the simulator's encoders already read a little ahead of its lidar, short
/// of the 10 nats that name it, and the declared base is a little narrow). The loops' 48 turns of 90°
/// start and stop at 60°/s, which is where a delay shows.
#[test]
fn without_truth_or_commands_a_late_lidar_and_the_wheel_base_are_read_from_the_paths_spans() {
    let (loops, recording) = loops();
    let world = GivenWorld(loops);
    let options = Options {
        effects: vec![
            Effect::SensorLatency(Sensor::Lidar),
            Effect::DriveWheelBase,
            Effect::OdometerWheelRadius,
        ],
        ..Options::default()
    };
    let read = |d: &Diagnosis, effect: Effect| -> f64 {
        d.candidates
            .iter()
            .find(|c| c.effect == effect)
            .map(|c| c.params[0])
            .unwrap_or_else(|| panic!("{effect} not fitted: {}", d.explanation))
    };
    let untouched = conceal_and_diagnose(&recording, &world, &[], &options, "untouched")
        .expect("a diagnosis")
        .diagnosis;
    assert!(untouched.effects.is_empty(), "{}", untouched.explanation);
    let late = Concealment::Restamp {
        sensor: Sensor::Lidar,
        delay_s: 0.06,
    };
    let wide = Concealment::WheelBase { scale: 1.06 };
    let d = conceal_and_diagnose(&recording, &world, &[late, wide], &options, "t")
        .expect("a diagnosis")
        .diagnosis;
    for effect in [late.effect(), wide.effect()] {
        assert!(
            d.effects.iter().any(|e| e.fit.effect == effect),
            "{effect} not named: {}",
            d.explanation
        );
    }
    let delay = read(&d, late.effect()) - read(&untouched, late.effect());
    assert!(
        (delay - 0.06).abs() < 0.2 * 0.06,
        "{delay} s: {}",
        d.explanation
    );
    let base = read(&d, wide.effect()) / read(&untouched, wide.effect());
    assert!(
        (base - 1.06).abs() < 0.2 * 0.06,
        "{base}: {}",
        d.explanation
    );
    assert!(
        d.effects
            .iter()
            .all(|e| e.fit.effect != Effect::OdometerWheelRadius),
        "{}",
        d.explanation
    );
}
