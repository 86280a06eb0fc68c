//! Each sensor's readings (lidar, sonar, encoders, drive) gathered against the aligned
//! trajectory, with their covariates and their training / held-out split.

use super::data::{Context, Covariate, Queries, SensorData, DRIVE_WINDOW_S, SPLIT_BLOCK_S};
use crate::catalogue::Sensor;
use crate::error::MismatchError;
use crate::physics::{Hypothesis, LidarQuery};
use crate::sparse_truth::{self, counted_at, IntervalNoise, GROSS_SHARE, GROSS_SPAN_M, REGRESSORS};
use crate::trajectory::Trajectory;
use hilsim_recording::{OdometrySample, TruthSample};

/// Margin around a contact of the replayed robot in which the drive is not compared, seconds.
const CONTACT_MARGIN_S: f64 = 0.5;

pub(super) fn split(t: f64) -> bool {
    ((t / SPLIT_BLOCK_S).floor() as i64).rem_euclid(2) == 1
}

/// Forward acceleration magnitude at `t` from the trajectory's speeds 50 ms either side.
fn accel_at(tr: &Trajectory, t: f64) -> f64 {
    let (a, _) = tr.twist_at(t - 0.05);
    let (b, _) = tr.twist_at(t + 0.05);
    ((b - a) / 0.1).abs()
}

/// The motion covariates at `t`.
fn motion(tr: &Trajectory, t: f64) -> [f64; 3] {
    let (v, w) = tr.twist_at(t);
    [v.abs(), accel_at(tr, t), w.abs().to_degrees()]
}

/// The queries of the `chosen` readings among a lidar's `samples`, each with its revolution's
/// start: the timestamp of its reading 0, or extrapolated from its first reading at the
/// nominal reading period of a head turning at `rpm`.
pub(super) fn lidar_queries(
    samples: &[hilsim_recording::LidarSample],
    chosen: &[&hilsim_recording::LidarSample],
    rpm: f64,
) -> Vec<LidarQuery> {
    let period = 60.0 / (rpm * 360.0);
    let mut rev_start = std::collections::HashMap::new();
    for s in samples {
        rev_start
            .entry(s.rev)
            .or_insert(s.t_s - s.angle_deg * period);
    }
    chosen
        .iter()
        .map(|s| LidarQuery {
            t_s: s.t_s,
            rev_start_s: rev_start[&s.rev],
            angle_deg: s.angle_deg,
        })
        .collect()
}

/// The lidar's valid readings.
pub(crate) fn lidar(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let (Some(samples), Some(declared)) = (&ctx.recording.lidar, ctx.physics.declared().lidar)
    else {
        return Ok(None);
    };
    let valid: Vec<_> = samples
        .iter()
        .filter(|s| !s.invalid && s.range_m > 0.0 && s.t_s <= ctx.end_s)
        .collect();
    let queries = lidar_queries(samples, &valid, declared.rpm);
    let nominal = ctx
        .physics
        .lidar(ctx.trajectory, &queries, &Hypothesis::nominal());
    let keep = away_from_limits(declared, &valid, &nominal);
    let pick = |k: &usize| keep[*k];
    let valid: Vec<_> = valid
        .iter()
        .enumerate()
        .filter(|(k, _)| pick(k))
        .map(|(_, s)| *s)
        .collect();
    let queries: Vec<LidarQuery> = queries
        .iter()
        .enumerate()
        .filter(|(k, _)| pick(k))
        .map(|(_, q)| *q)
        .collect();
    let nominal: Vec<_> = nominal
        .into_iter()
        .enumerate()
        .filter(|(k, _)| pick(k))
        .map(|(_, p)| p)
        .collect();
    let mut cov: Vec<(Covariate, Vec<f64>)> = [
        Covariate::Range,
        Covariate::Bearing,
        Covariate::Incidence,
        Covariate::Object,
        Covariate::Edge,
        Covariate::Time,
        Covariate::Speed,
        Covariate::Accel,
        Covariate::TurnRate,
    ]
    .into_iter()
    .map(|c| (c, Vec::with_capacity(valid.len())))
    .collect();
    for (q, p) in queries.iter().zip(&nominal) {
        let m = motion(ctx.trajectory, q.t_s);
        let values = [
            p.true_range_m.unwrap_or(f64::NAN),
            q.angle_deg,
            if p.true_range_m.is_some() {
                p.incidence_deg
            } else {
                f64::NAN
            },
            p.object.map_or(f64::NAN, f64::from),
            f64::from(u8::from(p.near_edge)),
            q.t_s,
            m[0],
            m[1],
            m[2],
        ];
        for ((_, col), v) in cov.iter_mut().zip(values) {
            col.push(v);
        }
    }
    Ok(Some(SensorData {
        sensor: Sensor::Lidar,
        t: valid.iter().map(|s| s.t_s).collect(),
        y: valid.iter().map(|s| s.range_m).collect(),
        heldout: queries.iter().map(|q| split(q.rev_start_s)).collect(),
        covariates: cov,
        queries: Queries::Lidar(queries),
        epsilon: 0.002,
        outlier_density: 0.002 / declared.max_range_m,
        clusters: None,
        world_reach_m: if declared.world_uncertainty_m > 0.0 {
            nominal.iter().map(|p| p.world_reach_m).collect()
        } else {
            Vec::new()
        },
    }))
}

