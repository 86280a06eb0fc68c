//! Mechanisms concealed in a real log: each one a rewrite of the recorded data that adds one
//! known piece of physics to whatever the log already holds (people walking through, glass, a
//! map that is only approximately right, encoders with backlash).
//!
//! Only what can be concealed *exactly* in a log is: a sensor's stamps (a late driver), the
//! encoders' travel (the wheels' radii and base, slip driven by the log's own changes of speed),
//! the lidar's ranges (a warm-up drift, which needs only each reading's range and time; returns
//! lost by range) and its beams' angles (a turned mount). [`NOT_CONCEALED`] lists the rest and why.

use hilsim_recording::{LidarSample, OdometrySample, Recording};

use super::draw::Draws;
use crate::{DrawSource, Effect, Sensor};

/// One mechanism concealed in a log, with its true values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Concealment {
    /// The sensor's samples stamped `delay_s` after they were taken, as a driver that stamps on
    /// arrival does.
    Restamp {
        /// The lidar or the odometer.
        sensor: Sensor,
        /// Seconds.
        delay_s: f64,
    },
    /// Each wheel's real radius over its nominal one: the encoders count turns, so they report
    /// the true travel divided by it.
    WheelRadius { left_scale: f64, right_scale: f64 },
    /// The real wheel base over the nominal one: a turn of the robot moves the wheels apart by
    /// that much more, and the encoders report it.
    WheelBase { scale: f64 },
    /// The wheels slip in proportion to their acceleration (the traction force needs a slip:
    /// Wong, *Theory of Ground Vehicles*, ch. 1): each change of a wheel's speed `Δv` adds
    /// `g Δv` to what its encoder reports beyond the travel, `g` the driving gain while the
    /// speed's magnitude grows and the braking gain while it falls.
    WheelSlip {
        driving_gain_s: f64,
        braking_gain_s: f64,
    },
    /// The lidar reads `(c + k d²) e^{−t/τ}` long, `t` from the log's start (its power-on).
    LidarWarmup {
        offset_m: f64,
        coefficient_per_m: f64,
        time_constant_s: f64,
    },
    /// The lidar turned on its mount by `yaw_deg` (counter-clockwise, seen from above): a wall
    /// the robot sees at bearing φ is read at the unit's angle φ − yaw.
    MountYaw { yaw_deg: f64 },
    /// Returns lost by range: each reading at range `d` is lost (flagged invalid, range 0, as a
    /// unit reports a return too weak to range) with chance `1 / (1 + (R/d)^k)`, half at `R`,
    /// drawn from a stream seeded by `seed`. By range alone, as a vendor's datasheet gives a
    /// unit's loss: the catalogue's logistic in the returned power head-on, without its fall
    /// with incidence and reflectivity.
    LidarLoss {
        half_loss_range_m: f64,
        steepness: f64,
        seed: u64,
    },
}

/// The catalogue's mechanisms that are not concealed in a real log, and why: each would need
/// the world's true geometry or a sensor the log does not have.
pub const NOT_CONCEALED: [(&str, &str); 6] = [
    (
        "lidar_incidence_angle",
        "the surface's angle to each beam comes from a map built from the same scans",
    ),
    (
        "lidar_reflectivity",
        "a log has no surface's reflectivity to scale the ranges by",
    ),
    (
        "lidar_mixed_pixels",
        "a blend of two surfaces needs the range behind each edge, which a log never saw",
    ),
    (
        "lidar_motion_skew",
        "a revolution's skew needs each beam's time within it, which the logs do not stamp",
    ),
    (
        "drive_motor_lag",
        "it shows only against commands, and the real logs have none to rewrite",
    ),
    ("sonar_*", "the real logs have no sonar"),
];

impl Concealment {
    /// The catalogue's entry it is.
    #[must_use]
    pub fn effect(&self) -> Effect {
        match *self {
            Self::Restamp { sensor, .. } => Effect::SensorLatency(sensor),
            Self::WheelRadius { .. } => Effect::OdometerWheelRadius,
            Self::WheelBase { .. } => Effect::DriveWheelBase,
            Self::WheelSlip { .. } => Effect::OdometerWheelSlip,
            Self::LidarWarmup { .. } => Effect::LidarWarmupDrift,
            Self::MountYaw { .. } => Effect::LidarMountOffset,
            Self::LidarLoss { .. } => Effect::LidarDropout,
        }
    }

