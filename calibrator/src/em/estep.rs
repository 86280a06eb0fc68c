//! The E-step: the smoother's data set from the samples, and one smoother pass (two for
//! [`EStep::Relinearized`]) at the current parameters.

use super::model::{Data, EmModel, Lin, Params, StepData, ODOMETER, SENSORS, SONAR};
use super::mstep;
use super::options::{EStep, EmOptions, MIN_AUX_READINGS};
use crate::kalman_smoother::{RtsSmoother, SmootherError};
use crate::target_samples::TargetSamples;
use crate::CalibrationError;

/// The data set of the smoother; activates the odometer and sonar slots the options and the
/// recording allow (with enough readings), noting any dropped.
pub(crate) fn build_data(
    samples: &TargetSamples,
    start: f64,
    params: &mut Params,
    opts: &EmOptions,
    notes: &mut Vec<String>,
) -> Data {
    let n = samples.len();
    let odometer: Vec<Option<f64>> = (0..n).map(|k| samples.odometer_distance(k)).collect();
    let sonar: Vec<Option<f64>> = samples.sonar_m.clone().unwrap_or_else(|| vec![None; n]);
    let mut use_slot = |slot: usize, wanted: bool, present: bool, readings: &[Option<f64>]| {
        let count = readings.iter().filter(|y| y.is_some()).count();
        if wanted && present {
            if count >= MIN_AUX_READINGS {
                params.sensors[slot].active = true;
            } else {
                notes.push(format!(
                    "{} not used: {count} readings at the sample instants (at least \
                     {MIN_AUX_READINGS} needed)",
                    mstep::NAMES[slot]
                ));
            }
        }
    };
    use_slot(
        ODOMETER,
        opts.use_odometer,
        samples.odometer_travel_m.is_some(),
        &odometer,
    );
    use_slot(SONAR, opts.use_sonar, samples.sonar_m.is_some(), &sonar);
    let steps = (0..n)
        .map(|k| {
            let readings = [samples.lidar_m[k], odometer[k], sonar[k]];
            let mut y = [0.0; SENSORS];
            let mut has = [false; SENSORS];
            for slot in 0..SENSORS {
                if let (true, Some(v)) = (params.sensors[slot].active, readings[slot]) {
                    y[slot] = v;
                    has[slot] = true;
                }
            }
            StepData {
                y,
                has,
                u: samples.u(k),
            }
        })
        .collect();
    Data {
        steps,
        prior_mean: start + samples.commanded_m[0],
        prior_u: samples.commanded_m[0],
        prior_var: 0.0,
    }
}

/// One E-step: a smoother pass at the linearisation `lin` (and for [`EStep::Relinearized`] a
/// second at the first pass's smoothed state, which then becomes `lin`). Returns the
/// log-likelihood of the last pass.
pub(crate) fn e_step(
    smoother: &mut RtsSmoother<2>,
    data: &Data,
    params: &Params,
    lin: &mut [Lin],
    variant: EStep,
) -> Result<f64, CalibrationError> {
    let pass = |smoother: &mut RtsSmoother<2>, lin: &[Lin]| {
        smoother
            .run(&EmModel {
                data,
                params,
                lin,
                second_order: variant.second_order(),
            })
            .map_err(diverged)
    };
    let mut ll = pass(smoother, lin)?;
    if variant == EStep::Relinearized {
        update_lin(lin, smoother);
        ll = pass(smoother, lin)?;
    }
    Ok(ll)
}

pub(super) fn update_lin(lin: &mut [Lin], smoother: &RtsSmoother<2>) {
    for ((l, m), p) in lin
        .iter_mut()
        .zip(smoother.smoothed_means())
        .zip(smoother.smoothed_covs())
    {
        *l = Lin::from_smoothed(m, p);
    }
}

fn diverged(err: SmootherError) -> CalibrationError {
    CalibrationError::Diverged(format!("the Kalman smoother failed: {err}"))
}