/// Standard deviations from a range limit within which a reading, and six within which a
/// true range, are not compared (see [`away_from_limits`]).
const LIMIT_GUARD_SD: f64 = 3.0;
pub(super) const LIMIT_GUARD_TRUE_SD: f64 = 6.0;

/// Which lidar readings are compared: those whose reading and true range are well inside the
/// range limits. Near a limit the unit's validity rule decides which readings are reported
/// (by the reported value, as the simulation does, or by the true distance; at another
/// maximum than the declared one), and the survivors' mean moves by a good part of the noise
/// (0.1 m at 5 m for a noise of 0.004 d²): structure no catalogued effect is about. The limits
/// are the declared ones, narrowed to the readings' own extremes (a unit whose maximum is
/// shorter than declared shows it). A reading is kept when it lies more than 3σ inside them
/// and its true range more than 6σ (so a reading kept is never one the rule could have
/// dropped, to 1.3e-3 of a side), σ the reading's predicted noise.
fn away_from_limits(
    declared: crate::physics::DeclaredLidar,
    valid: &[&hilsim_recording::LidarSample],
    nominal: &[crate::physics::LidarPrediction],
) -> Vec<bool> {
    let (lo, hi) = valid
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s.range_m), hi.max(s.range_m))
        });
    let min = declared.min_range_m.max(lo);
    let max = declared.max_range_m.min(hi);
    valid
        .iter()
        .zip(nominal)
        .map(|(s, p)| {
            let sd = p
                .components
                .iter()
                .max_by(|a, b| a.weight.total_cmp(&b.weight))
                .map_or(0.0, |g| g.sd_m);
            let inside = |v: f64, k: f64| v >= min + k * sd && v <= max - k * sd;
            inside(s.range_m, LIMIT_GUARD_SD)
                && p.true_range_m
                    .is_none_or(|t| inside(t, LIMIT_GUARD_TRUE_SD))
        })
        .collect()
}