    /// Its values in the catalogue's parameters, in [`Effect::params`]' order.
    #[must_use]
    pub fn catalogue_params(&self) -> Vec<f64> {
        match *self {
            Self::Restamp { delay_s, .. } => vec![delay_s],
            Self::WheelRadius {
                left_scale,
                right_scale,
            } => vec![left_scale, right_scale],
            Self::WheelBase { scale } => vec![scale],
            Self::WheelSlip {
                driving_gain_s,
                braking_gain_s,
            } => vec![driving_gain_s, braking_gain_s / driving_gain_s],
            Self::LidarWarmup {
                offset_m,
                coefficient_per_m,
                time_constant_s,
            } => vec![coefficient_per_m, time_constant_s, offset_m],
            Self::MountYaw { yaw_deg } => vec![yaw_deg, 0.0, 0.0],
            // The catalogue's logistic in log power with spread s is `1 / (1 + (R/d)^(2/s))`
            // (power falls as d⁻²), at any incidence with its incidence power 0.
            Self::LidarLoss {
                half_loss_range_m,
                steepness,
                ..
            } => vec![half_loss_range_m, 2.0 / steepness, 0.0],
        }
    }

    /// The scored parameter's true value ([`Effect::scored`]).
    #[must_use]
    pub fn scored(&self) -> f64 {
        self.effect().scored(&self.catalogue_params())
    }

    /// Its values by the catalogue's names, for the report.
    #[must_use]
    pub fn named_params(&self) -> Vec<(String, f64)> {
        self.effect()
            .params()
            .iter()
            .zip(self.catalogue_params())
            .map(|(spec, v)| (spec.name.to_string(), v))
            .collect()
    }

    /// Rewrites `recording` with it.
    pub fn apply(&self, recording: &mut Recording) {
        match *self {
            Self::Restamp { sensor, delay_s } => match sensor {
                Sensor::Lidar => crate::own_world::restamp_lidar(recording, delay_s),
                _ => {
                    for s in recording.odometry.iter_mut().flatten() {
                        s.t_s += delay_s;
                    }
                }
            },
            Self::WheelRadius {
                left_scale,
                right_scale,
            } => rewrite_travel(recording, |_, travel| {
                [travel[0] / left_scale, travel[1] / right_scale]
            }),
            Self::WheelBase { scale } => rewrite_travel(recording, |_, [left, right]| {
                let centre = 0.5 * (left + right);
                let apart = 0.5 * scale * (right - left);
                [centre - apart, centre + apart]
            }),
            Self::WheelSlip {
                driving_gain_s,
                braking_gain_s,
            } => {
                let Some(odometry) = recording.odometry.as_mut() else {
                    return;
                };
                let leads = slip_leads(odometry, driving_gain_s, braking_gain_s);
                for (s, lead) in odometry.iter_mut().zip(leads) {
                    s.left_m += lead[0];
                    s.right_m += lead[1];
                }
            }
            Self::LidarWarmup {
                offset_m,
                coefficient_per_m,
                time_constant_s,
            } => {
                for s in recording.lidar.iter_mut().flatten().filter(|s| reads(s)) {
                    let d = s.range_m;
                    s.range_m += (offset_m + coefficient_per_m * d * d)
                        * (-s.t_s.max(0.0) / time_constant_s).exp();
                }
            }
            Self::MountYaw { yaw_deg } => {
                for s in recording.lidar.iter_mut().flatten() {
                    s.angle_deg = (s.angle_deg - yaw_deg).rem_euclid(360.0);
                }
            }
            Self::LidarLoss {
                half_loss_range_m,
                steepness,
                seed,
            } => {
                let mut stream = Draws::from_seed(seed);
                for s in recording.lidar.iter_mut().flatten().filter(|s| reads(s)) {
                    let lost = 1.0 / (1.0 + (half_loss_range_m / s.range_m).powf(steepness));
                    if stream.unit() < lost {
                        s.invalid = true;
                        s.range_m = 0.0;
                    }
                }
            }
        }
    }
}

