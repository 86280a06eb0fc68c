//! The plot data of a diagnosis: one sensor's held-out residuals against the located variable
//! and against time, before and after the fix. `show` draws them.

use crate::catalogue::Sensor;
use crate::explain::CandidateFit;
use crate::locate::Evidence;
use crate::physics::Hypothesis;
use crate::residuals::{fits, Context, Covariate, SensorData};

/// Points a plot shows at most (evenly thinned).
const MAX_POINTS: usize = 2500;

/// Residuals of one sensor's held-out readings against one variable.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotData {
    /// The sensor.
    pub sensor: Sensor,
    /// The variable on the x axis.
    pub variable: Covariate,
    /// Names of the categories, for a categorical variable (indexed by value).
    pub categories: Vec<(f64, String)>,
    /// The variable's values.
    pub x: Vec<f64>,
    /// Residuals under the nominal model, metres.
    pub before: Vec<f64>,
    /// Residuals under the fitted effect, metres (when one is named).
    pub after: Option<Vec<f64>>,
    /// The located range of the variable, when there is one.
    pub highlight: Option<(f64, f64)>,
    /// A title.
    pub title: String,
}

/// The plots of a diagnosis: the located sensor's held-out residuals against the located
/// variable and against time, before and after the fix.
pub(crate) fn plots(
    ctx: &Context<'_>,
    data: &[SensorData],
    located: Option<&Evidence>,
    fitted: Option<&CandidateFit>,
) -> Vec<PlotData> {
    let Some(sensor) = located
        .map(|l| l.sensor)
        .or(fitted.map(|f| f.effect.sensor()))
    else {
        return Vec::new();
    };
    let Some(d) = data.iter().find(|d| d.sensor == sensor) else {
        return Vec::new();
    };
    let held = d.rows(Some(true));
    let stride = held.len().div_ceil(MAX_POINTS).max(1);
    let rows: Vec<usize> = held.into_iter().step_by(stride).collect();
    let before: Vec<f64> = fits(d, &rows, &ctx.predict(d, &Hypothesis::nominal(), &rows))
        .iter()
        .map(|f| f.residual)
        .collect();
    let after = fitted.filter(|f| f.effect.sensor() == sensor).map(|f| {
        let h = Hypothesis::with(f.effect, f.params.clone());
        fits(d, &rows, &ctx.predict(d, &h, &rows))
            .iter()
            .map(|f| f.residual)
            .collect::<Vec<f64>>()
    });
    let mut variables = Vec::new();
    if let Some(c) = located.and_then(|l| l.covariate) {
        variables.push(c);
    }
    if !variables.contains(&Covariate::Time) {
        variables.push(Covariate::Time);
    }
    variables
        .into_iter()
        .filter_map(|c| {
            let values = d.covariate(c)?;
            let categories = if c == Covariate::Object {
                let mut ids: Vec<f64> = rows
                    .iter()
                    .map(|&i| values[i])
                    .filter(|v| v.is_finite())
                    .collect();
                ids.sort_by(f64::total_cmp);
                ids.dedup();
                ids.into_iter()
                    .map(|v| (v, ctx.physics.object_name(v as u32)))
                    .collect()
            } else if c == Covariate::Edge {
                vec![
                    (0.0, "away from edges".into()),
                    (1.0, "near an edge".into()),
                ]
            } else {
                Vec::new()
            };
            Some(PlotData {
                sensor,
                variable: c,
                categories,
                x: rows.iter().map(|&i| values[i]).collect(),
                before: before.clone(),
                after: after.clone(),
                highlight: located
                    .filter(|l| l.covariate == Some(c))
                    .and_then(|l| l.range),
                title: format!("{sensor} residuals against {} (held-out half)", c.name()),
            })
        })
        .collect()
}
