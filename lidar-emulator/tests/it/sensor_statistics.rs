//! The sensors' noise must be the configured model: the lidar's bias polynomial and
//! β₂d² spread recovered by fits over 10⁵ readings, the sonar's cone, the odometer's slip and
//! ticks.
//!
//! Every tolerance is derived from the sampling distribution of the estimate it bounds, with a
//! fixed seed; "5 SE" means five standard errors (a false alarm rate of ~6e-7 per check had the
//! seed been drawn at random).

use std::sync::OnceLock;

use hilsim_lidar_emulator::Emulation;
use hilsim_recording::TruthSample;
use hilsim_sim::Scenario;

/// The landmark paper's XV-11 model (Sec. 4.1): alpha, metres.
const ALPHA: [f64; 3] = [0.0525, 0.8838, 0.0584];
/// The noise standard deviation's d² coefficient, 1/m.
const BETA_2: f64 = 0.0029;
/// The lidar reports whole millimetres: rounding adds a variance of q²/12 (Sheppard), q = 1 mm.
const QUANTISATION_VAR_M2: f64 = 1e-6 / 12.0;

fn scenario(text: &str) -> Scenario {
    Scenario::from_toml(text, "statistics.toml".as_ref()).unwrap()
}

/// Pairs (true range d, reported range y) of every valid lidar reading of a 60 s run, the robot
/// standing in a 5 m × 3 m room: 1 m to the front wall, 4 m to the back wall, 0.5 m and 2.5 m to
/// the sides, so that the beams' true ranges span 0.5 m to 4.7 m (the far corner).
fn lidar_pairs() -> &'static [(f64, f64)] {
    static PAIRS: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    PAIRS.get_or_init(|| {
        let s = scenario(&format!(
            r#"
            name = "lidar-statistics"
            duration_s = 60.0
            [world]
            walls = [
                {{ from = [1.0, -2.5], to = [1.0, 0.5] }},
                {{ from = [1.0, 0.5], to = [-4.0, 0.5] }},
                {{ from = [-4.0, 0.5], to = [-4.0, -2.5] }},
                {{ from = [-4.0, -2.5], to = [1.0, -2.5] }},
            ]
            [robot]
            start = {{ x = 0.0, y = 0.0 }}
            wheel_base_m = 0.23
            [sensors.lidar]
            bias = {ALPHA:?}
            noise = [0.0, 0.0, {BETA_2}]
            # Far enough that no reading near 4.7 m (mean 5.5 m, σ 6 cm) is cut off as beyond range.
            max_range_m = 10.0
            "#
        ));
        let mut emulation = Emulation::new(&s, 11).unwrap();
        let mut pairs = Vec::with_capacity(110_000);
        while let Some(samples) = emulation.step() {
            // Only the strength (independent of the range noise: its own speckle draw) can make
            // a reading invalid here, so keeping the valid ones selects no range noise.
            pairs.extend(
                samples
                    .lidar
                    .iter()
                    .filter(|r| r.error_code.is_none())
                    .map(|r| (r.true_range_m.unwrap(), f64::from(r.distance_mm) / 1000.0)),
            );
        }
        pairs
    })
}

/// The model's variance of one reported range at true range `d`, m².
fn variance(d: f64) -> f64 {
    (BETA_2 * d * d).powi(2) + QUANTISATION_VAR_M2
}

fn mean_of(d: f64) -> f64 {
    ALPHA[0] + ALPHA[1] * d + ALPHA[2] * d * d
}

/// Solves the 3×3 system `a x = b` (symmetric positive definite) by Gaussian elimination and
/// returns x and a⁻¹.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    // Augment with the identity and b, eliminate fully (Gauss–Jordan, no pivoting needed for an
    // SPD matrix).
    let mut m = [[0.0; 7]; 3];
    for i in 0..3 {
        m[i][..3].copy_from_slice(&a[i]);
        m[i][3 + i] = 1.0;
        m[i][6] = b[i];
    }
    for col in 0..3 {
        let pivot = m[col][col];
        for v in &mut m[col] {
            *v /= pivot;
        }
        for row in 0..3 {
            if row != col {
                let f = m[row][col];
                let pivot_row = m[col];
                for (v, p) in m[row].iter_mut().zip(pivot_row) {
                    *v -= f * p;
                }
            }
        }
    }
    let x = [m[0][6], m[1][6], m[2][6]];
    let inv = [0, 1, 2].map(|i| [m[i][3], m[i][4], m[i][5]]);
    (x, inv)
}

