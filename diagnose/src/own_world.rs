//! A log's world: the user's scenario, or the world built from the log's own scans as
//! `hilsim world` builds it, and a log diagnosed in it ([`diagnosed_in`]). A map built from
//! the scans at a truth's poses is built again under the lidar's named delay, mount and warm-up.
//! `hilsim diagnose --real` without `--sim` and the self-test on a log both judge a log here.

use hilsim_lidar_emulator::effects::{real_mount, warmup_error_m};
use hilsim_recording::Recording;
use hilsim_sim::scenario::Effects;
use hilsim_sim::Scenario;

use hilsim_sim::scenario::LidarMountOffset;

use crate::catalogue::MOUNT_YAW_RESOLUTION_DEG;
use crate::crisp_map::crispest_mount_yaw_deg;
use crate::{Diagnosis, Effect, Options, Sensor, SimPhysics};

/// Where a log's world comes from.
pub trait LogWorld: Sync {
    /// The scenario `recording` (named `label`: `untouched`, `the first half`, `trial I`) is
    /// diagnosed against.
    ///
    /// # Errors
    /// The world cannot be made, in one line.
    fn scenario(&self, recording: &Recording, label: &str) -> Result<Scenario, String>;
    /// How the world is made, for the report.
    fn describe(&self) -> String;
    /// Whether a part of a log is a run in this world: a world built from each recording is
    /// built for its part too; a scenario (a scripted drive, or a twin's path) starts where the
    /// whole log starts, so the log's second half is not a run of it.
    fn takes_parts(&self) -> bool {
        true
    }
    /// Whether the world is built from each recording's own scans. Without truth the path is
    /// then matched from those scans too, and a lidar turned on its mount turns the world and
    /// the path with it: nothing in the log shows the turn.
    fn built_from_scans(&self) -> bool {
        false
    }
    /// `scenario` with its map built again from `recording`'s scans turned by the mount yaw
    /// they agree on best, when that departs from the declared one, and that yaw (degrees
    /// from the declared mount); `None` when the world does not move with the lidar's mount.
    ///
    /// # Errors
    /// The world cannot be made again, in one line.
    fn sharpened(
        &self,
        _recording: &Recording,
        _label: &str,
        _scenario: &Scenario,
    ) -> Option<Result<(Scenario, f64), String>> {
        None
    }
    /// The scenario to judge `recording` against again once `diagnosis` (against `scenario`)
    /// has named what moves where its scans land; `None` when the world does not move with it.
    ///
    /// # Errors
    /// The world cannot be made again, in one line.
    fn rebuilt(
        &self,
        _recording: &Recording,
        _label: &str,
        _scenario: &Scenario,
        _diagnosis: &Diagnosis,
    ) -> Option<Result<Scenario, String>> {
        None
    }
}

/// The user's scenario, the same for every trial.
#[derive(Debug, Clone)]
pub struct GivenWorld(pub Scenario);

impl LogWorld for GivenWorld {
    fn scenario(&self, _: &Recording, _: &str) -> Result<Scenario, String> {
        Ok(self.0.clone())
    }
    fn describe(&self) -> String {
        format!("the world of scenario {}", self.0.name)
    }
    fn takes_parts(&self) -> bool {
        false
    }
}

/// The world built from each recording as `hilsim world` builds it (the map from its scans at
/// its path, the lidar's noise measured against it), in a scratch directory removed afterwards.
#[derive(Debug, Clone, Default)]
pub struct BuiltWorld {
    /// How the world is built.
    pub options: hilsim_twin::WorldOptions,
}

