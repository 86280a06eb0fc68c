//! The drive's predictions conditioned on its past: a Kalman filter on the declared actuation
//! error.

use crate::physics::{DeclaredActuation, Gaussian};

/// The one-step predictive distributions of the wheels' travel over each window (rows: window
/// `i / 2`, wheel `i % 2`, in time order), given the travel the commands give (`increments`),
/// the real travel (`y`) and the declared actuation error.
///
/// The actuation error is one scale factor on both wheels, `1 + f + w(t)`: `f` fixed for the
/// run, `w` an Ornstein–Uhlenbeck wander. It is correlated across every window, so the windows'
/// residuals against the commands alone are not independent: a run whose fixed error happens
/// to be 2 % would show as a bias in every window. A Kalman filter on `(f, w)` conditions each
/// window on the windows before it; its innovations are independent, with the variances it
/// predicts, exactly when the drive is as declared (the prediction-error decomposition of the
/// likelihood: Shumway & Stoffer, *Time Series Analysis and Its Applications*, §6.2). With an
/// ideal drive the filter's state stays at zero and this is the commands' travel itself.
pub(super) fn drive_predictions(
    increments: &[f64],
    y: &[f64],
    starts: &[f64],
    actuation: DeclaredActuation,
    noise_var: f64,
) -> Vec<Gaussian> {
    let noise_var = noise_var.max(1e-12);
    // Discrete OU from one window to the next (`dt` apart): w' = a w + √(1 − a²) σ_w e.
    let decay = |dt: f64| {
        if actuation.wander_tau_s > 0.0 {
            (-dt / actuation.wander_tau_s).exp()
        } else {
            0.0
        }
    };
    // State (f, w) and its covariance [[pff, pfw], [pfw, pww]].
    let (mut f, mut w) = (0.0, 0.0);
    let (mut pff, mut pfw, mut pww) =
        (actuation.scale_sd.powi(2), 0.0, actuation.wander_sd.powi(2));
    let mut out = Vec::with_capacity(increments.len());
    for (i, (&inc, &real)) in increments.iter().zip(y).enumerate() {
        if i % 2 == 0 && i > 0 {
            let a = decay(starts[i / 2] - starts[i / 2 - 1]);
            w *= a;
            pfw *= a;
            pww = a * a * pww + actuation.wander_sd.powi(2) * (1.0 - a * a);
        }
        // Observation: real = inc (1 + f + w) + noise.
        let mean = inc * (1.0 + f + w);
        let (hf, hw) = (inc, inc);
        let (phf, phw) = (pff * hf + pfw * hw, pfw * hf + pww * hw);
        let var = hf * phf + hw * phw + noise_var;
        out.push(Gaussian::new(1.0, mean, var.sqrt()));
        let innovation = real - mean;
        // A reading far outside its prediction (an outlier to the model) does not steer the
        // state: that is the outlier component's business.
        if innovation.is_finite() && innovation.abs() <= 5.0 * var.sqrt() {
            let (kf, kw) = (phf / var, phw / var);
            f += kf * innovation;
            w += kw * innovation;
            pff -= kf * phf;
            pfw -= kf * phw;
            pww -= kw * phw;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::residuals::data::DRIVE_WINDOW_S;
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// A drive whose fixed scale error is 2 σ of the declared one (4 %): against the commands
    /// alone every moving window is biased the same way; the filter's innovations, standardised,
    /// are mean-zero unit-variance noise. 2,000 windows of two wheels: the standard error of the
    /// mean of 4,000 unit scores is 0.016, so 0.08 is 5 SE; of their mean square, 0.022, so the
    /// ±0.15 band is ~7 SE.
    #[test]
    fn the_drive_filter_whitens_a_declared_actuation_error() {
        let actuation = DeclaredActuation {
            scale_sd: 0.02,
            wander_sd: 0.01,
            wander_tau_s: 10.0,
        };
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let noise_sd = 0.001_f64;
        let (mut wander, a) = (0.0_f64, (-DRIVE_WINDOW_S / 10.0).exp());
        let (mut increments, mut y) = (Vec::new(), Vec::new());
        for k in 0..2000 {
            wander =
                a * wander + 0.01 * (1.0 - a * a).sqrt() * rng.sample::<f64, _>(StandardNormal);
            // Moving and standing in turns of 5 s; the wheels at 0.3 and 0.2 m/s.
            let moving = (k / 50) % 2 == 0;
            for speed in [0.03, 0.02] {
                let inc = if moving { speed } else { 0.0 };
                increments.push(inc);
                let noise: f64 = rng.sample(StandardNormal);
                y.push(inc * (1.0 + 0.04 + wander) + noise_sd * noise);
            }
        }
        let scores = |preds: &[Gaussian]| -> (f64, f64) {
            let z: Vec<f64> = preds
                .iter()
                .zip(&y)
                .map(|(g, y)| (y - g.mean_m) / g.sd_m)
                .collect();
            let n = z.len() as f64;
            (
                z.iter().sum::<f64>() / n,
                z.iter().map(|z| z * z).sum::<f64>() / n,
            )
        };
        let var = noise_sd * noise_sd;
        let starts: Vec<f64> = (0..2000).map(|k| f64::from(k) * DRIVE_WINDOW_S).collect();
        let (mean, msq) = scores(&drive_predictions(&increments, &y, &starts, actuation, var));
        assert!(mean.abs() < 0.08, "mean score {mean}");
        assert!((msq - 1.0).abs() < 0.15, "mean square {msq}");
        // The same data against the commands alone (an ideal drive declared): far from noise.
        let (mean, _) = scores(&drive_predictions(
            &increments,
            &y,
            &starts,
            DeclaredActuation::default(),
            var,
        ));
        assert!(mean > 0.3, "mean score against the commands alone {mean}");
    }
}
