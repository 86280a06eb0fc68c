//! Locate: where the residuals stop being noise. Each sensor's normal scores are tested for a
//! bias and an excess spread overall, for a bias and a spread that change with each variable
//! (range, bearing, incidence angle, object, time, speed, acceleration, turn rate…: readings
//! binned by the variable, the bins' means and mean squares compared), and for whiteness in time
//! (Ljung–Box). Every outcome is a normal score ("σ") with the same meaning: how far into the
//! tail of its null distribution the statistic lies. The strongest is the located mismatch.

use std::collections::BTreeMap;

use crate::catalogue::Sensor;
use crate::residuals::{Covariate, Fit, SensorData};
use crate::stats::{chi2_score, ljung_box};
use hilsim_lidar_emulator::normal;

/// Readings a bin needs to be tested.
const MIN_BIN: usize = 30;
/// Bins a continuous variable is cut into (at most).
const BINS: usize = 8;
/// Lags of the whiteness test.
const LAGS: usize = 10;

/// What kind of departure from noise a test looks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TestKind {
    /// The residuals' mean is not zero.
    Bias,
    /// The residuals spread more than the noise model says.
    Spread,
    /// The residuals' mean changes with a variable.
    BiasAgainst,
    /// The residuals' spread changes with a variable.
    SpreadAgainst,
    /// The residuals are correlated in time.
    Whiteness,
}

/// The outcome of one test.
#[derive(Debug, Clone, PartialEq)]
pub struct Evidence {
    /// The sensor tested.
    pub sensor: Sensor,
    /// The test.
    pub test: TestKind,
    /// The variable the residuals were tested against.
    pub covariate: Option<Covariate>,
    /// Normal score: the statistic's upper-tail probability as a standard normal quantile.
    pub score: f64,
    /// Where the departure is strongest, in words ("incidence angle 52–80 deg").
    pub place: String,
    /// The numbers behind it, in words.
    pub detail: String,
    /// The strongest bin's limits (continuous variables), for plots.
    pub range: Option<(f64, f64)>,
    /// How large the departure is, metres: a bias's mean residual (against a variable: the
    /// bin's mean residual less the overall one), a spread's excess standard deviation (robust:
    /// heavier tails than Gaussian do not count), or the standard deviation of a correlated
    /// component in time. NaN when it cannot be measured (no reading has a prediction).
    pub size_m: f64,
    /// The departure's typical size, metres: as `size_m`, with the median residual in place of
    /// the mean for a bias (against a variable: the bin's median less the overall one). A few
    /// readings far off (a ray the map lets through a gap its wall has, a person walking by)
    /// move a mean but not what most readings do; `size_m` for the other tests.
    pub median_m: f64,
    /// The declared noise there: the RMS of the predicted standard deviations, metres.
    pub noise_m: f64,
    /// How far the world's own error can move those readings, metres (their mean; 0 in a world
    /// drawn exactly).
    pub world_m: f64,
    /// The departure's size beyond what the world's error can make, metres: measured as
    /// `size_m` is, on each reading's residual less its world reach (a bias), or on the spread
    /// less the reach's (a spread). `size_m` in a world drawn exactly.
    pub beyond_world_m: f64,
}

impl Evidence {
    /// Whether this departure is a mismatch: statistically significant (its score above
    /// `threshold`) and large enough to matter (its size above `floors`' floor for its sensor
    /// and noise). A size that cannot be measured counts as large (a recording that does not
    /// align, readings where nothing was expected).
    #[must_use]
    pub fn counts(&self, threshold: f64, floors: &Floors) -> bool {
        self.score > threshold
            && (self.size_m.is_nan()
                || self.beyond_world_m > floors.floor_m(self.sensor, self.noise_m))
    }

    /// Whether this departure is significant and above its floor (whether or not the world's
    /// error could make it).
    #[must_use]
    pub fn beyond_floor(&self, threshold: f64, floors: &Floors) -> bool {
        self.score > threshold
            && (self.size_m.is_nan() || self.size_m > floors.floor_m(self.sensor, self.noise_m))
    }

    /// Whether the world's own error can make this departure (what is left of it beyond the
    /// world's reach is under the floor): a sensor's physics then cannot be told from the
    /// map's error.
    #[must_use]
    pub fn within_world(&self, threshold: f64, floors: &Floors) -> bool {
        self.beyond_floor(threshold, floors) && !self.counts(threshold, floors)
    }
}