/// Whether a lidar sample is a reading (a range the unit returned).
fn reads(s: &LidarSample) -> bool {
    !s.invalid && s.range_m > 0.0 && s.range_m.is_finite()
}

/// Rewrites every odometry sample's cumulative travel `[left, right]` by `f`, which is linear in
/// the travel so that the rewrite of the cumulative travel is the rewrite of every step.
fn rewrite_travel(recording: &mut Recording, f: impl Fn(f64, [f64; 2]) -> [f64; 2]) {
    for s in recording.odometry.iter_mut().flatten() {
        [s.left_m, s.right_m] = f(s.t_s, [s.left_m, s.right_m]);
    }
}

/// How often a wheel's speed is taken for a slip's lead, seconds: a quarter of the span it is
/// measured over ([`crate::stamps::WHEEL_SPEED_SPAN_S`]), so that consecutive speeds share most
/// of their readings. Taken at every reading instead, a logger's bursts and scatter of stamps
/// would add changes of speed the wheels never made, each a lead that braking does not give
/// back as it was gained: a drift with the readings, not a slip.
const SLIP_SPEED_STEP_S: f64 = 0.25;

/// Each odometry sample's slip lead `[left, right]`: the wheel's changes of speed (from its own
/// encoder, [`crate::stamps::wheel_speeds`], every [`SLIP_SPEED_STEP_S`]) summed, each weighted
/// by the driving gain while the speed's magnitude grows and by the braking gain while it falls
/// (a reversal brakes to rest, then drives), and read at the sample's stamp between those
/// times.
fn slip_leads(odometry: &[OdometrySample], driving_s: f64, braking_s: f64) -> Vec<[f64; 2]> {
    let times = crate::stamps::speed_times(odometry, SLIP_SPEED_STEP_S);
    let mut lead = [0.0_f64; 2];
    let mut before = [0.0_f64; 2];
    let leads: Vec<[f64; 2]> = times
        .iter()
        .map(|&t| {
            let v = crate::stamps::wheel_speeds(odometry, t);
            for w in 0..2 {
                let (from, to) = (before[w], v[w]);
                let (braked, driven) = if from * to < 0.0 {
                    (-from, to)
                } else if to.abs() < from.abs() {
                    (to - from, 0.0)
                } else {
                    (0.0, to - from)
                };
                lead[w] += braking_s * braked + driving_s * driven;
                before[w] = to;
            }
            lead
        })
        .collect();
    odometry
        .iter()
        .map(|s| crate::stamps::pair_at(&times, &leads, s.t_s))
        .collect()
}

/// The wheels' mechanisms a log without truth does not show apart from the lidar's, and why.
const NOT_CONCEALED_WITHOUT_TRUTH: [(&str, &str); 2] = [
    (
        "sensor_latency (odometer)",
        "without truth only the lidar's delay relative to the encoders shows, which the \
         diagnosis names the lidar's",
    ),
    (
        "odometer_wheel_slip",
        "without truth a lead of the encoders on the speed's changes is the encoders running \
         early against the lidar, which the diagnosis names the lidar's delay",
    ),
];

fn has_truth(recording: &Recording) -> bool {
    recording.truth.as_ref().is_some_and(|t| !t.is_empty())
}

fn has_encoders(recording: &Recording) -> bool {
    recording.odometry.as_ref().is_some_and(|o| !o.is_empty())
}

/// Why a lidar turned on its mount is not concealed in a log without truth whose world is built
/// from its own scans.
const MOUNT_TURNS_THE_WORLD: &str = "not identifiable from this log: without truth the path is \
     matched from the scans and the world built from them, and a turned lidar turns both with \
     it (give a map or a truth to diagnose the mount)";

/// Whether a lidar turned on its mount turns everything `recording` is judged against: no
/// truth, and a world built from its own scans (`world_from_scans`).
fn mount_turns_the_world(recording: &Recording, world_from_scans: bool) -> bool {
    world_from_scans && !has_truth(recording)
}

