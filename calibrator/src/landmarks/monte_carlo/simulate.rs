//! One simulated data set: landmarks, the sensor's true stops, and its noisy bearings and
//! ranges.

use rand::RngCore;
use rand_distr::{Distribution, StandardNormal};

use super::setup::Setup;
use crate::landmarks::estimate::{Observation, ObservationSet};
use crate::landmarks::regression::horner;

/// One simulated data set with its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// What the estimator sees.
    pub set: ObservationSet,
    /// True landmark centres.
    pub landmarks: Vec<[f64; 2]>,
    /// True sensor positions.
    pub stops: Vec<[f64; 2]>,
    /// True distance of each observation, metres.
    pub distances: Vec<f64>,
}

/// Draws a data set.
pub fn simulate(setup: &Setup, rng: &mut impl RngCore) -> Trial {
    let nominal = setup.nominal();
    let landmarks = setup
        .fixed_landmarks
        .clone()
        .unwrap_or_else(|| draw_landmarks(setup, &nominal, rng));
    let stops: Vec<[f64; 2]> = nominal
        .iter()
        .map(|s| {
            [
                s[0] + setup.sigma_s_m * normal(rng),
                s[1] + setup.sigma_s_m * normal(rng),
            ]
        })
        .collect();
    let mut observations = Vec::new();
    let mut distances = Vec::new();
    for (l, c) in landmarks.iter().enumerate() {
        for (k, s) in stops.iter().enumerate() {
            let (dx, dy) = (c[0] - s[0], c[1] - s[1]);
            let d = dx.hypot(dy) - setup.radius_m;
            let reading = horner(&setup.alpha, d) + horner(&setup.beta, d).max(0.0) * normal(rng);
            observations.push(Observation {
                landmark: l,
                stop: k,
                bearing_rad: dy.atan2(dx) + setup.sigma_theta_rad * normal(rng),
                range_m: reading,
                count: 1,
                scatter: Vec::new(),
            });
            distances.push(d);
        }
    }
    Trial {
        set: ObservationSet {
            stops: nominal,
            stop_sd_m: vec![None; setup.positions],
            landmarks: landmarks.len(),
            radius_m: setup.radius_m,
            observations,
        },
        landmarks,
        stops,
        distances,
    }
}

/// Random landmarks 0.5–2.5 m either side of the path, within 0.2–5 m of every nominal
/// position (the paper's field rule, Sec. 4.3) and 0.5 m apart.
fn draw_landmarks(setup: &Setup, nominal: &[[f64; 2]], rng: &mut impl RngCore) -> Vec<[f64; 2]> {
    let x_end = nominal.last().map_or(0.0, |s| s[0]);
    let mut out: Vec<[f64; 2]> = Vec::new();
    let mut tries = 0;
    while out.len() < setup.landmarks {
        tries += 1;
        let x = -1.0 + (x_end + 2.0) * uniform(rng);
        let side = if uniform(rng) < 0.5 { -1.0 } else { 1.0 };
        let y = side * (0.5 + 2.0 * uniform(rng));
        let c = [x, y];
        let ok_range = nominal.iter().all(|s| {
            let d = (c[0] - s[0]).hypot(c[1] - s[1]) - setup.radius_m;
            (0.2..=5.0).contains(&d)
        });
        let apart = out.iter().all(|o| (o[0] - x).hypot(o[1] - y) >= 0.5);
        if (ok_range && apart) || tries > 10_000 {
            out.push(c);
        }
    }
    out
}

pub(super) fn normal(rng: &mut impl RngCore) -> f64 {
    StandardNormal.sample(rng)
}

fn uniform(rng: &mut impl RngCore) -> f64 {
    (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}