#[test]
fn lidar_bias_polynomial_and_noise_are_recovered_from_1e5_readings() {
    let pairs = lidar_pairs();
    let n = pairs.len();
    // 60 s at 1,800 readings/s = 108,000 (a beam grazing a wall could return too weak a signal).
    assert!(n >= 100_000, "{n} valid readings");
    let (lo, hi) = pairs
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &(d, _)| {
            (lo.min(d), hi.max(d))
        });
    assert!(lo < 0.55 && hi > 4.5, "ranges {lo}..{hi} m");

    // Weighted least squares of y = α₀ + α₁d + α₂d² with weights 1/Var(y | d) from the model
    // (β₂²d⁴ + q²/12): unbiased whatever the weights, efficient with these, and then
    // Cov(α̂) = s²(XᵀWX)⁻¹ with s² ≈ 1.
    let mut xtwx = [[0.0; 3]; 3];
    let mut xtwy = [0.0; 3];
    for &(d, y) in pairs {
        let w = 1.0 / variance(d);
        let x = [1.0, d, d * d];
        for i in 0..3 {
            for j in 0..3 {
                xtwx[i][j] += w * x[i] * x[j];
            }
            xtwy[i] += w * x[i] * y;
        }
    }
    let (alpha, inv) = solve3(xtwx, xtwy);
    let chi2: f64 = pairs
        .iter()
        .map(|&(d, y)| (y - (alpha[0] + alpha[1] * d + alpha[2] * d * d)).powi(2) / variance(d))
        .sum();
    let s2 = chi2 / (n - 3) as f64;
    eprintln!("{n} readings over {lo:.3}..{hi:.3} m: alpha = {alpha:?}, reduced chi2 = {s2:.4}");
    // s² is a mean of n ≈ χ²₁ terms: SE √(2/n) ≈ 0.0044 (a little less in truth: the uniform
    // rounding error has lighter tails than a Gaussian). 5 SE ≈ 0.022.
    let s2_tol = 5.0 * (2.0 / n as f64).sqrt();
    assert!((s2 - 1.0).abs() <= s2_tol, "reduced χ² {s2} ± {s2_tol}");
    for i in 0..3 {
        let se = (s2 * inv[i][i]).sqrt();
        eprintln!("alpha_{i} = {:.6} ± {se:.2e}", alpha[i]);
        // 5 standard errors of the fit: SE(α₀) ≈ 32 µm, SE(α₁) ≈ 69 µm/m, SE(α₂) ≈ 29 µm/m² here.
        assert!(
            (alpha[i] - ALPHA[i]).abs() <= 5.0 * se,
            "alpha_{i} = {} ± {se}, configured {}",
            alpha[i],
            ALPHA[i]
        );
    }

    // The spread: with residuals r about the configured mean, E[r²] = β₂²d⁴ + q²/12, so each
    // c_i = (r_i² − q²/12)/d_i⁴ estimates β₂² and their mean is the (weighted least-squares) fit of
    // r² = c·d⁴ with Var(r²) ∝ d⁸.
    let c: Vec<f64> = pairs
        .iter()
        .map(|&(d, y)| ((y - mean_of(d)).powi(2) - QUANTISATION_VAR_M2) / d.powi(4))
        .collect();
    let c_mean = c.iter().sum::<f64>() / n as f64;
    let c_sd = (c.iter().map(|v| (v - c_mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let beta_2 = c_mean.sqrt();
    // SE(ĉ) = sd(c)/√n, and by the delta method SE(√ĉ) = SE(ĉ)/(2√ĉ): ≈ β₂/√(2n) ≈ 6.4e-6 /m.
    let se = c_sd / (n as f64).sqrt() / (2.0 * beta_2);
    eprintln!("beta_2 = {beta_2:.6} ± {se:.2e}");
    assert!(
        (beta_2 - BETA_2).abs() <= 5.0 * se,
        "beta_2 = {beta_2} ± {se}, configured {BETA_2}"
    );
}

#[test]
fn lidar_spread_at_4_m_is_16_times_the_spread_at_1_m() {
    let pairs = lidar_pairs();
    // Readings whose true range is within 1 % of 1 m and of 4 m: beams within ~8° of the front
    // and back walls' normals, plus where side walls cross those ranges.
    let bin = |centre: f64| {
        let inside: Vec<(f64, f64)> = pairs
            .iter()
            .copied()
            .filter(|&(d, _)| (d - centre).abs() <= 0.01 * centre)
            .collect();
        let n = inside.len() as f64;
        // Sheppard-corrected variance of the residuals about the configured mean, and the model's
        // d⁴ averaged over the bin (the bin is 2 % wide, d⁴ varies by 8 % across it).
        let var = inside
            .iter()
            .map(|&(d, y)| (y - mean_of(d)).powi(2))
            .sum::<f64>()
            / n
            - QUANTISATION_VAR_M2;
        let d4 = inside.iter().map(|&(d, _)| d.powi(4)).sum::<f64>() / n;
        (inside.len(), var, d4)
    };
    let (n1, var1, d4_1) = bin(1.0);
    let (n4, var4, d4_4) = bin(4.0);
    assert!(
        n1 >= 2000 && n4 >= 2000,
        "{n1} readings near 1 m, {n4} near 4 m"
    );
    let ratio = (var4 / var1).sqrt();
    // σ = β₂d²: the standard deviations' ratio is √(mean d⁴ at 4 m / mean d⁴ at 1 m) ≈ 16.
    let expected = (d4_4 / d4_1).sqrt();
    eprintln!("σ(4 m)/σ(1 m) = {ratio:.3}, model {expected:.3}, from {n1} and {n4} readings");
    assert!((expected - 16.0).abs() < 0.5, "{expected}");
    // A sample variance of n Gaussian draws has Var(ln s²) ≈ 2/n, so
    // SE(ln(s₄/s₁)) = ½·√(2/n₄ + 2/n₁): ≈ 0.014 for the ~5,000 readings in each bin here, so
    // 5 SE ≈ ±7 %.
    let se_log = 0.5 * (2.0 / n4 as f64 + 2.0 / n1 as f64).sqrt();
    assert!(
        (ratio.ln() - expected.ln()).abs() <= 5.0 * se_log,
        "σ(4 m)/σ(1 m) = {ratio}, expected {expected} (±{:.1} %, {n1} and {n4} readings)",
        500.0 * se_log
    );
}

/// Sonar pings of a 1 s run with one cylinder of radius 0.05 m at 1.5 m, `off_axis_deg` to the
/// left of the sonar's axis, and nothing else in the world.
fn sonar_pings(off_axis_deg: f64) -> Vec<hilsim_recording::SonarSample> {
    let (sin, cos) = off_axis_deg.to_radians().sin_cos();
    let s = scenario(&format!(
        r#"
        name = "sonar-cone"
        duration_s = 1.0
        [world]
        cylinders = [{{ center = [{}, {}], radius = 0.05 }}]
        [robot]
        start = {{ x = 0.0, y = 0.0 }}
        wheel_base_m = 0.23
        [sensors.sonar]
        bias = [0.0, 1.0]
        noise = [0.0]
        half_angle_deg = 15.0
        "#,
        1.5 * cos,
        1.5 * sin
    ));
    let run = Emulation::new(&s, 5).unwrap().run();
    run.recording.sonar.unwrap()
}

#[test]
fn sonar_hears_an_object_inside_its_cone_and_not_one_outside() {
    // At 10° off-axis, inside the 15° half-angle: every one of the 10 pings (10 Hz for 1 s)
    // hears the cylinder's nearest point, 1.5 − 0.05 m away. The cone's rays are 0.25° apart, so
    // one runs along the 10° line itself; with f32 geometry, 1e-4 m is ample.
    let inside = sonar_pings(10.0);
    assert_eq!(inside.len(), 10, "{inside:?}");
    for ping in &inside {
        let d = ping.true_range_m.unwrap();
        assert!((d - 1.45).abs() <= 1e-4, "{ping:?}");
        // Noiseless and unbiased: the report is d in whole millimetres.
        assert!((ping.range_m - 1.45).abs() <= 0.0005 + 1e-4, "{ping:?}");
    }
    // Mirrored: the cone is symmetric.
    assert_eq!(sonar_pings(-10.0).len(), 10);
    // At 20° the cylinder subtends 20° ± asin(0.05/1.5) = 18.1°..21.9°: wholly outside the cone,
    // and nothing else is there to echo.
    let outside = sonar_pings(20.0);
    assert!(outside.is_empty(), "{outside:?}");
}

/// The true travel of a robot driving straight along +x from x = 0, at `t`, from the per-step
/// truth.
fn travel_at(truth: &[TruthSample], t: f64) -> f64 {
    let i = truth
        .partition_point(|s| s.t_s <= t)
        .clamp(1, truth.len() - 1);
    let (a, b) = (&truth[i - 1], &truth[i]);
    let u = ((t - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0);
    a.x_m + (b.x_m - a.x_m) * u
}

#[test]
fn odometer_scale_is_one_plus_slip_and_readings_are_whole_ticks() {
    const SLIP: f64 = 0.05;
    const NOISE_M: f64 = 0.002;
    const TICK_M: f64 = 0.0025;
    let s = scenario(&format!(
        r#"
        name = "odometer"
        [robot]
        start = {{ x = 0.0, y = 0.0 }}
        wheel_base_m = 0.23
        [[drive]]
        speed_mps = 0.4
        distance_m = 2.0
        [[drive]]
        stop_s = 1.0
        [sensors.odometer]
        slip = {SLIP}
        noise_m = {NOISE_M}
        tick_m = {TICK_M}
        "#
    ));
    let recording = Emulation::new(&s, 9).unwrap().run().recording;
    let truth = recording.truth.unwrap();
    let odometry = recording.odometry.unwrap();
    // 6 s at 20 Hz.
    assert_eq!(odometry.len(), 120);
    for o in &odometry {
        for v in [o.left_m, o.right_m] {
            let ticks = (v / TICK_M).round();
            assert!(
                (v - ticks * TICK_M).abs() <= 1e-9,
                "{v} is not a multiple of {TICK_M}"
            );
        }
    }
    // Least squares through the origin of reported = scale · true travel, both wheels (a straight
    // run: each wheel travels what the body does).
    let pairs: Vec<(f64, f64)> = odometry
        .iter()
        .flat_map(|o| {
            let x = travel_at(&truth, o.t_s);
            [(x, o.left_m), (x, o.right_m)]
        })
        .collect();
    let sxx: f64 = pairs.iter().map(|(x, _)| x * x).sum();
    let scale = pairs.iter().map(|(x, y)| x * y).sum::<f64>() / sxx;
    let residual_var = pairs
        .iter()
        .map(|(x, y)| (y - scale * x).powi(2))
        .sum::<f64>()
        / (pairs.len() - 1) as f64;
    // Each reading's error is the noise plus the tick rounding: σ² ≈ 0.002² + 0.0025²/12
    // ≈ (2.13 mm)². A sample standard deviation of n = 240 residuals has a relative SE of
    // 1/√(2n) ≈ 4.6 %, i.e. 0.1 mm: 5 SE = 0.5 mm.
    assert!(
        (residual_var.sqrt() - (NOISE_M.powi(2) + TICK_M.powi(2) / 12.0).sqrt()).abs() < 0.5e-3,
        "residual σ {} m",
        residual_var.sqrt()
    );
    // The slope's SE is σ/√Σx² ≈ 2.1 mm/√(2·(100·4/3 + 20·4)) m ≈ 1e-4.
    let se = (residual_var / sxx).sqrt();
    eprintln!(
        "odometer scale {scale:.5} ± {se:.1e}, residual sigma {:.2e} m",
        residual_var.sqrt()
    );
    assert!(
        (scale - (1.0 + SLIP)).abs() <= 5.0 * se,
        "scale {scale} ± {se}, expected {}",
        1.0 + SLIP
    );
}