/// The mechanisms that can be concealed in `recording` at the draws' `strength`: the lidar's
/// with a lidar (its mount's turn not without truth in a world built from its own scans,
/// `world_from_scans`); the wheels' radii and base with encoders judged against a truth or the
/// lidar (a log without truth is diagnosed along the scans' own matches); their slip and delay
/// only against a truth, and only when the encoders' stamps scatter by less than the largest
/// lead drawn ([`not_concealed`]).
#[must_use]
pub fn concealable(recording: &Recording, strength: f64, world_from_scans: bool) -> Vec<Effect> {
    let mut effects = Vec::new();
    let has_lidar = recording.lidar.as_ref().is_some_and(|l| !l.is_empty());
    if has_lidar {
        effects.extend([
            Effect::LidarWarmupDrift,
            Effect::LidarMountOffset,
            Effect::SensorLatency(Sensor::Lidar),
            Effect::LidarDropout,
        ]);
        if mount_turns_the_world(recording, world_from_scans) {
            effects.retain(|e| *e != Effect::LidarMountOffset);
        }
    }
    if has_encoders(recording) && (has_truth(recording) || has_lidar) {
        effects.extend([Effect::OdometerWheelRadius, Effect::DriveWheelBase]);
    }
    if has_encoders(recording) && has_truth(recording) {
        effects.extend(
            encoder_leads().filter(|e| leads_beyond_stamps(recording, *e, strength).is_none()),
        );
    }
    effects
}

/// The encoders' mechanisms told by a lead on their count over the wheels' changes of speed, in
/// the catalogue's order.
fn encoder_leads() -> impl Iterator<Item = Effect> {
    Effect::ALL
        .into_iter()
        .filter(|e| crate::stamps::is_encoder_lead(*e))
}

/// Why `effect`, a lead of the encoders, is not identifiable from `recording` at the draws'
/// `strength`: its encoders' stamps scatter (`stamps.rs`) by at least the largest lead the
/// self-test draws (the delay's, or the slip's gain), so the diagnosis would not name any it
/// could conceal. `None` when they scatter less, or when a sparse truth's spans read the lead
/// whatever the scatter.
fn leads_beyond_stamps(recording: &Recording, effect: Effect, strength: f64) -> Option<String> {
    // A sparse truth's spans read a lead through the scatter.
    if crate::sparse_truth::reads_encoder_leads(recording) {
        return None;
    }
    let scatter_s = recording
        .odometry
        .as_deref()
        .and_then(crate::stamps::encoder_scatter_s)?;
    let range = effect.params().first()?.self_test;
    let DrawSource::Uniform { hi, .. } = range.source else {
        return None;
    };
    let largest_s = if range.scaled { hi * strength } else { hi };
    (scatter_s >= largest_s).then(|| {
        format!(
            "not identifiable from this log: its encoders' stamps scatter by ±{:.0} ms about \
             their neighbours' at speed, at least the largest lead drawn ({:.0} ms)",
            scatter_s * 1000.0,
            largest_s * 1000.0
        )
    })
}

/// The catalogue's mechanisms not concealed in `recording` at the draws' `strength`, and why:
/// [`NOT_CONCEALED`], a log's wheels' slip and delay without truth, those its encoders' stamps
/// scatter too much to show, and the mount's turn without truth in a world built from its own
/// scans (`world_from_scans`).
#[must_use]
pub fn not_concealed(
    recording: &Recording,
    strength: f64,
    world_from_scans: bool,
) -> Vec<(String, String)> {
    let owned = |(e, why): (&str, &str)| (e.to_string(), why.to_string());
    let mut out: Vec<(String, String)> = NOT_CONCEALED.into_iter().map(owned).collect();
    if mount_turns_the_world(recording, world_from_scans) {
        out.push(owned((
            Effect::LidarMountOffset.name(),
            MOUNT_TURNS_THE_WORLD,
        )));
    }
    if has_encoders(recording) && !has_truth(recording) {
        out.extend(NOT_CONCEALED_WITHOUT_TRUTH.into_iter().map(owned));
    } else if has_encoders(recording) {
        out.extend(encoder_leads().filter_map(|e| {
            leads_beyond_stamps(recording, e, strength).map(|why| (e.label(), why))
        }));
    }
    out
}

