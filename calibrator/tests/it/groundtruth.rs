//! The ground-truth baseline (ML fit against the true distances, order by AIC, as in
//! Alhashimi et al., ICINCO 2016) recovers the lidar model and picks the true order.

use hilsim_calibrator::groundtruth::{self, fit_aic, fit_ml};
use hilsim_calibrator::target_samples::{extract, SampleOptions};
use hilsim_calibrator::{Method, Sensor};
use hilsim_fixtures::em_experiment::{Run, LIDAR_ALPHA, LIDAR_BETA2};
use nalgebra::{Matrix3, Vector3};
use rand_distr::{Distribution, StandardNormal};

#[test]
fn aic_picks_the_quadratic_order_on_quadratic_data() {
    // 200 data sets of the paper's lidar (quadratic bias, β2 d² noise) at 185 distances
    // spread over 0.5–4 m, as one 0.1 m/s run gives.
    let sets = 200;
    let mut rng = hilsim_sim::rng::stream(5, "issue-5-aic");
    let mut picked = [0usize; 5];
    for _ in 0..sets {
        let d: Vec<f64> = (0..185).map(|k| 0.5 + 3.5 * k as f64 / 184.0).collect();
        let y: Vec<f64> = d
            .iter()
            .map(|&d| {
                let e: f64 = StandardNormal.sample(&mut rng);
                LIDAR_ALPHA[0]
                    + LIDAR_ALPHA[1] * d
                    + LIDAR_ALPHA[2] * d * d
                    + LIDAR_BETA2 * d * d * e
            })
            .collect();
        let fit = fit_aic(&d, &y, 4).expect("fits");
        // The wrong noise shapes (sd constant or ∝ d, against a 64:1 spread of the true sd
        // over the range) lose by hundreds of log-likelihood units: never chosen.
        assert_eq!(fit.noise_power, 2);
        picked[fit.order()] += 1;
    }
    // Underfitting is impossible: α2 = 0.058 is ~50 standard errors from 0 here.
    assert_eq!(picked[0] + picked[1], 0, "{picked:?}");
    // AIC overfits with a fixed probability (Shibata, Biometrika 1976): with up to two extra
    // coefficients it keeps the true order when the χ²₁ gains Z1², Z2² of adding them satisfy
    // Z1² < 2 and Z1² + Z2² < 4, asymptotically with probability 0.787. With 200 sets the
    // frequency's sd is √(0.787·0.213/200) = 0.029; 5 sd below is 0.64. (This seed: 0.725.)
    let frequency = picked[2] as f64 / sets as f64;
    assert!(
        frequency > 0.64,
        "order 2 chosen in {frequency} of the sets: {picked:?}"
    );
}

#[test]
fn the_baseline_recovers_the_lidar_model_from_a_recording() {
    let rec = Run {
        seed: 3,
        ..Run::default()
    }
    .record();
    let cal = groundtruth::calibrate(&rec, &groundtruth::Options::default()).expect("fits");
    assert_eq!(cal.method, Method::Groundtruth);
    let order = cal.order.expect("the chosen order");
    assert!((2..=4).contains(&order), "order {order}");
    let lidar = &cal.sensors[&Sensor::Lidar];
    assert_eq!(lidar.alpha.len(), order + 1);
    assert_eq!(lidar.beta.len(), 3, "noise sd ∝ d²");
    assert!(
        cal.sensors.contains_key(&Sensor::Sonar) && cal.sensors.contains_key(&Sensor::Odometer)
    );
    // The training-set error (as the paper's Fig. 3 footnote): the inversion of the fitted
    // bias removes the bias, leaving the noise, β2 d² ≤ 6 cm against the raw 0.5 m at 4 m.
    let m = cal.metrics.expect("truth");
    assert!(m.mse_ratio() > 10.0, "{m:?}");

    // The quadratic fit's coefficients against the truth, within 5 standard errors of the
    // weighted least-squares covariance β2² (Σ φ φᵀ / d⁴)⁻¹, φ = [1, d, d²].
    let s = extract(&rec, &SampleOptions::default()).expect("samples");
    let truth = s.truth_m.as_ref().expect("truth");
    let (d, y): (Vec<f64>, Vec<f64>) = truth
        .iter()
        .zip(&s.lidar_m)
        .filter_map(|(&d, y)| y.map(|y| (d, y)))
        .unzip();
    let fit = fit_ml(&d, &y, 2, 2).expect("fits");
    let mut info = Matrix3::zeros();
    for &d in &d {
        let phi = Vector3::new(1.0, d, d * d);
        info += phi * phi.transpose() / d.powi(4);
    }
    let cov = info.try_inverse().expect("regular") * LIDAR_BETA2 * LIDAR_BETA2;
    for i in 0..3 {
        let tolerance = 5.0 * cov[(i, i)].sqrt();
        assert!(
            (fit.alpha[i] - LIDAR_ALPHA[i]).abs() < tolerance,
            "alpha_{i} = {} vs {} ± {tolerance}",
            fit.alpha[i],
            LIDAR_ALPHA[i]
        );
    }
    // β from N residuals: relative sd √(1/(2N)), 5 of them; the millimetre quantisation adds
    // (0.29 mm)² to a variance of at least (β2 · 0.5²)² = (1 mm)², under 9 % (4 % in β).
    let tolerance = 5.0 / (2.0 * d.len() as f64).sqrt() + 0.04;
    assert!(
        (fit.beta / LIDAR_BETA2 - 1.0).abs() < tolerance,
        "beta_2 = {} vs {LIDAR_BETA2}",
        fit.beta
    );
}

#[test]
fn inversion_is_the_bias_inverse() {
    for d in [0.5, 1.7, 4.0] {
        let y = LIDAR_ALPHA[0] + LIDAR_ALPHA[1] * d + LIDAR_ALPHA[2] * d * d;
        let back = groundtruth::invert(&LIDAR_ALPHA, y).expect("invertible");
        assert!((back - d).abs() < 1e-9, "{back} vs {d}");
    }
}