/// The sonar's pings.
pub(crate) fn sonar(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let (Some(samples), Some(_)) = (
        &ctx.recording.sonar,
        ctx.physics.declared().sonar_half_angle_deg,
    ) else {
        return Ok(None);
    };
    let rows: Vec<_> = samples
        .iter()
        .filter(|s| s.range_m.is_finite() && s.t_s <= ctx.end_s)
        .collect();
    let times: Vec<f64> = rows.iter().map(|s| s.t_s).collect();
    let nominal = ctx
        .physics
        .sonar(ctx.trajectory, &times, &Hypothesis::nominal());
    // As the lidar's near its range limit (`away_from_limits`): whether a ping near the
    // farthest echo is reported depends on the unit's rule (its true distance or its reading
    // against the limit), so pings within 3σ of the farthest reading, or whose predicted
    // reading is within 6σ of it, are not compared. The limit is the recording's own farthest
    // reading: the declared one bounds the echo, not the reading (which the bias stretches).
    let farthest = rows
        .iter()
        .map(|s| s.range_m)
        .fold(f64::NEG_INFINITY, f64::max);
    let keep: Vec<bool> = rows
        .iter()
        .zip(&nominal)
        .map(|(s, p)| {
            p.reading.is_none_or(|g| {
                s.range_m <= farthest - LIMIT_GUARD_SD * g.sd_m
                    && g.mean_m <= farthest - LIMIT_GUARD_TRUE_SD * g.sd_m
            })
        })
        .collect();
    let rows: Vec<_> = rows
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(s, _)| *s)
        .collect();
    let nominal: Vec<_> = nominal
        .into_iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(p, _)| p)
        .collect();
    let times: Vec<f64> = rows.iter().map(|s| s.t_s).collect();
    let mut cov: Vec<(Covariate, Vec<f64>)> = [
        Covariate::Range,
        Covariate::OffAxisNearer,
        Covariate::Time,
        Covariate::Speed,
        Covariate::TurnRate,
    ]
    .into_iter()
    .map(|c| (c, Vec::new()))
    .collect();
    for (s, p) in rows.iter().zip(&nominal) {
        let m = motion(ctx.trajectory, s.t_s);
        let axis = p.true_range_m.unwrap_or(f64::INFINITY);
        let nearer = p.wide_cone_m.map_or(0.0, |w| (axis - w).clamp(0.0, 5.0));
        let values = [
            p.true_range_m.unwrap_or(s.range_m),
            nearer,
            s.t_s,
            m[0],
            m[2],
        ];
        for ((_, col), v) in cov.iter_mut().zip(values) {
            col.push(v);
        }
    }
    Ok(Some(SensorData {
        sensor: Sensor::Sonar,
        t: times.clone(),
        y: rows.iter().map(|s| s.range_m).collect(),
        heldout: times.iter().map(|&t| split(t)).collect(),
        covariates: cov,
        queries: Queries::Sonar(times),
        epsilon: 0.002,
        outlier_density: 0.002 / 5.0,
        clusters: None,
        world_reach_m: Vec::new(),
    }))
}

/// The encoders' readings: two rows (left, right) per reading.
pub(crate) fn odometer(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let (Some(samples), true) = (&ctx.recording.odometry, ctx.physics.declared().odometer) else {
        return Ok(None);
    };
    if let Some(truth) = ctx.recording.truth.as_deref() {
        if !ctx.estimated && sparse_truth::is_sparse(truth, samples) {
            return Ok(Some(odometer_over_spans(ctx, truth, samples)));
        }
    }
    let tr = ctx.trajectory;
    // The path's wheel travel counts from its first pose: readings before it are not judged,
    // and the travel the encoders had counted by then (a log whose truth starts late) is taken
    // off the rest.
    let start_s = tr.times()[0];
    let rows: Vec<_> = samples
        .iter()
        .filter(|s| s.t_s >= start_s && s.t_s <= ctx.end_s)
        .collect();
    // Zero when the path starts at or before the encoders' first reading.
    let [left_before, right_before] = if samples[0].t_s < start_s {
        counted_at(samples, start_s)
    } else {
        [0.0; 2]
    };
    let times: Vec<f64> = rows.iter().map(|s| s.t_s).collect();
    let travel = tr.wheel_travel(ctx.physics.declared().wheel_base_m);
    let speed = |t: f64, wheel: usize| {
        let k = tr.interval(t);
        let dt = tr.times().get(k + 1).map_or(1.0, |t1| t1 - tr.times()[k]);
        travel
            .get(k + 1)
            .map_or(0.0, |next| (next[wheel] - travel[k][wheel]) / dt)
    };
    let mut t = Vec::new();
    let mut y = Vec::new();
    let mut cov: Vec<(Covariate, Vec<f64>)> = [
        Covariate::WheelSpeed,
        Covariate::Accel,
        Covariate::Time,
        Covariate::TurnRate,
    ]
    .into_iter()
    .map(|c| (c, Vec::new()))
    .collect();
    for s in &rows {
        for wheel in 0..2 {
            t.push(s.t_s);
            y.push(if wheel == 0 {
                s.left_m - left_before
            } else {
                s.right_m - right_before
            });
            let v = speed(s.t_s, wheel);
            let a = (speed(s.t_s + 0.05, wheel) - speed(s.t_s - 0.05, wheel)) / 0.1;
            let values = [v, a.abs(), s.t_s, motion(tr, s.t_s)[2]];
            for ((_, col), v) in cov.iter_mut().zip(values) {
                col.push(v);
            }
        }
    }
    Ok(Some(SensorData {
        sensor: Sensor::Odometer,
        heldout: t.iter().map(|&t| split(t)).collect(),
        t,
        y,
        covariates: cov,
        queries: Queries::Odometer(times),
        epsilon: 1e-4,
        outlier_density: 1e-4 / 1.0,
        clusters: None,
        world_reach_m: Vec::new(),
    }))
}