impl LogWorld for BuiltWorld {
    fn scenario(&self, recording: &Recording, label: &str) -> Result<Scenario, String> {
        let scratch = tempfile::Builder::new()
            .prefix("hilsim-self-test-")
            .tempdir()
            .map_err(|e| format!("{label}: a scratch directory: {e}"))?;
        let built = (|| -> Result<Scenario, String> {
            let dir = scratch.path().join("recording");
            recording.write_dir(&dir).map_err(|e| e.to_string())?;
            let world = hilsim_twin::build_world(&dir, &self.options).map_err(|e| e.to_string())?;
            let files = hilsim_twin::TwinFiles::beside(&scratch.path().join("world.toml"), None);
            world
                .write_measured(&files, world.declared(), false)
                .map_err(|e| e.to_string())?;
            Scenario::load(&files.scenario).map_err(|e| e.to_string())
        })();
        built.map_err(|e| format!("{label}: the world: {e}"))
    }
    fn describe(&self) -> String {
        "the world built from each recording's own scans".to_string()
    }
    fn built_from_scans(&self) -> bool {
        true
    }
    /// A map built from scans placed at a truth's poses through a turned lidar is smeared
    /// (each scan turned about the place it was seen from), and judged against it the turn is
    /// partly the map's. The scans are placed at the mount yaw at which they agree best
    /// ([`crispest_mount_yaw_deg`]); when it departs from the declared one by the least yaw
    /// the catalogue names, the map is built from them so placed, while the scenario still
    /// declares the recorded mount, so that the turn shows against it. Without a truth the
    /// path is matched from the scans and turns with them: nothing is done.
    fn sharpened(
        &self,
        recording: &Recording,
        label: &str,
        scenario: &Scenario,
    ) -> Option<Result<(Scenario, f64), String>> {
        let yaw_deg = crispest_mount_yaw_deg(recording, self.options.max_range_m)?;
        if yaw_deg.abs() < MOUNT_YAW_RESOLUTION_DEG {
            return None;
        }
        let turned = Effects {
            lidar_mount_offset: Some(LidarMountOffset {
                yaw_deg,
                x_m: 0.0,
                y_m: 0.0,
            }),
            ..Effects::default()
        };
        let placed = placed_under(recording, &turned)?;
        Some(self.scenario(&placed, label).map(|again| {
            let mut judged = scenario.clone();
            judged.files.map.clone_from(&again.files.map);
            (judged, yaw_deg)
        }))
    }
    /// A map built from scans placed at a truth's poses takes in the lidar's delay and mount:
    /// each scan lands where the robot was at its stamp, seen through the declared mount, so a
    /// late or turned lidar smears every wall the robot passed while turning, and the smear reads
    /// as an error at edges (mixed pixels) and takes part of the delay. A warm-up moves the walls
    /// the early scans alone see, and so takes part of its drift into the map. Named, the scans
    /// are placed under them (re-stamped, seen through the mount named, the drift taken off
    /// their ranges) and the map built again;
    /// the scenario keeps everything else it declared (the timing, the mount, the lidar's noise
    /// measured against the first map), so the delay and mount are judged again against a map
    /// they did not shape. The noise is kept: measured again against the second map it is
    /// smaller, and on a log with a delay and a warm-up concealed together neither was then
    /// named (the warm-up's far readings, metres short at 20 m, judged against the smaller
    /// noise). Without a truth the path is matched from the scans themselves:
    /// the path moves with them, and the map's walls do not come apart.
    fn rebuilt(
        &self,
        recording: &Recording,
        label: &str,
        scenario: &Scenario,
        diagnosis: &Diagnosis,
    ) -> Option<Result<Scenario, String>> {
        // Without a truth the path is matched from the scans (see above).
        recording.truth.as_ref()?;
        let placed = placed_under(recording, &named_placement(diagnosis))?;
        Some(self.scenario(&placed, label).map(|again| {
            let mut judged = scenario.clone();
            judged.files.map.clone_from(&again.files.map);
            judged
        }))
    }
}

/// The lidar's named delay, mount offset and warm-up in `diagnosis`: what moves where its
/// scans land.
fn named_placement(diagnosis: &Diagnosis) -> Effects {
    let mut effects = Effects::default();
    for named in &diagnosis.effects {
        let e = named.fit.effect;
        if matches!(
            e,
            Effect::SensorLatency(Sensor::Lidar)
                | Effect::LidarMountOffset
                | Effect::LidarWarmupDrift
        ) {
            e.apply(&named.fit.params, &mut effects);
        }
    }
    effects
}

/// What `placement` moves, in words: "the lidar's delay of 32 ms and its mount turned
/// +2.48°, moved x +0.066 m, y -0.049 m" (and "its warm-up's drift taken off its ranges").
fn placement_text(placement: &Effects) -> String {
    let delay = placement
        .sensor_latency
        .filter(|l| l.lidar_s != 0.0)
        .map(|l| format!("delay of {:.0} ms", 1000.0 * l.lidar_s));
    let mount = placement.lidar_mount_offset.map(|m| {
        format!(
            "mount turned {:+.2}°, moved x {:+.3} m, y {:+.3} m",
            m.yaw_deg, m.x_m, m.y_m
        )
    });
    let warmup = placement
        .lidar_warmup_drift
        .map(|_| "warm-up's drift taken off its ranges".to_string());
    let named: Vec<String> = delay.into_iter().chain(mount).chain(warmup).collect();
    format!("the lidar's {}", named.join(" and its "))
}

