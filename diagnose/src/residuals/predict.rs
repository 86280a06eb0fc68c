//! A sensor's readings predicted under a hypothesis.

use super::data::{Context, Predictive, Queries, SensorData};
use super::drive_filter::drive_predictions;
use super::path_error::along_estimated_path;
use crate::physics::{Hypothesis, LidarQuery};
use crate::trajectory::Trajectory;
use smallvec::smallvec;

impl Context<'_> {
    /// The predictive distributions of `rows` of `data` under `h`.
    pub fn predict(&self, data: &SensorData, h: &Hypothesis, rows: &[usize]) -> Vec<Predictive> {
        self.predict_as(data, h, rows, true)
    }

    /// Whether [`Context::predict`] conditions `data`'s readings on those before them for an
    /// error it shares between them (the encoders along a path estimated from the lidar): its
    /// predictive means then follow the readings, and an effect's size is the change of
    /// [`Context::predict_unconditioned`]'s instead.
    pub fn conditions(&self, data: &SensorData) -> bool {
        self.estimated && matches!(data.queries, Queries::Odometer(_))
    }

    /// As [`Context::predict`], the shared error left independent in every reading: what the
    /// physics predicts of each reading on its own.
    pub fn predict_unconditioned(
        &self,
        data: &SensorData,
        h: &Hypothesis,
        rows: &[usize],
    ) -> Vec<Predictive> {
        self.predict_as(data, h, rows, false)
    }

    fn predict_as(
        &self,
        data: &SensorData,
        h: &Hypothesis,
        rows: &[usize],
        conditioned: bool,
    ) -> Vec<Predictive> {
        match &data.queries {
            Queries::Lidar(q) => {
                let qs: Vec<LidarQuery> = rows.iter().map(|&i| q[i]).collect();
                self.physics
                    .lidar(self.trajectory, &qs, h)
                    .into_iter()
                    .map(|p| p.components.into_iter().map(|g| self.widen(g)).collect())
                    .collect()
            }
            Queries::Sonar(times) => {
                let ts: Vec<f64> = rows.iter().map(|&i| times[i]).collect();
                let moved = self.robot_path(h);
                self.physics
                    .sonar(moved.as_ref().unwrap_or(self.trajectory), &ts, h)
                    .into_iter()
                    .map(|p| p.reading.into_iter().map(|g| self.widen(g)).collect())
                    .collect()
            }
            Queries::Odometer(times) => {
                let moved = self.robot_path(h);
                let path = moved.as_ref().unwrap_or(self.trajectory);
                // The trajectory's own position noise enters each wheel's travel: independent
                // errors for a recorded one; for one estimated from the lidar, an error shared
                // by neighbouring readings, so every reading is predicted given those before it.
                let extra = self.position_sd_m * self.position_sd_m;
                if conditioned && self.conditions(data) {
                    let preds = self.physics.odometry(path, times, h);
                    let physics: Vec<_> = (0..data.len())
                        .map(|i| preds[i / 2].wheels[i % 2])
                        .collect();
                    let t: Vec<f64> = (0..data.len()).map(|i| times[i / 2]).collect();
                    let train: Vec<bool> = data.heldout.iter().map(|h| !h).collect();
                    let all =
                        along_estimated_path(&physics, &data.y, &t, &train, self.position_sd_m);
                    return rows.iter().map(|&i| smallvec![all[i]]).collect();
                }
                let ts: Vec<f64> = rows.iter().map(|&i| times[i / 2]).collect();
                let preds = self.physics.odometry(path, &ts, h);
                rows.iter()
                    .zip(preds)
                    .map(|(&i, p)| {
                        let mut g = p.wheels[i % 2];
                        g.sd_m = (g.sd_m * g.sd_m + extra).sqrt();
                        smallvec![g]
                    })
                    .collect()
            }
            Queries::OdometerSpans { spans, noise } => {
                let ends: Vec<f64> = rows
                    .iter()
                    .flat_map(|&i| [spans[i / 2].0, spans[i / 2].1])
                    .collect();
                let preds = self.physics.odometry(self.trajectory, &ends, h);
                rows.iter()
                    .zip(preds.chunks_exact(2))
                    .map(|(&i, ends)| {
                        let travel =
                            [0, 1].map(|w| ends[1].wheels[w].mean_m - ends[0].wheels[w].mean_m);
                        // Each end's readings carry the encoders' noise, the wheels' own; the
                        // span, the truth's departure from them.
                        let encoders: f64 = ends
                            .iter()
                            .flat_map(|e| e.wheels.iter().map(|g| g.sd_m * g.sd_m))
                            .sum();
                        let mut g = ends[1].wheels[0];
                        g.mean_m = if i % 2 == 0 {
                            (travel[0] + travel[1]) / 2.0
                        } else {
                            travel[1] - travel[0]
                        };
                        let encoders = if i % 2 == 0 { encoders / 4.0 } else { encoders };
                        g.sd_m = (encoders + noise[i % 2].variance(data.y[i])).sqrt();
                        smallvec![g]
                    })
                    .collect()
            }
            Queries::Drive(windows) => {
                let predicted = self.physics.drive(&self.recording.commands, self.end_s, h);
                let Ok(path) = Trajectory::new(&predicted) else {
                    return rows.iter().map(|_| Predictive::new()).collect();
                };
                let travel = path.wheel_travel(self.physics.declared().wheel_base_m);
                let increments: Vec<f64> = (0..data.len())
                    .map(|i| {
                        let (a, b) = windows[i / 2];
                        let (wa, wb) = (path.interpolate(&travel, a), path.interpolate(&travel, b));
                        wb[i % 2] - wa[i % 2]
                    })
                    .collect();
                // Two differences of the trajectory's positions per window; against an
                // estimate the path follows the encoders between the lidar's corrections, so a
                // window's travel carries the difference of two encoder readings' noise too.
                let mut noise_var = 2.0 * self.position_sd_m * self.position_sd_m;
                if self.estimated {
                    let encoder_sd = self
                        .physics
                        .odometry(self.trajectory, &[0.0], &Hypothesis::nominal())
                        .first()
                        .map_or(0.0, |p| p.wheels[0].sd_m);
                    noise_var += 2.0 * encoder_sd * encoder_sd;
                }
                let starts: Vec<f64> = windows.iter().map(|w| w.0).collect();
                let all = drive_predictions(
                    &increments,
                    &data.y,
                    &starts,
                    self.physics.declared().actuation,
                    noise_var,
                );
                rows.iter().map(|&i| smallvec![all[i]]).collect()
            }
        }
    }
}