/// The encoders' travel over spans of a sparse truth's poses
/// ([`sparse_truth::poses_per_span`]): two rows per span, the wheels' mean travel and their
/// difference ([`Queries::OdometerSpans`]). Their cumulative travel against a path through
/// sparse poses would carry every span's error (a pose stamped late, a curve the filled path
/// cut) into all later readings; over spans each error stays in its own.
fn odometer_over_spans(
    ctx: &Context<'_>,
    truth: &[TruthSample],
    samples: &[OdometrySample],
) -> SensorData {
    let tr = ctx.trajectory;
    let (first_s, last_s) = (samples[0].t_s, samples[samples.len() - 1].t_s);
    let poses: Vec<f64> = truth
        .iter()
        .map(|p| p.t_s)
        .filter(|&t| t >= first_s && t <= last_s.min(ctx.end_s))
        .step_by(sparse_truth::poses_per_span(truth))
        .collect();
    let spans: Vec<(f64, f64)> = poses
        .windows(2)
        .map(|w| (w[0], w[1]))
        .filter(|&(a, b)| b > a)
        .collect();
    let travel = tr.wheel_travel(ctx.physics.declared().wheel_base_m);
    let mut t = Vec::new();
    let mut y = Vec::new();
    let mut cov: Vec<(Covariate, Vec<f64>)> =
        [Covariate::WheelSpeed, Covariate::Time, Covariate::TurnRate]
            .into_iter()
            .map(|c| (c, Vec::new()))
            .collect();
    let mut regressed: [Vec<([f64; REGRESSORS], f64)>; 2] = [Vec::new(), Vec::new()];
    let mean_and_difference = |w: [f64; 2]| [(w[0] + w[1]) / 2.0, w[1] - w[0]];
    // The wheels' mean speed at `t`, over a quarter second either side.
    let speed = |t: f64| {
        let (a, b) = (
            tr.interpolate(&travel, t - 0.25),
            tr.interpolate(&travel, t + 0.25),
        );
        (b[0] - a[0] + b[1] - a[1]) / 2.0 / 0.5
    };
    for &(a, b) in &spans {
        let (counted_a, counted_b) = (counted_at(samples, a), counted_at(samples, b));
        let (path_a, path_b) = (tr.interpolate(&travel, a), tr.interpolate(&travel, b));
        let counted = mean_and_difference([0, 1].map(|w| counted_b[w] - counted_a[w]));
        let path = mean_and_difference([0, 1].map(|w| path_b[w] - path_a[w]));
        let mid = (a + b) / 2.0;
        for row in 0..2 {
            t.push(mid);
            y.push(counted[row]);
            regressed[row].push(([path[0], path[1], speed(b) - speed(a)], counted[row]));
            let values = [path[0] / (b - a), mid, motion(tr, mid)[2]];
            for ((_, col), v) in cov.iter_mut().zip(values) {
                col.push(v);
            }
        }
    }
    let noise = [0, 1].map(|row| {
        IntervalNoise::measure(&regressed[row], row).unwrap_or(IntervalNoise {
            sd_m: ctx.position_sd_m,
            share: 0.0,
        })
    });
    SensorData {
        sensor: Sensor::Odometer,
        heldout: t.iter().map(|&t| split(t)).collect(),
        t,
        y,
        covariates: cov,
        queries: Queries::OdometerSpans { spans, noise },
        epsilon: GROSS_SHARE,
        outlier_density: GROSS_SHARE / GROSS_SPAN_M,
        clusters: None,
        world_reach_m: Vec::new(),
    }
}