/// The practical-significance floors: a departure smaller than
/// `max(absolute floor of its sensor, noise_share × the declared noise there)` is not reported
/// as a mismatch however significant it is over many readings. Derived in `docs/diagnose.md`
/// ("Practical significance").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Floors {
    /// Lidar, metres.
    pub lidar_m: f64,
    /// Sonar, metres.
    pub sonar_m: f64,
    /// Encoders, metres.
    pub odometer_m: f64,
    /// Drive (a wheel's travel over a 0.1 s window), metres.
    pub drive_m: f64,
    /// Share of the declared noise's standard deviation below which a departure does not
    /// matter.
    pub noise_share: f64,
}

impl Default for Floors {
    /// A scenario's world is measured to a few millimetres (a tape measure, a drawing), so a
    /// range mismatch below 5 mm is as likely the world's as the sensor's; an encoder or the
    /// drive resolves far less than a millimetre of travel, but their noise is a few: 2 mm
    /// and 1 mm (a 0.1 s window). A departure below a quarter of the noise's standard
    /// deviation changes no single reading's likelihood by more than 0.25²/2 ≈ 3 %: it matters
    /// only summed over thousands of readings, where any two simulators differ.
    fn default() -> Self {
        Self {
            lidar_m: 0.005,
            sonar_m: 0.005,
            odometer_m: 0.002,
            drive_m: 0.001,
            noise_share: 0.25,
        }
    }
}

impl Floors {
    /// The absolute floor of `sensor`, metres.
    #[must_use]
    pub fn absolute_m(&self, sensor: Sensor) -> f64 {
        match sensor {
            Sensor::Lidar => self.lidar_m,
            Sensor::Sonar => self.sonar_m,
            Sensor::Odometer => self.odometer_m,
            Sensor::Drive => self.drive_m,
        }
    }

    /// The floor of a departure of `sensor` where the declared noise is `noise_m`.
    #[must_use]
    pub fn floor_m(&self, sensor: Sensor, noise_m: f64) -> f64 {
        let relative = if noise_m.is_finite() {
            self.noise_share * noise_m
        } else {
            0.0
        };
        self.absolute_m(sensor).max(relative)
    }
}

/// A two-sided normal statistic as a one-sided score (the same tail probability).
fn two_sided(t: f64) -> f64 {
    let p = 2.0 * normal::sf(t.abs());
    if p < 1e-300 {
        t.abs()
    } else {
        -normal::quantile(p.min(1.0))
    }
}

/// Bins of `rows` by `values`: categories, or up to [`BINS`] groups of near-equal count that
/// never split equal values. Returns (label value or range, rows).
fn bins(values: &[f64], rows: &[usize], categorical: bool) -> Vec<((f64, f64), Vec<usize>)> {
    let mut rows: Vec<usize> = rows
        .iter()
        .copied()
        .filter(|&i| values[i].is_finite())
        .collect();
    if categorical {
        let mut groups: BTreeMap<i64, Vec<usize>> = BTreeMap::new();
        for i in rows {
            groups.entry(values[i] as i64).or_default().push(i);
        }
        return groups
            .into_iter()
            .filter(|(_, g)| g.len() >= MIN_BIN)
            .map(|(k, g)| ((k as f64, k as f64), g))
            .collect();
    }
    rows.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let n = rows.len();
    if n < 2 * MIN_BIN {
        return Vec::new();
    }
    let target = (n / BINS).max(MIN_BIN);
    let mut out: Vec<((f64, f64), Vec<usize>)> = Vec::new();
    let mut start = 0;
    while start < n {
        let mut end = (start + target).min(n);
        while end < n && values[rows[end]] == values[rows[end - 1]] {
            end += 1;
        }
        // A short tail joins the last bin.
        if n - end < MIN_BIN {
            end = n;
        }
        let chunk = rows[start..end].to_vec();
        out.push(((values[chunk[0]], values[chunk[chunk.len() - 1]]), chunk));
        start = end;
    }
    out
}

