//! The sensors: the papers' range model (reading = Σ αᵢ dⁱ + (Σ βᵢ dⁱ)·e, Saha et al. /
//! the EM paper's eq. (2), coefficients from the scenario), rays cast in this crate's own
//! world, and the concealed effects and nuisances of the run.

use hilsim_recording::{LidarSample, OdometrySample, Pose, SonarSample, TruthSample};
use hilsim_sim::scenario::{LidarTiming, Scenario};

use crate::concealed::{delay_s, speed_of_sound, Concealed, Stamped};
use crate::form::{EchoPick, LossBy, RANGE_CURVE_SPAN_M};
use crate::motion::Motion;
use crate::noise::Stream;
use crate::nuisance::Nuisances;
use crate::world::World;

/// Σ cᵢ dⁱ.
fn poly(c: &[f64], d: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * d + k)
}

/// The incidence angle's cap: beyond 80° the footprint's depth `d tan θ` has no meaning.
const MAX_INCIDENCE_RAD: f64 = 80.0 * std::f64::consts::PI / 180.0;
/// Directions a mixed-pixel footprint is sampled at (across the beam's width).
const FOOTPRINT_SAMPLES: usize = 9;
/// Intensity at 1 m on the default material, head-on; it falls as d^-0.7 (XV-11 captures).
const INTENSITY_AT_1M: f64 = 9000.0;
/// Below this intensity the unit sets its strength-warning flag.
const WEAK_INTENSITY: f64 = 50.0;

fn at_mount(p: Pose, x: f64, y: f64, yaw_deg: f64) -> ([f64; 2], f64) {
    let (s, c) = p.yaw.sin_cos();
    (
        [p.x + c * x - s * y, p.y + s * x + c * y],
        p.yaw + yaw_deg.to_radians(),
    )
}

fn quantise(v: f64, step: f64) -> f64 {
    if step > 0.0 {
        (v / step).round() * step
    } else {
        v
    }
}

/// Everything the sensors need.
pub struct Run<'a> {
    pub scenario: &'a Scenario,
    pub world: &'a World,
    pub motion: &'a Motion,
    pub end_s: f64,
    pub concealed: &'a [Concealed],
    pub nuisances: Nuisances,
    /// Each wheel's radius over nominal (the encoders report the ground's travel over it).
    pub radius_scale: [f64; 2],
}

