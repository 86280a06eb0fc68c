//! A lidar other than the XV-11 — readings 0.5° apart (720 a revolution) or 1,080 a
//! revolution — calibrates with every method (EM, ground truth, landmarks), smooths, and the
//! landmark detector finds the cylinders. Before, a reading's angle was a whole degree and a
//! stop's scan had 360 beams.

use std::sync::OnceLock;

use hilsim_calibrator::em::EmOptions;
use hilsim_calibrator::landmarks::{analyse, Options};
use hilsim_calibrator::target_samples::SampleOptions;
use hilsim_calibrator::{calibrate, smoothing, Method};
use hilsim_lidar_emulator::{Emulation, RangeModel};
use hilsim_recording::{wrap_angle, LidarSample, Pose, Recording};
use hilsim_sim::{Scenario, World};
use rand::SeedableRng;

fn scenario(name: &str) -> Scenario {
    let path = format!("{}/../scenarios/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    Scenario::load(path.as_ref()).expect("a checked-in scenario loads")
}

/// The true pose at `t`, interpolated between the truth rows around it.
fn pose_at(rec: &Recording, t: f64) -> Pose {
    let truth = rec
        .truth
        .as_deref()
        .expect("simulated recordings have truth");
    let i = truth
        .partition_point(|p| p.t_s <= t)
        .clamp(1, truth.len() - 1);
    let (a, b) = (&truth[i - 1], &truth[i]);
    let f = ((t - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0);
    Pose::new(
        a.x_m + f * (b.x_m - a.x_m),
        a.y_m + f * (b.y_m - a.y_m),
        a.yaw_rad + f * wrap_angle(b.yaw_rad - a.yaw_rad),
    )
}

/// The scenario's run with its XV-11 replaced by a lidar of `per_rev` readings a revolution at
/// `360/per_rev` degree steps, on the XV-11's revolutions (5 Hz), each reading a ray cast from
/// the true pose at its instant and drawn from the scenario's range model (eq. 2), to the
/// millimetre; a reading out of the lidar's range is invalid.
fn other_lidar(name: &str, per_rev: usize, seed: u64) -> Recording {
    let s = scenario(name);
    let mut rec = Emulation::new(&s, s.seed).expect("sensors").run().recording;
    let world = World::new(&s);
    let config = s.sensors.lidar.as_ref().expect("a lidar");
    let model = RangeModel::builder()
        .bias(&config.bias)
        .noise(&config.noise)
        .build()
        .expect("the scenario's model");
    let mount = rec.meta.lidar.unwrap_or_default();
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    let xv11 = rec.lidar.take().expect("a lidar table");
    let starts: Vec<(u64, f64)> = xv11
        .iter()
        .filter(|r| r.angle_deg == 0.0)
        .map(|r| (r.rev, r.t_s))
        .collect();
    let mut lidar = Vec::with_capacity(starts.len() * per_rev);
    for w in starts.windows(2) {
        let ((rev, t0), (_, t1)) = (w[0], w[1]);
        for i in 0..per_rev {
            let angle_deg = i as f64 * 360.0 / per_rev as f64;
            let t_s = ((t0 + (t1 - t0) * i as f64 / per_rev as f64) * 1e6).round() / 1e6;
            let sensor = mount.in_world(&pose_at(&rec, t_s));
            let heading = sensor.yaw + angle_deg.to_radians();
            let hit = world.cast_ray([sensor.x, sensor.y], heading, config.max_range_m);
            let reading = hit
                .map(|h| (model.sample(h.distance, &mut rng) * 1e3).round() / 1e3)
                .filter(|r| (config.min_range_m..=config.max_range_m).contains(r));
            lidar.push(LidarSample {
                t_s,
                rev,
                angle_deg,
                range_m: reading.unwrap_or(0.0),
                strength: if reading.is_some() { 200 } else { 0 },
                invalid: reading.is_none(),
                warning: false,
                true_range_m: None,
            });
        }
    }
    rec.lidar = Some(lidar);
    rec
}

fn half_degree() -> &'static Recording {
    static R: OnceLock<Recording> = OnceLock::new();
    R.get_or_init(|| other_lidar("landmarks-5", 720, 17))
}

fn readings_1080() -> &'static Recording {
    static R: OnceLock<Recording> = OnceLock::new();
    R.get_or_init(|| other_lidar("landmarks-5", 1080, 18))
}

/// The landmark paper's pipeline on the raw scans of a finer lidar: the five cylinders and
/// nothing else, and the configured model recovered as well as from the XV-11
/// (`landmarks_recording`: MSE ratio above 10, order 2).
#[test]
fn the_landmark_detector_and_calibration_take_any_angular_grid() {
    for (rec, what) in [(half_degree(), "0.5°"), (readings_1080(), "1080 readings")] {
        let analysis = analyse(rec, &Options::default()).expect(what);
        assert_eq!(analysis.tracks.len(), 5, "{what}");
        let cal = &analysis.calibration;
        assert_eq!(cal.landmarks.as_ref().map(Vec::len), Some(5), "{what}");
        let m = cal.metrics.expect("truth scores it");
        assert!(m.mse_ratio() > 10.0, "{what}: MSE ratio {}", m.mse_ratio());
        let alpha = &cal.sensors[&hilsim_recording::Sensor::Lidar].alpha;
        // f̂(2 m) within 5 cm of the configured bias at 2 m (as for the XV-11).
        let configured = [0.0525, 0.8838, 0.0584];
        let at = |a: &[f64]| a.iter().rev().fold(0.0, |acc, c| acc * 2.0 + c);
        assert!(
            (at(alpha) - at(&configured)).abs() < 0.05,
            "{what}: {alpha:?}"
        );
    }
}

/// EM and the ground-truth baseline follow the beam straight ahead (0° is a reading of both
/// grids), and a trained calibration smooths a recording of the finer lidar.
#[test]
fn em_groundtruth_and_smoothing_take_any_angular_grid() {
    for per_rev in [720, 1080] {
        let rec = other_lidar("straight-board", per_rev, 7);
        let target = SampleOptions::default();
        let truth = calibrate(&rec, Method::Groundtruth, target).expect("groundtruth");
        let em = calibrate(&rec, Method::Em, target).expect("em");
        for cal in [&truth, &em] {
            let m = cal.metrics.expect("truth scores it");
            let lidar = m.lidar_model.expect("the lidar model's own figures");
            assert!(
                lidar.mse_ratio > 3.0,
                "{per_rev} readings, {:?}: lidar MSE ratio {}",
                cal.method,
                lidar.mse_ratio
            );
        }
        let smoothed = smoothing::smooth(&rec, &em, &EmOptions::default()).expect("smooths");
        let revolutions = rec
            .lidar
            .as_ref()
            .map_or(0, |l| l.last().map_or(0, |r| r.rev));
        assert!(
            smoothed.len() as u64 + 2 >= revolutions,
            "{per_rev}: {}",
            smoothed.len()
        );
    }
}