fn fmt_value(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// The bin's description.
fn place(c: Covariate, lim: (f64, f64), names: &dyn Fn(u32) -> String) -> String {
    match c {
        Covariate::Object => names(lim.0 as u32),
        Covariate::Edge => {
            if lim.0 > 0.5 {
                "beams near an edge".to_string()
            } else {
                "beams away from edges".to_string()
            }
        }
        // Echoes no nearer off the axis than on it, to the report's centimetre: "nearer by
        // 0 m" would read as a measurement.
        Covariate::OffAxisNearer if lim.1 < 0.005 => {
            "no echo nearer off the axis than on it".to_string()
        }
        // Its name is a noun for the bins and plots; a bin reads as a phrase.
        Covariate::OffAxisNearer if fmt_value(lim.0) == fmt_value(lim.1) => {
            format!("off-axis echo nearer by {} m", fmt_value(lim.1))
        }
        Covariate::OffAxisNearer => format!(
            "off-axis echo nearer by {}–{} m",
            fmt_value(lim.0),
            fmt_value(lim.1)
        ),
        _ if fmt_value(lim.0) == fmt_value(lim.1) => {
            format!("{} {} {}", c.name(), fmt_value(lim.0), c.unit())
                .trim_end()
                .to_string()
        }
        _ => format!(
            "{} {}–{} {}",
            c.name(),
            fmt_value(lim.0),
            fmt_value(lim.1),
            c.unit()
        )
        .trim_end()
        .to_string(),
    }
}

/// Mean and variance of the scores of `rows` (`fits` indexed by row position `pos[i]`).
fn moments(z: &[f64]) -> (f64, f64) {
    let n = z.len() as f64;
    let mean = z.iter().sum::<f64>() / n;
    let var = z.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, var)
}

/// `Σ_c (Σ_{k ∈ c} dev(k))²` over the clusters `c` that share errors (`cluster[k]`): the
/// cluster-robust ("sandwich") variance of the sum of `dev` over `ks` (Liang & Zeger,
/// Biometrika 1986). Deviations are taken from the null's value, so a bin inside one cluster
/// can never count as more than one observation.
fn clustered_sum_var(ks: &[usize], dev: impl Fn(usize) -> f64, cluster: &[u32]) -> f64 {
    let mut sums: BTreeMap<u32, f64> = BTreeMap::new();
    for &k in ks {
        *sums.entry(cluster[k]).or_default() += dev(k);
    }
    sums.values().map(|s| s * s).sum()
}

/// Every test of one sensor's residuals. `fits[k]` is the fit of row `rows[k]` of `data`.
/// `whiteness`: whether to test the residuals' correlation in time (not against an estimated
/// trajectory, whose errors a revolution's readings share).
pub(crate) fn locate(
    data: &SensorData,
    rows: &[usize],
    fits: &[Fit],
    names: &dyn Fn(u32) -> String,
    whiteness: bool,
) -> Vec<Evidence> {
    let n = rows.len();
    if n < 2 * MIN_BIN {
        return Vec::new();
    }
    let scores = Scores::new(data, rows, fits);
    let mut out = scores.overall().to_vec();
    for (c, values) in &data.covariates {
        if let Some(against) = scores.against(*c, values, names) {
            out.extend(against);
        }
    }
    if whiteness {
        out.extend(scores.whiteness());
    }
    out
}

/// One sensor's normal scores and what every test needs of them.
struct Scores<'a> {
    data: &'a SensorData,
    rows: &'a [usize],
    fits: &'a [Fit],
    /// Position of each data row in `rows`.
    pos: Vec<usize>,
    /// The normal scores, by position in `rows`.
    z: Vec<f64>,
    /// The cluster of each position, when readings share errors.
    cluster: Option<Vec<u32>>,
    /// Their mean.
    mean: f64,
    /// Their variance, at least 1.
    var: f64,
    /// Their sum of squares.
    ss: f64,
}