/// Every lidar reading of `recording` stamped `delay_s` later (earlier when negative).
pub(crate) fn restamp_lidar(recording: &mut Recording, delay_s: f64) {
    for s in recording.lidar.iter_mut().flatten() {
        s.t_s += delay_s;
    }
}

/// `recording` with its scans re-stamped by the lidar's delay in `placement`, its mount moved
/// by its mount offset and its warm-up's drift taken off each valid range (at the range read
/// and the reading's stamp, as recorded); `None` when `placement` does none of these.
fn placed_under(recording: &Recording, placement: &Effects) -> Option<Recording> {
    let delay_s = placement.sensor_latency.map_or(0.0, |l| l.lidar_s);
    if delay_s == 0.0
        && placement.lidar_mount_offset.is_none()
        && placement.lidar_warmup_drift.is_none()
    {
        return None;
    }
    let mut placed = recording.clone();
    if let Some(drift) = &placement.lidar_warmup_drift {
        for s in placed.lidar.iter_mut().flatten() {
            if !s.invalid && s.range_m > 0.0 {
                s.range_m = (s.range_m - warmup_error_m(drift, s.range_m, s.t_s)).max(0.0);
            }
        }
    }
    restamp_lidar(&mut placed, -delay_s);
    placed.meta.lidar = Some(real_mount(
        placed.meta.lidar.unwrap_or_default(),
        placement.lidar_mount_offset,
    ));
    Some(placed)
}

/// `recording` (named `label`) judged by `judged` against `world`'s scenario for it, or
/// against that scenario with its map built from the scans turned by the mount yaw at which
/// they agree best ([`LogWorld::sharpened`]) when judged against it the lidar shows a turn the
/// same way: the scenario, its judgement, whether its map is of the turned scans, and the note
/// saying what was found (which the judgement holds too). A map of turned scans in which the lidar shows no such turn (a short run's few
/// points, a range error that smears walls as a turn does) is not kept, and a note says so.
fn judged_in_the_crispest_map(
    world: &dyn LogWorld,
    recording: &Recording,
    label: &str,
    judged: &dyn Fn(&Scenario) -> Result<Diagnosis, String>,
) -> Result<(Scenario, Diagnosis, bool, Option<String>), String> {
    let scenario = world.scenario(recording, label)?;
    let Some(crisper) = world.sharpened(recording, label, &scenario) else {
        let first = judged(&scenario)?;
        return Ok((scenario, first, false, None));
    };
    let (crisper, yaw_deg) = crisper?;
    let mut turned = judged(&crisper)?;
    let shows_the_turn = named_placement(&turned)
        .lidar_mount_offset
        .is_some_and(|m| m.yaw_deg * yaw_deg > 0.0);
    if shows_the_turn {
        let note = format!(
            "the map was built from the scans turned {yaw_deg:+.2}° from the declared mount, \
             where placed at the truth's poses they agree best (the crispest map); the lidar is \
             judged against it as declared"
        );
        turned.notes.push(note.clone());
        return Ok((crisper, turned, true, Some(note)));
    }
    let mut first = judged(&scenario)?;
    let note = format!(
        "the scans placed at the truth's poses agree best turned {yaw_deg:+.2}° from the \
         declared mount, but judged against the map built from them so turned the lidar showed \
         no such turn: it is judged against the map built from the scans as recorded"
    );
    first.notes.push(note.clone());
    Ok((scenario, first, false, Some(note)))
}