impl Run<'_> {
    fn has(&self, f: impl Fn(&Concealed) -> bool) -> bool {
        self.concealed.iter().any(f)
    }

    /// One range-noise deviate: Gaussian, or Student-t of unit variance.
    fn deviate(&self, s: &mut Stream) -> f64 {
        if self.nuisances.tail_dof > 0.0 {
            s.student_unit_variance(self.nuisances.tail_dof)
        } else {
            s.normal()
        }
    }

    /// The lidar's readings.
    pub fn lidar(&self, seed: u64) -> Option<Vec<LidarSample>> {
        let cfg = self.scenario.sensors.lidar.as_ref()?;
        let n = &self.nuisances;
        let mut noise = Stream::new(seed, "reality-lidar");
        let mut drops = Stream::new(seed, "reality-lidar-drops");
        let mut returns = Stream::new(seed, "reality-lidar-returns");
        let weak = self.concealed.iter().find_map(|c| match *c {
            Concealed::LidarWeakReturns {
                half_loss_range_m,
                log_power_sd,
                reference,
                loss,
            } => Some((half_loss_range_m, log_power_sd, reference, loss)),
            _ => None,
        });
        // A loss curve's own half point, so that half the returns are lost at d½.
        let half_point = match weak {
            Some((_, _, _, LossBy::RangeCurve(c))) => c.reaches(0.5),
            _ => 0.0,
        };
        let period = 60.0 / cfg.rpm;
        let slot = period / 360.0;
        let snapshot = cfg.timing == LidarTiming::PerRevolution
            && !self.has(|c| matches!(c, Concealed::LidarMotionSkew));
        let max_range = cfg.max_range_m * n.max_range_factor;
        // Where the unit really sits: the scenario's mount moved in the robot's frame.
        let (dx, dy, dyaw) = self
            .concealed
            .iter()
            .find_map(|c| match *c {
                Concealed::LidarMountOffset { yaw_deg, x_m, y_m } => Some((x_m, y_m, yaw_deg)),
                _ => None,
            })
            .unwrap_or((0.0, 0.0, 0.0));
        let late_s = delay_s(self.concealed, Stamped::Lidar);
        let mut out = Vec::new();
        let revolutions = (self.end_s / period).floor() as u64;
        for rev in 0..revolutions {
            let t_rev = rev as f64 * period;
            if drops.chance(n.dropped_revolutions) {
                continue;
            }
            let mut dropped_packet = false;
            for i in 0..360u16 {
                if i % 4 == 0 {
                    dropped_packet = drops.chance(n.dropped_packets);
                }
                let t = t_rev + f64::from(i) * slot;
                let t_geometry = if snapshot {
                    t_rev
                } else {
                    (t + n.reading_phase * slot).max(0.0)
                };
                let (origin, heading) = at_mount(
                    self.motion.pose(t_geometry),
                    cfg.mount.x_m + dx,
                    cfg.mount.y_m + dy,
                    cfg.mount.yaw_deg + dyaw,
                );
                let direction = heading
                    + f64::from(i).to_radians()
                    + cfg.angle_noise_deg.to_radians() * noise.normal();
                let e = self.deviate(&mut noise);
                let spurious = noise.chance(n.spurious_share);
                let spurious_at = noise.between(cfg.min_range_m, max_range);
                let jitter = n.timestamp_jitter_s * noise.normal();
                if dropped_packet {
                    continue;
                }
                let reading = self.lidar_reading(cfg, origin, direction, t, e, max_range);
                let (range, true_range, strength, power) = match reading {
                    Some(r) => r,
                    None => (0.0, None, 0.0, 0.0),
                };
                let lost = weak.is_some_and(|(half_m, sd, reference, loss)| match loss {
                    // A return whose received power, scattered, falls below the threshold.
                    LossBy::Power => {
                        let relative = power / reference * half_m * half_m;
                        relative * (sd * returns.normal()).exp() < 1.0
                    }
                    LossBy::RangeCurve(c) => {
                        let d = true_range.unwrap_or(f64::INFINITY);
                        returns.chance(c.at((d / half_m).ln() + half_point))
                    }
                });
                let range = if lost { 0.0 } else { range };
                let range = if spurious { spurious_at } else { range };
                let range = quantise(range, n.lidar_resolution_m);
                let valid_by = if n.validity_by_true_range && !spurious {
                    true_range.unwrap_or(f64::INFINITY)
                } else {
                    range
                };
                let valid = range > 0.0 && valid_by >= cfg.min_range_m && valid_by <= max_range;
                let strength = (strength * n.intensity_scale).clamp(0.0, f64::from(u16::MAX));
                out.push(LidarSample {
                    t_s: (t + late_s + jitter).max(0.0),
                    rev,
                    angle_deg: f64::from(i),
                    range_m: if valid { range } else { 0.0 },
                    strength: if valid { strength as u16 } else { 0 },
                    invalid: !valid,
                    warning: valid && strength < WEAK_INTENSITY,
                    true_range_m: None,
                });
            }
        }
        out.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        Some(out)
    }

    /// One lidar reading (before rounding and validity): the reported range, the true range,
    /// the intensity and the power a diffuse surface returns, `ρ cos θ / d²`, or `None` when
    /// nothing is within reach.
    fn lidar_reading(
        &self,
        cfg: &hilsim_sim::scenario::Lidar,
        origin: [f64; 2],
        direction: f64,
        t: f64,
        e: f64,
        max_range: f64,
    ) -> Option<(f64, Option<f64>, f64, f64)> {
        let reach = 2.0 * max_range;
        let hit = self.world.cast(origin, direction, reach)?;
        let mut d = hit.range_m;
        for c in self.concealed {
            if let Concealed::LidarMixedPixels {
                half_width_deg,
                blend,
            } = *c
            {
                // The footprint sampled across its width (its blend's profile). A harmonic blend:
                // the triangulation camera sees every part and reports f b / x̄, the weighted
                // harmonic mean of their ranges; else the power-weighted mean of the ranges.
                let (mut num, mut den) = (0.0, 0.0);
                for k in 0..FOOTPRINT_SAMPLES {
                    let u = (k as f64 + 0.5) / FOOTPRINT_SAMPLES as f64 * 2.0 - 1.0;
                    let (offset, profile) = blend.profile(u);
                    let dir = direction + offset * half_width_deg.to_radians();
                    if let Some(h) = self.world.cast(origin, dir, reach) {
                        let w = profile * h.reflectivity * h.incidence_rad.cos()
                            / (h.range_m * h.range_m);
                        if blend.harmonic() {
                            num += w;
                            den += w / h.range_m;
                        } else {
                            num += w * h.range_m;
                            den += w;
                        }
                    }
                }
                if den > 0.0 {
                    d = num / den;
                }
            }
        }
        let theta = hit.incidence_rad.min(MAX_INCIDENCE_RAD);
        // The effects move the distance the unit measures; its calibration (the bias
        // polynomial) then maps that distance to the reading, as it maps the true one.
        let mut measured = d;
        for c in self.concealed {
            measured += match *c {
                Concealed::LidarIncidence {
                    coefficient,
                    collimated_m,
                    growth,
                } => (coefficient * d + collimated_m) * growth.at(theta),
                Concealed::LidarReflectivity {
                    coefficient_m,
                    reference,
                    walk,
                } => coefficient_m * walk.at(hit.reflectivity, reference),
                Concealed::LidarWarmup {
                    coefficient_per_m,
                    time_constant_s,
                    offset_m,
                    settling,
                } => (offset_m + coefficient_per_m * d * d) * settling.at(t, time_constant_s),
                Concealed::LidarPeriodicRange {
                    amplitude_m,
                    period_m,
                } => amplitude_m * (std::f64::consts::TAU * d / period_m).sin(),
                _ => 0.0,
            };
        }
        let mut reading = poly(&cfg.bias, measured) + poly(&cfg.noise, d) * e;
        for c in self.concealed {
            if let Concealed::LidarTriangulation {
                origin_m,
                baseline_ratio,
                pointing_per_m,
            } = *c
            {
                // What the unit's own geometry reads where the declared calibration reads
                // `measured`; a denominator kept positive, as a spot stays on the sensor.
                let own =
                    origin_m + measured / (baseline_ratio + measured * pointing_per_m).max(0.1);
                reading += own - measured;
            }
            if let Concealed::LidarRangeCurve {
                at_2m_m,
                slope,
                curve,
            } = *c
            {
                let shaped = RANGE_CURVE_SPAN_M * (curve.at(measured) - curve.at(2.0));
                reading += at_2m_m + slope * shaped;
            }
        }
        let intensity =
            INTENSITY_AT_1M * hit.reflectivity / 0.8 * hit.incidence_rad.cos() * d.powf(-0.7);
        let power = hit.reflectivity * hit.incidence_rad.cos() / (hit.range_m * hit.range_m);
        Some((reading.max(0.0), Some(hit.range_m), intensity, power))
    }

    /// The sonar's pings (none where no echo is within range).
    pub fn sonar(&self, seed: u64) -> Option<Vec<SonarSample>> {
        let cfg = self.scenario.sensors.sonar.as_ref()?;
        let n = &self.nuisances;
        let mut noise = Stream::new(seed, "reality-sonar");
        let (half_angle, pick) = self
            .concealed
            .iter()
            .find_map(|c| match *c {
                Concealed::SonarBeamWidth {
                    half_angle_deg,
                    pick,
                } => Some((half_angle_deg, pick)),
                _ => None,
            })
            .unwrap_or((cfg.half_angle_deg, EchoPick::Nearest));
        let scale = self
            .concealed
            .iter()
            .find_map(|c| match *c {
                Concealed::SonarSpeedOfSound {
                    air_temperature_c,
                    calibrated_at_c,
                } => Some(speed_of_sound(air_temperature_c) / speed_of_sound(calibrated_at_c)),
                _ => None,
            })
            .unwrap_or(1.0);
        // The range a late echo detection adds, the round trip's delay at the calibration's
        // speed of sound.
        let echo_delay_m: f64 = self
            .concealed
            .iter()
            .map(|c| match *c {
                Concealed::SonarEchoDelay {
                    delay_s,
                    calibrated_at_c,
                } => speed_of_sound(calibrated_at_c) * delay_s / 2.0,
                _ => 0.0,
            })
            .sum();
        let rate = cfg.rate_hz * n.rate_factor;
        let late_s = delay_s(self.concealed, Stamped::Sonar);
        let mut out = Vec::new();
        let mut k = 0u64;
        loop {
            let t = n.sample_phase_s + k as f64 / rate;
            k += 1;
            if t > self.end_s {
                break;
            }
            let (origin, heading) = at_mount(
                self.motion.pose(t),
                cfg.mount.x_m,
                cfg.mount.y_m,
                cfg.mount.yaw_deg,
            );
            let nearest = self.echo(origin, heading, half_angle, pick, cfg.max_range_m);
            let e = self.deviate(&mut noise);
            let jitter = n.timestamp_jitter_s * noise.normal();
            if !nearest.is_finite() {
                continue;
            }
            // The echo time is converted with the calibration temperature's speed of sound;
            // the true echo travels at the air's: the range reads c_cal / c_air too short or long.
            let reading =
                (poly(&cfg.bias, nearest) + poly(&cfg.noise, nearest) * e) / scale + echo_delay_m;
            out.push(SonarSample {
                t_s: (t + late_s + jitter).max(0.0),
                range_m: quantise(reading, n.sonar_resolution_m),
                true_range_m: None,
            });
        }
        out.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        Some(out)
    }

    /// The range the sonar reports from the echoes across its beam (infinite: none), the
    /// beam sampled every 0.25°: within the cone for the nearest echo, over twice the
    /// half-angle for a lobe.
    fn echo(
        &self,
        origin: [f64; 2],
        heading: f64,
        half_angle_deg: f64,
        pick: EchoPick,
        max_range_m: f64,
    ) -> f64 {
        let reach = if pick == EchoPick::Nearest { 1.0 } else { 2.0 };
        let steps = (reach * half_angle_deg / 0.25).ceil() as i64;
        let echoes = (-steps..=steps).filter_map(|j| {
            let off = (j as f64 * 0.25).clamp(-reach * half_angle_deg, reach * half_angle_deg);
            self.world
                .cast(origin, heading + off.to_radians(), max_range_m)
                .map(|h| (off, h.range_m))
        });
        // The main lobe's amplitude `e^{−2 φ²/φ₀²}`, φ₀ the half-angle.
        let lobe = |off: f64| (-2.0 * (off / half_angle_deg.max(0.1)).powi(2)).exp();
        match pick {
            EchoPick::Nearest => echoes.map(|(_, d)| d).fold(f64::INFINITY, f64::min),
            EchoPick::BeamCentroid => {
                let (num, den) = echoes.fold((0.0, 0.0), |(n, w), (off, d)| {
                    let weight = lobe(off) / (d * d);
                    (n + weight * d, w + weight)
                });
                if den > 0.0 {
                    num / den
                } else {
                    f64::INFINITY
                }
            }
            // Detected where the lobe and the spreading clear the amplitude at the half-angle
            // at 2 m.
            EchoPick::Threshold => echoes
                .filter(|&(off, d)| lobe(off) * (2.0 / d).powi(2) >= (-2.0f64).exp())
                .map(|(_, d)| d)
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// The encoders' cumulative travel.
    pub fn odometer(&self, seed: u64) -> Option<Vec<OdometrySample>> {
        let cfg = self.scenario.sensors.odometer.as_ref()?;
        let n = &self.nuisances;
        let mut noise = Stream::new(seed, "reality-odometer");
        let slip = self.concealed.iter().find_map(|c| match *c {
            Concealed::WheelSlip {
                gain_s,
                braking_share,
                traction,
            } => Some((gain_s, braking_share, traction)),
            _ => None,
        });
        let mut lead = [0.0f64; 2];
        let mut last_speed = [0.0f64; 2];
        let mut last_t = 0.0f64;
        let rate = cfg.rate_hz * n.rate_factor;
        let rho = n.encoder_correlation;
        let late_s = delay_s(self.concealed, Stamped::Odometer);
        let mut out = Vec::new();
        let mut k = 0u64;
        loop {
            let t = n.sample_phase_s + k as f64 / rate;
            k += 1;
            if t > self.end_s {
                break;
            }
            let travel = self.motion.travel(t);
            let speed = self.motion.speed(t);
            // The slip grows with each wheel's change of speed since the last sample: at the
            // driving gain while its speed's magnitude grows, the braking share of it while it
            // falls.
            if let Some((gain, share, traction)) = slip {
                let dt = (t - last_t).max(1e-6);
                for w in 0..2 {
                    let dv = speed[w] - last_speed[w];
                    let grows = speed[w].abs() > last_speed[w].abs();
                    let rate = gain * traction.at(dv / dt) * dt;
                    lead[w] += if grows { rate } else { share * rate };
                }
                last_speed = speed;
                last_t = t;
            }
            let (a, b) = (noise.normal(), noise.normal());
            let e = [a, rho * a + (1.0 - rho * rho).sqrt() * b];
            let jitter = n.timestamp_jitter_s * noise.normal();
            let wheel = |w: usize| {
                // The encoders count the wheel's turns and report them at the nominal radius.
                let ground = (travel[w] + lead[w]) / self.radius_scale[w];
                let v = ground * (1.0 + cfg.slip) + cfg.noise_m * e[w];
                quantise(v, cfg.tick_m)
            };
            out.push(OdometrySample {
                t_s: (t + late_s + jitter).max(0.0),
                left_m: wheel(0),
                right_m: wheel(1),
            });
        }
        out.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        Some(out)
    }

    /// The true trajectory at the truth rate, with motion-capture noise.
    pub fn truth(&self, seed: u64) -> Vec<TruthSample> {
        let n = &self.nuisances;
        let mut noise = Stream::new(seed, "reality-truth");
        let count = (self.end_s * n.truth_hz).floor() as usize;
        (0..=count)
            .map(|k| {
                let t = k as f64 / n.truth_hz;
                let p = self.motion.pose(t);
                let yaw = p.yaw + n.truth_noise_rad * noise.normal();
                TruthSample {
                    t_s: t,
                    x_m: p.x + n.truth_noise_m * noise.normal(),
                    y_m: p.y + n.truth_noise_m * noise.normal(),
                    yaw_rad: yaw.sin().atan2(yaw.cos()),
                }
            })
            .collect()
    }
}