impl<'a> Scores<'a> {
    fn new(data: &'a SensorData, rows: &'a [usize], fits: &'a [Fit]) -> Self {
        let mut pos = vec![usize::MAX; data.len()];
        for (k, &i) in rows.iter().enumerate() {
            pos[i] = k;
        }
        let z: Vec<f64> = fits.iter().map(|f| f.z).collect();
        // Readings that share an error (of an estimated trajectory) are not independent: the
        // tests' variances are then the larger of the independent and the cluster-robust one.
        let cluster: Option<Vec<u32>> = data
            .clusters
            .as_ref()
            .map(|c| rows.iter().map(|&i| c[i]).collect());
        let (mean, sample_var) = moments(&z);
        // Normal scores have variance 1 when the prediction is right. Every test below measures
        // departures on that scale, or on the sample's when it is wider: residuals far smaller
        // than the declared noise (a simulation that reproduces the data better than its noise
        // model says) are no mismatch, however their tiny values are patterned.
        let var = sample_var.max(1.0);
        let ss: f64 = z.iter().map(|v| v * v).sum();
        Self {
            data,
            rows,
            fits,
            pos,
            z,
            cluster,
            mean,
            var,
            ss,
        }
    }

    /// The variance of a sum of deviations `dev` over `ks`: `independent`, or the
    /// cluster-robust one when larger.
    fn robust(&self, ks: &[usize], dev: &dyn Fn(usize) -> f64, independent: f64) -> f64 {
        match &self.cluster {
            Some(c) => independent.max(clustered_sum_var(ks, dev, c)),
            None => independent,
        }
    }

    /// The median residual (metres) of the positions `ks` that have one (NaN when none has).
    fn median_residual(&self, ks: &[usize]) -> f64 {
        let mut r: Vec<f64> = ks
            .iter()
            .map(|&k| self.fits[k].residual)
            .filter(|r| r.is_finite())
            .collect();
        if r.is_empty() {
            return f64::NAN;
        }
        let mid = r.len() / 2;
        *r.select_nth_unstable_by(mid, f64::total_cmp).1
    }

    /// The mean residual (metres) of the positions `ks` (NaN when none has one).
    fn mean_residual(&self, ks: &[usize]) -> f64 {
        let r: Vec<f64> = ks
            .iter()
            .map(|&k| self.fits[k].residual)
            .filter(|r| r.is_finite())
            .collect();
        if r.is_empty() {
            f64::NAN
        } else {
            r.iter().sum::<f64>() / r.len() as f64
        }
    }

    /// The mean of the world's reach at the positions `ks`, metres.
    fn world(&self, ks: &[usize]) -> f64 {
        if ks.is_empty() {
            return 0.0;
        }
        ks.iter().map(|&k| self.reach(k)).sum::<f64>() / ks.len() as f64
    }

    /// The world's reach of the reading at position `k`, metres.
    fn reach(&self, k: usize) -> f64 {
        self.rows.get(k).map_or(0.0, |&i| self.data.world_reach(i))
    }

    /// The mean residual (metres) of the positions `ks`, each less what the world's error can
    /// make of it (its residual moved toward 0 by its reach, not past it).
    fn mean_beyond_world(&self, ks: &[usize]) -> f64 {
        let r: Vec<f64> = ks
            .iter()
            .map(|&k| (self.fits[k].residual, self.reach(k)))
            .filter(|(r, _)| r.is_finite())
            .map(|(r, reach)| r.signum() * (r.abs() - reach).max(0.0))
            .collect();
        if r.is_empty() {
            f64::NAN
        } else {
            r.iter().sum::<f64>() / r.len() as f64
        }
    }

    /// An excess spread `excess_m` at `ks` less the spread the world's error can make there
    /// (a reach `u` spreads a reading by up to `u/√3`, a surface anywhere within ±u), metres.
    fn spread_beyond_world(&self, excess_m: f64, ks: &[usize]) -> f64 {
        if ks.is_empty() || !excess_m.is_finite() {
            return excess_m;
        }
        let world_var =
            ks.iter().map(|&k| self.reach(k).powi(2) / 3.0).sum::<f64>() / ks.len() as f64;
        (excess_m * excess_m - world_var).max(0.0).sqrt()
    }

    /// The RMS of the predicted standard deviations at the positions `ks`, metres.
    fn noise(&self, ks: &[usize]) -> f64 {
        let v: Vec<f64> = ks
            .iter()
            .map(|&k| self.fits[k].sd)
            .filter(|s| s.is_finite())
            .collect();
        if v.is_empty() {
            f64::NAN
        } else {
            (v.iter().map(|s| s * s).sum::<f64>() / v.len() as f64).sqrt()
        }
    }

