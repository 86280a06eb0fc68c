//! EM's M-step against its E-step's likelihood, and the parameters' flat form.

use nalgebra::Vector2;

use super::model::{
    Data, EmModel, Free, Lin, Params, SensorParams, StepData, LIDAR, ODOMETER, SONAR,
};
use super::mstep;
use super::prior::Priors;
use crate::kalman_smoother::RtsSmoother;

/// A deterministic standard normal sequence (Box–Muller on a 64-bit LCG), so that the
/// unit tests need no random-number crate features.
fn normals(n: usize) -> Vec<f64> {
    let mut state: u64 = 0x853c_49e6_748f_ea9b;
    let mut uniform = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let (u1, u2) = (uniform(), uniform());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        })
        .collect()
}

/// The paper's model with every noise variance frozen at a linearisation point is linear
/// and Gaussian, and EM on it must never lower its likelihood: this checks the M-step's
/// closed forms (with the paper's weights) against the E-step's likelihood to rounding.
#[test]
fn the_paper_m_step_is_exact_em_for_the_frozen_model() {
    let n = 150;
    let e = normals(3 * n);
    let u = 0.02;
    let mut params = Params {
        sensors: [
            SensorParams::paper(LIDAR),
            SensorParams::paper(ODOMETER),
            SensorParams::paper(SONAR),
        ],
        q_rel: 0.01,
        speed_scale: 1.0,
    };
    params.sensors[LIDAR].active = true;
    params.sensors[ODOMETER].active = true;
    let steps = (0..n)
        .map(|k| {
            // The true distance wanders off the commanded one by ~1 cm.
            let d = 0.5 + u * k as f64 + 0.01 * (k as f64 / 20.0).sin();
            let lidar = 0.05 + 0.88 * d + 0.06 * d * d + 0.004 * d * d * e[k];
            let odometer = -0.01 + 1.02 * d + 0.003 * e[n + k];
            StepData {
                y: [lidar, odometer, 0.0],
                // Every fifth lidar reading missing.
                has: [k % 5 != 3, true, false],
                u,
            }
        })
        .collect();
    let data = Data {
        steps,
        prior_mean: 0.5,
        prior_u: 0.0,
        prior_var: 0.0,
    };
    let lin: Vec<Lin> = (0..n).map(|k| Lin::exact(0.5 + u * k as f64)).collect();
    let dr: Vec<Vector2<f64>> = lin.iter().map(|l| Vector2::new(l.m, l.d2)).collect();
    let zeros = vec![nalgebra::Matrix2::zeros(); n];
    let init = mstep::Posterior {
        means: &dr,
        covs: &zeros,
        lag_one: &zeros,
    };
    params = mstep::m_step(
        &data,
        &params,
        &init,
        &lin,
        false,
        Free::default(),
        &Priors::default(),
    )
    .unwrap();
    let mut smoother = RtsSmoother::<2>::new();
    fn model<'a>(data: &'a Data, params: &'a Params, lin: &'a [Lin]) -> EmModel<'a> {
        EmModel {
            data,
            params,
            lin,
            second_order: false,
        }
    }
    let mut ll = smoother.run(&model(&data, &params, &lin)).unwrap();
    let first = ll;
    for iteration in 0..30 {
        let post = mstep::Posterior {
            means: smoother.smoothed_means(),
            covs: smoother.smoothed_covs(),
            lag_one: smoother.lag_one_covs(),
        };
        let next = mstep::m_step(
            &data,
            &params,
            &post,
            &lin,
            false,
            Free::default(),
            &Priors::default(),
        )
        .unwrap();
        let ll_next = smoother.run(&model(&data, &next, &lin)).unwrap();
        // Rounding: ~1e-13 relative per operation over a few thousand.
        assert!(
            ll_next >= ll - 1e-10 * ll.abs(),
            "iteration {iteration}: {ll} -> {ll_next}"
        );
        params = next;
        ll = ll_next;
    }
    assert!(ll > first);
    // Run to the fixed point (q = 0.01 keeps EM's rate low enough for 400 iterations to
    // reach it); there the likelihood must be at a maximum: moving any parameter by 1e-3
    // of its size (or 1e-6) either way must not raise it beyond rounding. Wrong M-step
    // weights leave the fixed point off the maximum (checked: weights 1/d² instead of
    // 1/d⁴ fail here).
    for _ in 0..400 {
        let post = mstep::Posterior {
            means: smoother.smoothed_means(),
            covs: smoother.smoothed_covs(),
            lag_one: smoother.lag_one_covs(),
        };
        params = mstep::m_step(
            &data,
            &params,
            &post,
            &lin,
            false,
            Free::default(),
            &Priors::default(),
        )
        .unwrap();
        ll = smoother.run(&model(&data, &params, &lin)).unwrap();
    }
    let mut flat = Vec::new();
    params.flat(Free::default(), &mut flat);
    for i in 0..flat.len() {
        for sign in [-1.0, 1.0] {
            let mut moved = flat.clone();
            moved[i] += sign * (1e-3 * flat[i].abs()).max(1e-6);
            let p = params.with_flat(Free::default(), &moved).unwrap();
            let ll_moved = smoother.run(&model(&data, &p, &lin)).unwrap();
            assert!(
                ll_moved <= ll + 1e-9 * ll.abs(),
                "parameter {i} moved {sign}: {ll} -> {ll_moved}"
            );
        }
    }
}

#[test]
fn parameters_round_trip_through_their_flat_form() {
    let mut p = Params {
        sensors: [
            SensorParams::paper(LIDAR),
            SensorParams::paper(ODOMETER),
            SensorParams::paper(SONAR),
        ],
        q_rel: 0.02,
        speed_scale: 1.0,
    };
    p.sensors[LIDAR].active = true;
    p.sensors[LIDAR].beta[2] = 0.004;
    p.sensors[SONAR].active = true;
    p.sensors[SONAR].beta[0] = 0.008;
    let mut flat = Vec::new();
    let with_q = Free {
        q: true,
        speed_scale: false,
    };
    p.flat(with_q, &mut flat);
    assert_eq!(flat.len(), 3 + 1 + 2 + 1 + 1);
    assert_eq!(p.with_flat(with_q, &flat), Some(p));
    flat[3] = -1.0;
    assert_eq!(
        p.with_flat(with_q, &flat),
        None,
        "a negative noise level is outside"
    );
}