/// The drive: the wheels' travel over 0.1 s windows along the aligned trajectory, against the
/// travel the commands give.
pub(crate) fn drive(ctx: &Context<'_>) -> Result<Option<SensorData>, MismatchError> {
    let commands = &ctx.recording.commands;
    if commands.is_empty() {
        return Ok(None);
    }
    let tr = ctx.trajectory;
    let travel = tr.wheel_travel(ctx.physics.declared().wheel_base_m);
    let n = (ctx.end_s / DRIVE_WINDOW_S).floor() as usize;
    let mut windows = Vec::with_capacity(n);
    let (mut t, mut y) = (Vec::new(), Vec::new());
    let mut cov: Vec<(Covariate, Vec<f64>)> = [
        Covariate::WheelSpeed,
        Covariate::SinceCommand,
        Covariate::Time,
        Covariate::TurnRate,
    ]
    .into_iter()
    .map(|c| (c, Vec::new()))
    .collect();
    let half_base = ctx.physics.declared().wheel_base_m / 2.0;
    // Where the robot touches an obstacle its wheels' travel is the contact's doing (and the
    // real run meets it a little earlier or later, or another simulator resolves it otherwise):
    // those windows, with a margin, are not the drive's evidence.
    let contacts = ctx.physics.drive_contacts(commands, ctx.end_s);
    let touching = |a: f64, b: f64| {
        contacts
            .iter()
            .any(|&(from, to)| a < to + CONTACT_MARGIN_S && b > from - CONTACT_MARGIN_S)
    };
    for k in 0..n {
        let (a, b) = (k as f64 * DRIVE_WINDOW_S, (k + 1) as f64 * DRIVE_WINDOW_S);
        if touching(a, b) {
            continue;
        }
        windows.push((a, b));
        let (wa, wb) = (tr.interpolate(&travel, a), tr.interpolate(&travel, b));
        // The command in force at the window's start, and how long it has been.
        let i = commands.partition_point(|c| c.t_s <= a + 1e-9);
        let (cmd, since) = match i.checked_sub(1).map(|j| commands[j]) {
            Some(c) => (c, a - c.t_s),
            None => (
                hilsim_recording::CommandSample {
                    t_s: 0.0,
                    left_mps: 0.0,
                    right_mps: 0.0,
                },
                a,
            ),
        };
        let turn = ((cmd.right_mps - cmd.left_mps) / (2.0 * half_base))
            .abs()
            .to_degrees();
        for wheel in 0..2 {
            t.push(a);
            y.push(wb[wheel] - wa[wheel]);
            let speed = if wheel == 0 {
                cmd.left_mps
            } else {
                cmd.right_mps
            };
            let values = [speed, since, a, turn];
            for ((_, col), v) in cov.iter_mut().zip(values) {
                col.push(v);
            }
        }
    }
    if windows.is_empty() {
        return Ok(None);
    }
    Ok(Some(SensorData {
        sensor: Sensor::Drive,
        heldout: t.iter().map(|&t| split(t)).collect(),
        t,
        y,
        covariates: cov,
        queries: Queries::Drive(windows),
        epsilon: 1e-4,
        outlier_density: 1e-4 / 0.5,
        clusters: None,
        world_reach_m: Vec::new(),
    }))
}