    /// The excess spread at `ks`, metres: the noise there times `√(s² − 1)`, `s` the scores'
    /// robust scale (1.4826 × their median absolute deviation, 1 for the declared noise).
    /// Robust, so a small share of wild readings or heavier tails than Gaussian do not make a
    /// spread large: only a wider core does.
    fn excess_spread(&self, ks: &[usize]) -> f64 {
        let mut z: Vec<f64> = ks.iter().map(|&k| self.z[k]).collect();
        if z.is_empty() {
            return f64::NAN;
        }
        let mid = z.len() / 2;
        let median = *z.select_nth_unstable_by(mid, f64::total_cmp).1;
        let mut dev: Vec<f64> = z.iter().map(|v| (v - median).abs()).collect();
        let mad = *dev.select_nth_unstable_by(mid, f64::total_cmp).1;
        let s = 1.4826 * mad;
        self.noise(ks) * (s * s - 1.0).max(0.0).sqrt()
    }

    /// The overall bias (a t statistic of the scores) and spread (Σ z² against its χ²_n null,
    /// as a normal score).
    fn overall(&self) -> [Evidence; 2] {
        let (sensor, z, mean, ss) = (self.data.sensor, &self.z, self.mean, self.ss);
        let n = self.rows.len();
        let all: Vec<usize> = (0..n).collect();
        let t = mean * n as f64 / self.robust(&all, &|k| z[k], self.var * n as f64).sqrt();
        let spread = (ss - n as f64)
            / self
                .robust(&all, &|k| z[k] * z[k] - 1.0, 2.0 * n as f64)
                .sqrt();
        [
            Evidence {
                sensor,
                test: TestKind::Bias,
                covariate: None,
                score: two_sided(t),
                place: format!("all {sensor} readings"),
                detail: format!(
                    "mean normal score {mean:+.2} (mean residual {:+.1} mm) over {n} readings",
                    self.mean_residual(&all) * 1000.0
                ),
                range: None,
                size_m: self.mean_residual(&all).abs(),
                median_m: self.median_residual(&all).abs(),
                noise_m: self.noise(&all),
                world_m: self.world(&all),
                beyond_world_m: self.mean_beyond_world(&all).abs(),
            },
            Evidence {
                sensor,
                test: TestKind::Spread,
                covariate: None,
                score: spread,
                // (the mean square is tested against the declared 1, upwards only)
                place: format!("all {sensor} readings"),
                detail: format!(
                    "mean squared normal score {:.2} (1 for noise) over {n} readings",
                    ss / n as f64
                ),
                range: None,
                size_m: self.excess_spread(&all),
                median_m: self.excess_spread(&all),
                noise_m: self.noise(&all),
                world_m: self.world(&all),
                beyond_world_m: self.spread_beyond_world(self.excess_spread(&all), &all),
            },
        ]
    }