/// The lidar's first and last stamps in `recording`, seconds.
fn lidar_span_s(recording: &Recording) -> (f64, f64) {
    let lidar = recording.lidar.as_deref().unwrap_or_default();
    match (lidar.first(), lidar.last()) {
        (Some(a), Some(b)) => (a.t_s, b.t_s),
        _ => (0.0, 0.0),
    }
}

/// `effect` concealed in `recording` at a strength drawn from `d`, scaled by `strength`: the
/// self-test's moderate ranges (`docs/diagnose.md`), each in a form drawn among those the
/// mechanism takes.
pub(crate) fn draw(
    d: &mut Draws,
    effect: Effect,
    strength: f64,
    recording: &Recording,
) -> Concealment {
    let signed = |d: &mut Draws, lo: f64, hi: f64| d.sign() * d.between(lo, hi) * strength;
    match effect {
        Effect::SensorLatency(sensor) => Concealment::Restamp {
            sensor,
            delay_s: d.between(0.02, 0.08) * strength,
        },
        Effect::OdometerWheelRadius => Concealment::WheelRadius {
            left_scale: 1.0 + signed(d, 0.01, 0.03),
            right_scale: 1.0 + signed(d, 0.01, 0.03),
        },
        Effect::DriveWheelBase => Concealment::WheelBase {
            scale: 1.0 + signed(d, 0.03, 0.1),
        },
        Effect::OdometerWheelSlip => {
            let driving_gain_s = d.between(0.03, 0.1) * strength;
            // Braking gives back what speeding up led, or slips only while speeding up, or
            // skids a share of it: the forms a tyre's traction–slip curve takes on its two
            // sides (Wong, ch. 1).
            let share = match d.next() % 3 {
                0 => 1.0,
                1 => 0.0,
                _ => d.between(-1.0, 1.0),
            };
            Concealment::WheelSlip {
                driving_gain_s,
                braking_gain_s: share * driving_gain_s,
            }
        }
        Effect::LidarWarmupDrift => {
            // The range error at 2 m at power-on, all in the constant or all in the quadratic
            // term (a unit's pointing, or its optics' focal length, drifting); the time
            // constant a share of the log's lidar span, so that the drift settles within it
            // whatever the log's length.
            let size_m = signed(d, 0.016, 0.04);
            let (_, end_s) = lidar_span_s(recording);
            let time_constant_s = d.between(0.05, 0.25) * end_s.max(20.0);
            let (offset_m, coefficient_per_m) = if d.next() & 1 == 0 {
                (size_m, 0.0)
            } else {
                (0.0, size_m / 4.0)
            };
            Concealment::LidarWarmup {
                offset_m,
                coefficient_per_m,
                time_constant_s,
            }
        }
        Effect::LidarDropout => {
            // Half lost at a range between the log's median reading and its 90th percentile, so
            // that both sides of it are well read; the loss rising from 12 % to 88 % over a
            // factor of 1.5 to 4 of range (the logistic's ±ln 7.33 = ±1.99 about its middle).
            let (median_m, far_m) = reading_quantiles(recording);
            let half_loss_range_m = median_m * (far_m / median_m).powf(d.unit());
            let factor = d.between(1.5, 4.0);
            Concealment::LidarLoss {
                half_loss_range_m,
                steepness: 2.0 * 7.33_f64.ln() / factor.ln(),
                seed: d.next(),
            }
        }
        _ => Concealment::MountYaw {
            yaw_deg: signed(d, 1.0, 3.0),
        },
    }
}