/// `recording` (named `label` in an error) diagnosed against `world`'s scenario for it, and
/// again against the world rebuilt under what the first diagnosis named, when it moves the
/// world ([`LogWorld::rebuilt`]): the scenario judged against last, and its diagnosis.
///
/// # Errors
/// The world cannot be made or the diagnosis refuses the recording, in one line.
pub fn diagnosed_in(
    world: &dyn LogWorld,
    recording: &Recording,
    label: &str,
    options: &Options,
) -> Result<(Scenario, Diagnosis), String> {
    let judged = |scenario: &Scenario| -> Result<Diagnosis, String> {
        let physics = SimPhysics::new(scenario).map_err(|e| format!("{label}: {e:#}"))?;
        crate::diagnose(&physics, recording, options).map_err(|e| format!("{label}: {e}"))
    };
    let (scenario, first, turned, crisp_note) =
        judged_in_the_crispest_map(world, recording, label, &judged)?;
    let Some(rebuilt) = world.rebuilt(recording, label, &scenario, &first) else {
        return Ok((scenario, first));
    };
    let rebuilt = rebuilt?;
    let mut again = judged(&rebuilt)?;
    let built_first = if turned {
        "turned as above"
    } else {
        "as recorded"
    };
    again.notes.extend(crisp_note);
    let placement = placement_text(&named_placement(&first));
    // The second map is right only if judged against it the lidar still shows what it was
    // built under: a judgement that no longer names the delay or the mount it placed the scans
    // by has not settled, and the first stands.
    let named_in_the_lidar = |d: &Diagnosis| {
        let placed = named_placement(d);
        (
            placed.sensor_latency.is_some(),
            placed.lidar_mount_offset.is_some(),
            placed.lidar_warmup_drift.is_some(),
        )
    };
    if named_in_the_lidar(&again) != named_in_the_lidar(&first) {
        let mut first = first;
        first.notes.push(format!(
            "the map was built again from the scans placed under {placement}, as this judgement \
             names them, but judged against that map the lidar no longer showed them: this \
             judgement, against the map built from the scans as recorded, stands"
        ));
        return Ok((scenario, first));
    }
    again.notes.push(format!(
        "the map was built from the scans {built_first}, then again with each scan placed \
         under {placement}, as the first judgement named them: a late or turned lidar smears \
         a map built from its own scans at a truth's poses; the recording is judged against \
         the second map"
    ));
    Ok((rebuilt, again))
}

#[cfg(test)]
mod tests {
    use super::*;
    use hilsim_recording::{LidarSample, Mount};
    use hilsim_sim::scenario::{LidarMountOffset, SensorLatency};

    fn placement(lidar_s: f64, mount: Option<LidarMountOffset>) -> Effects {
        Effects {
            sensor_latency: Some(SensorLatency {
                lidar_s,
                ..SensorLatency::default()
            }),
            lidar_mount_offset: mount,
            ..Effects::default()
        }
    }

    /// Placed under a delay, every scan is stamped that much earlier; under a mount offset,
    /// the meta's mount is the declared one moved by it; under neither, nothing is rebuilt.
    #[test]
    fn scans_are_placed_under_the_named_delay_and_mount() {
        let mut recording = Recording::default();
        recording.meta.lidar = Some(Mount {
            x_m: 0.1,
            ..Mount::default()
        });
        recording.lidar = Some(vec![LidarSample {
            t_s: 2.0,
            rev: 0,
            angle_deg: 10.0,
            range_m: 1.5,
            strength: 0,
            invalid: false,
            warning: false,
            true_range_m: None,
        }]);
        assert!(placed_under(&recording, &placement(0.0, None)).is_none());
        let offset = LidarMountOffset {
            x_m: 0.02,
            y_m: -0.01,
            yaw_deg: 2.5,
        };
        let placed = placed_under(&recording, &placement(0.05, Some(offset))).expect("moved");
        let lidar = placed.lidar.expect("its scans");
        assert!((lidar[0].t_s - 1.95).abs() < 1e-12, "{}", lidar[0].t_s);
        let mount = placed.meta.lidar.expect("its mount");
        assert!((mount.x_m - 0.12).abs() < 1e-12 && (mount.y_m + 0.01).abs() < 1e-12);
        assert!((mount.yaw_deg - 2.5).abs() < 1e-12);
        assert_eq!(
            placement_text(&placement(0.032, Some(offset))),
            "the lidar's delay of 32 ms and its mount turned +2.50°, moved x +0.020 m, y -0.010 m"
        );
        assert_eq!(
            placement_text(&placement(0.0, Some(offset))),
            "the lidar's mount turned +2.50°, moved x +0.020 m, y -0.010 m"
        );
    }
}