    /// Bias and spread against covariate `c` (its `values` by data row): the bins' means about
    /// the overall mean and their mean squares about the overall one, each a χ²_{B−1};
    /// `None` with fewer than two bins.
    fn against(
        &self,
        c: Covariate,
        values: &[f64],
        names: &dyn Fn(u32) -> String,
    ) -> Option<[Evidence; 2]> {
        let (sensor, z, mean, var) = (self.data.sensor, &self.z, self.mean, self.var);
        let groups = bins(values, self.rows, c.categorical());
        if groups.len() < 2 {
            return None;
        }
        let b = groups.len();
        // Bias against the variable: the bins' means about the overall mean, χ²_{B−1}.
        let mut chi_bias = 0.0;
        let mut chi_spread = 0.0;
        let mut best_bias = (0.0f64, 0usize);
        let mut best_spread = (0.0f64, 0usize);
        let mut stats = Vec::with_capacity(b);
        let msq_all = (self.ss / self.rows.len() as f64).max(1.0);
        for (g, (_, group)) in groups.iter().enumerate() {
            let ks: Vec<usize> = group.iter().map(|&i| self.pos[i]).collect();
            let nb = ks.len() as f64;
            let mb = ks.iter().map(|&k| z[k]).sum::<f64>() / nb;
            let vb = ks.iter().map(|&k| z[k] * z[k]).sum::<f64>() / nb;
            let zb = (mb - mean) * nb / self.robust(&ks, &|k| z[k] - mean, var * nb).sqrt();
            // The mean square of a bin of normal scores has variance 2 msq² / n_b.
            let sb = (vb - msq_all) * nb
                / self
                    .robust(
                        &ks,
                        &|k| z[k] * z[k] - msq_all,
                        2.0 * msq_all * msq_all * nb,
                    )
                    .sqrt();
            chi_bias += zb * zb;
            // Only an excess counts (a mismatch adds spread), so the sum is stochastically
            // below its χ²_{B−1} reference: conservative.
            chi_spread += sb.max(0.0).powi(2);
            if zb.abs() > best_bias.0.abs() {
                best_bias = (zb, g);
            }
            if sb > best_spread.0 {
                best_spread = (sb, g);
            }
            stats.push((mb, vb, ks));
        }
        let (zb, g) = best_bias;
        let (lim, _) = &groups[g];
        let (mb, _, ks) = &stats[g];
        let everywhere: Vec<usize> = (0..self.rows.len()).collect();
        let overall_residual = self.mean_residual(&everywhere);
        let overall_median = self.median_residual(&everywhere);
        let overall_beyond = self.mean_beyond_world(&everywhere);
        let bias = Evidence {
            sensor,
            test: TestKind::BiasAgainst,
            covariate: Some(c),
            score: chi2_score(chi_bias, b - 1),
            place: place(c, *lim, names),
            detail: format!(
                "mean normal score {mb:+.2} (mean residual {:+.1} mm, {zb:+.1}σ) over {} readings at {}, against {mean:+.2} overall; χ² {chi_bias:.0} on {} dof across {b} bins of {}",
                self.mean_residual(ks) * 1000.0,
                ks.len(),
                place(c, *lim, names),
                b - 1,
                c.name()
            ),
            range: (!c.categorical()).then_some(*lim),
            size_m: (self.mean_residual(ks) - overall_residual).abs(),
            median_m: (self.median_residual(ks) - overall_median).abs(),
            noise_m: self.noise(ks),
            world_m: self.world(ks),
            beyond_world_m: (self.mean_beyond_world(ks) - overall_beyond).abs(),
        };
        let (sb, g) = best_spread;
        let (lim, _) = &groups[g];
        let (_, vb, ks) = &stats[g];
        let spread = Evidence {
            sensor,
            test: TestKind::SpreadAgainst,
            covariate: Some(c),
            score: chi2_score(chi_spread, b - 1),
            place: place(c, *lim, names),
            detail: format!(
                "mean squared normal score {vb:.2} ({sb:+.1}σ) over {} readings at {}, against {msq_all:.2} overall; χ² {chi_spread:.0} on {} dof across {b} bins of {}",
                ks.len(),
                place(c, *lim, names),
                b - 1,
                c.name()
            ),
            range: (!c.categorical()).then_some(*lim),
            size_m: self.excess_spread(ks),
            median_m: self.excess_spread(ks),
            noise_m: self.noise(ks),
            world_m: self.world(ks),
            beyond_world_m: self.spread_beyond_world(self.excess_spread(ks), ks),
        };
        Some([bias, spread])
    }

    /// Whiteness: the scores in time order (Ljung–Box), when there are lags to test; each
    /// wheel on its own for the encoders and the drive (their rows alternate left, right), so
    /// noise the two wheels share at one instant is not mistaken for correlation in time. The
    /// wheel with the larger statistic is reported.
    fn whiteness(&self) -> Option<Evidence> {
        let (data, rows, sensor) = (self.data, self.rows, self.data.sensor);
        let channels = match sensor {
            Sensor::Odometer | Sensor::Drive => 2,
            Sensor::Lidar | Sensor::Sonar => 1,
        };
        let mut best: Option<(f64, usize, usize, Vec<usize>)> = None;
        for channel in 0..channels {
            let mut order: Vec<usize> = (0..rows.len())
                .filter(|&k| rows[k] % channels == channel)
                .collect();
            order.sort_by(|&a, &b| data.t[rows[a]].total_cmp(&data.t[rows[b]]));
            let series: Vec<f64> = order.iter().map(|&k| self.z[k]).collect();
            let (q, k) = ljung_box(&series, LAGS, 1.0);
            if k > 0 && best.as_ref().is_none_or(|b| q > b.0) {
                best = Some((q, k, series.len(), order));
            }
        }
        let (q, k, n, ks) = best?;
        // The correlated component's share of the variance, from the lags' mean squared
        // autocorrelation beyond its null (Q ≈ n Σ r²): a component of standard deviation s in
        // noise σ has r ≈ s² / (s² + σ²), so s = σ √(r / (1 − r)).
        let r = ((q - k as f64).max(0.0) / (n as f64 * k as f64))
            .sqrt()
            .min(0.99);
        let correlated_m = self.noise(&ks) * (r / (1.0 - r)).sqrt();
        Some(Evidence {
            sensor,
            test: TestKind::Whiteness,
            covariate: Some(Covariate::Time),
            score: chi2_score(q, k),
            place: format!("{sensor} readings in time order"),
            detail: format!("Ljung–Box Q {q:.0} on {k} lags (white noise: {k})"),
            range: None,
            size_m: correlated_m,
            median_m: correlated_m,
            noise_m: self.noise(&ks),
            world_m: self.world(&ks),
            beyond_world_m: self.spread_beyond_world(correlated_m, &ks),
        })
    }
}