/// The median and the 90th percentile of the ranges `recording`'s lidar read, metres (a
/// metre each when it read none).
fn reading_quantiles(recording: &Recording) -> (f64, f64) {
    let mut ranges: Vec<f64> = recording
        .lidar
        .iter()
        .flatten()
        .filter(|s| reads(s))
        .map(|s| s.range_m)
        .collect();
    if ranges.is_empty() {
        return (1.0, 1.0);
    }
    ranges.sort_by(f64::total_cmp);
    let at = |q: f64| ranges[((ranges.len() - 1) as f64 * q).round() as usize];
    (at(0.5), at(0.9))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn odometry(travel: &[(f64, f64, f64)]) -> Recording {
        Recording {
            odometry: Some(
                travel
                    .iter()
                    .map(|&(t_s, left_m, right_m)| OdometrySample {
                        t_s,
                        left_m,
                        right_m,
                    })
                    .collect(),
            ),
            ..Recording::default()
        }
    }

    /// Half lost at 5 m: about 1 % of the readings at 2 m, half at 5 m and 99 % at 12 m are
    /// lost (steepness 5), each flagged invalid with range 0; the same seed loses the same.
    #[test]
    fn returns_are_lost_by_range_about_half_at_the_half_loss_range() {
        let at = |range_m: f64| -> Vec<LidarSample> {
            (0..4000)
                .map(|i| LidarSample {
                    t_s: f64::from(i) * 0.001,
                    rev: 0,
                    angle_deg: 0.0,
                    range_m,
                    strength: 0,
                    invalid: false,
                    warning: false,
                    true_range_m: None,
                })
                .collect()
        };
        let loss = Concealment::LidarLoss {
            half_loss_range_m: 5.0,
            steepness: 5.0,
            seed: 3,
        };
        for (range_m, expected) in [(2.0, 0.0102), (5.0, 0.5), (12.0, 0.9875)] {
            let mut r = Recording {
                lidar: Some(at(range_m)),
                ..Recording::default()
            };
            loss.apply(&mut r);
            let lidar = r.lidar.expect("the scans");
            let lost = lidar
                .iter()
                .filter(|s| s.invalid && s.range_m == 0.0)
                .count();
            // 4,000 Bernoulli draws: a share's standard error is at most 0.8 %; 3 % is beyond
            // four of them.
            let share = lost as f64 / 4000.0;
            assert!((share - expected).abs() < 0.03, "{range_m} m: {share}");
            let mut again = Recording {
                lidar: Some(at(range_m)),
                ..Recording::default()
            };
            loss.apply(&mut again);
            assert_eq!(again.lidar, Some(lidar));
        }
    }

    #[test]
    fn a_wider_base_moves_the_wheels_apart_and_keeps_the_centre() {
        let mut r = odometry(&[(0.0, 0.0, 0.0), (1.0, 0.9, 1.1)]);
        Concealment::WheelBase { scale: 1.5 }.apply(&mut r);
        let s = r.odometry.unwrap()[1];
        assert!((s.left_m - 0.85).abs() < 1e-12 && (s.right_m - 1.15).abs() < 1e-12);
    }

    #[test]
    fn a_larger_wheel_is_reported_short() {
        let mut r = odometry(&[(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)]);
        Concealment::WheelRadius {
            left_scale: 1.25,
            right_scale: 0.5,
        }
        .apply(&mut r);
        let s = r.odometry.unwrap()[1];
        assert!((s.left_m - 0.8).abs() < 1e-12 && (s.right_m - 2.0).abs() < 1e-12);
    }

    /// A wheel that speeds up from rest to 0.4 m/s, cruises, brakes to rest: even gains give the
    /// lead back at rest; slipping only while speeding up keeps `g × 0.4 m/s`.
    #[test]
    fn slip_leads_while_moving_and_keeps_what_braking_does_not_give_back() {
        let mut travel = Vec::new();
        let mut x = 0.0;
        for i in 0..=400 {
            let t = f64::from(i) * 0.05;
            let v = if t < 2.0 {
                0.0
            } else if t < 3.0 {
                0.4 * (t - 2.0)
            } else if t < 12.0 {
                0.4
            } else if t < 13.0 {
                0.4 * (13.0 - t)
            } else {
                0.0
            };
            x += v * 0.05;
            travel.push((t, x, x));
        }
        let lead_at = |share: f64, t: f64| {
            let mut r = odometry(&travel);
            let before = r.odometry.clone().unwrap();
            Concealment::WheelSlip {
                driving_gain_s: 0.05,
                braking_gain_s: share * 0.05,
            }
            .apply(&mut r);
            let after = r.odometry.unwrap();
            let i = after.iter().position(|s| s.t_s >= t).unwrap();
            after[i].left_m - before[i].left_m
        };
        // Cruising at 0.4 m/s: the lead is g v, 20 mm, within the speed's measurement.
        assert!((lead_at(1.0, 8.0) - 0.02).abs() < 1e-3);
        // At rest again: given back, or kept whole.
        assert!(lead_at(1.0, 18.0).abs() < 1e-3);
        assert!((lead_at(0.0, 18.0) - 0.02).abs() < 1e-3);
    }

    /// A logger that stamps its samples in bursts as they arrive (every half second, five
    /// samples a millisecond apart, each counted a tenth of a second apart before it): the
    /// wheels' speed, and so an even slip's lead `g v`, is read through the bursts. Measured
    /// within the bursts it was up to 30 m/s.
    #[test]
    fn a_slip_is_led_by_the_speed_through_a_loggers_bursts_of_stamps() {
        let speed_mps = 0.3;
        let travel: Vec<(f64, f64, f64)> = (0..200)
            .map(|k| {
                let counted_s = 0.1 * f64::from(k);
                let burst_s = 0.5 * (counted_s / 0.5).floor() + 0.5;
                let stamp_s = burst_s + 0.001 * f64::from(k % 5);
                let x = speed_mps * counted_s;
                (stamp_s, x, x)
            })
            .collect();
        let mut r = odometry(&travel);
        let before = r.odometry.clone().unwrap();
        Concealment::WheelSlip {
            driving_gain_s: 0.05,
            braking_gain_s: 0.05,
        }
        .apply(&mut r);
        let after = r.odometry.unwrap();
        // Cruising (away from the log's ends, where the speed is measured one-sided): g v is
        // 15 mm; within 10 % (the bursts' half second of stamps' error over the span).
        for (a, b) in after.iter().zip(&before).skip(20).take(160) {
            let lead = a.left_m - b.left_m;
            assert!((lead - 0.05 * speed_mps).abs() < 0.0015, "{} {lead}", a.t_s);
        }
    }

    #[test]
    fn a_turned_mount_reads_a_wall_at_the_angle_less_the_yaw() {
        let mut r = Recording {
            lidar: Some(vec![LidarSample {
                t_s: 1.0,
                rev: 0,
                angle_deg: 1.0,
                range_m: 2.0,
                strength: 0,
                invalid: false,
                warning: false,
                true_range_m: None,
            }]),
            ..Recording::default()
        };
        Concealment::MountYaw { yaw_deg: 2.5 }.apply(&mut r);
        assert!((r.lidar.unwrap()[0].angle_deg - 358.5).abs() < 1e-12);
    }

    #[test]
    fn the_scored_value_is_the_catalogues() {
        let c = Concealment::LidarWarmup {
            offset_m: 0.0,
            coefficient_per_m: 0.005,
            time_constant_s: 30.0,
        };
        assert!((c.scored() - 0.02).abs() < 1e-12);
        let c = Concealment::WheelSlip {
            driving_gain_s: 0.05,
            braking_gain_s: 0.0,
        };
        assert_eq!(c.catalogue_params(), vec![0.05, 0.0]);
        // A loss by range is the catalogue's on its reference surface at any incidence.
        let c = Concealment::LidarLoss {
            half_loss_range_m: 5.0,
            steepness: 4.0,
            seed: 0,
        };
        let params = c.catalogue_params();
        assert_eq!(params, vec![5.0, 0.5, 0.0]);
        let catalogue = hilsim_sim::scenario::LidarDropout {
            half_loss_range_m: params[0],
            log_power_spread: params[1],
            incidence_power: params[2],
            reference: 0.8,
        };
        for range_m in [2.0, 5.0, 9.0] {
            let by_range = 1.0 / (1.0 + (5.0_f64 / range_m).powf(4.0));
            for cos_incidence in [1.0, 0.3] {
                let catalogue = hilsim_lidar_emulator::effects::dropout_probability(
                    &catalogue,
                    range_m,
                    cos_incidence,
                    0.8,
                );
                assert!(
                    (by_range - catalogue).abs() < 1e-12,
                    "{range_m} at {cos_incidence}: {by_range} {catalogue}"
                );
            }
        }
    }
}