/// The score a test must reach to count, for `tests` tests at family-wise level `alpha`
/// (Bonferroni).
#[must_use]
pub fn threshold(alpha: f64, tests: usize) -> f64 {
    -normal::quantile(alpha / tests.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::residuals::Queries;

    /// A bin of echoes no nearer off the sonar's axis than on it says so; one of echoes
    /// nearer gives how much, as a phrase (the covariate's name is a noun, for the χ²'s bins
    /// and the plots).
    #[test]
    fn a_bin_of_no_nearer_echo_is_not_said_to_be_nearer_by_nothing() {
        let names = |_: u32| String::new();
        assert_eq!(
            place(Covariate::OffAxisNearer, (0.0, 0.0), &names),
            "no echo nearer off the axis than on it"
        );
        assert_eq!(
            place(Covariate::OffAxisNearer, (0.0, 0.35), &names),
            "off-axis echo nearer by 0–0.35 m"
        );
        assert_eq!(
            place(Covariate::OffAxisNearer, (0.35, 0.35), &names),
            "off-axis echo nearer by 0.35 m"
        );
        assert_eq!(place(Covariate::Range, (0.0, 0.0), &names), "range 0 m");
    }

    /// Lidar readings from 0.5 to 5 m whose residuals are the declared noise's, but for one in
    /// eight beyond 4.4 m read 2 m short of the prediction (a ray a built map let through a
    /// gap in its far wall). The bias against the range is large in its mean and nil in its
    /// median.
    #[test]
    fn a_few_readings_far_off_move_a_bins_mean_not_its_median() {
        let n = 800;
        let sd = 0.02;
        let range: Vec<f64> = (0..n).map(|i| 0.5 + 4.5 * i as f64 / n as f64).collect();
        let fits: Vec<Fit> = range
            .iter()
            .enumerate()
            .map(|(i, d)| {
                // Scores spread evenly over ±1.5 within every run of 16 readings.
                let z = -1.5 + 3.0 * ((i * 7) % 16) as f64 / 15.0;
                let gap = *d > 4.4 && i % 8 == 0;
                Fit {
                    ll: 0.0,
                    z: if gap { -6.0 } else { z },
                    residual: if gap { -2.0 } else { z * sd },
                    sd,
                    outlier: gap,
                }
            })
            .collect();
        let data = SensorData {
            sensor: Sensor::Lidar,
            t: range.clone(),
            y: range.clone(),
            heldout: vec![false; n],
            covariates: vec![(Covariate::Range, range)],
            queries: Queries::Sonar(Vec::new()),
            epsilon: 0.01,
            outlier_density: 0.001,
            clusters: None,
            world_reach_m: Vec::new(),
        };
        let rows: Vec<usize> = (0..n).collect();
        let evidence = locate(&data, &rows, &fits, &|_| String::new(), false);
        let by_range = evidence
            .iter()
            .find(|e| e.test == TestKind::BiasAgainst && e.covariate == Some(Covariate::Range))
            .expect("a bias against the range");
        assert!(by_range.size_m > 0.15, "{by_range:?}");
        assert!(by_range.median_m < sd / 2.0, "{by_range:?}");
    }
}
