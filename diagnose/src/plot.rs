//! The plot data of a diagnosis: one sensor's held-out residuals against the located variable
//! and against time, before and after the fix. `show` draws them.

use hilsim_recording::Pose;

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
    /// The located range of the variable, when there is one (a category's value twice, for a
    /// categorical variable).
    pub highlight: Option<(f64, f64)>,
    /// Where in the world each reading was, metres (NaN when unknown): the lidar's or the
    /// sonar's hit point, the robot's position for the odometer and the drive.
    pub positions: Vec<[f64; 2]>,
    /// A title.
    pub title: String,
}

/// Where the residuals "before the fix" are taken for an effect seen through the path (a lidar
/// mount or delay the estimated path took up, seen by the sonar and the encoders): the path
/// that took it up and the sensors' data along it. The fix is the path put back by the effect,
/// so "after" is the nominal model along the diagnosis's final path.
pub(crate) struct Before<'c, 'a> {
    pub ctx: &'c Context<'a>,
    pub data: &'c [SensorData],
}

/// The plots of a diagnosis: the located sensor's held-out residuals against the located
/// variable and against time, before and after the fix.
pub(crate) fn plots(
    ctx: &Context<'_>,
    data: &[SensorData],
    located: Option<&Evidence>,
    fitted: Option<&CandidateFit>,
    through_path: Option<Before<'_, '_>>,
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
    let nominal = |ctx: &Context<'_>, d: &SensorData| -> Vec<f64> {
        fits(
            d,
            &rows,
            &ctx.predict_unconditioned(d, &Hypothesis::nominal(), &rows),
        )
        .iter()
        .map(|f| f.residual)
        .collect()
    };
    // Along the path that took the effect up, the same readings (the data of one recording).
    let took_up = through_path.and_then(|b| {
        let d_before = b.data.iter().find(|x| x.sensor == sensor)?;
        (d_before.len() == d.len()).then(|| nominal(b.ctx, d_before))
    });
    let (before, after) = match took_up {
        Some(before) => (before, Some(nominal(ctx, d))),
        None => (
            nominal(ctx, d),
            fitted.filter(|f| f.effect.sensor() == sensor).map(|f| {
                let h = Hypothesis::with(f.effect, f.params.clone());
                fits(d, &rows, &ctx.predict_unconditioned(d, &h, &rows))
                    .iter()
                    .map(|f| f.residual)
                    .collect::<Vec<f64>>()
            }),
        ),
    };
    let positions = world_positions(ctx, d, &rows);
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
            let located_here = located.filter(|l| l.covariate == Some(c));
            // A located category is named in the evidence's place ("board 1 (dark)").
            let located_category = located_here.and_then(|l| {
                categories
                    .iter()
                    .find(|(_, name)| l.place.contains(name.as_str()))
                    .map(|(v, _)| (*v, *v))
            });
            Some(PlotData {
                sensor,
                variable: c,
                x: rows.iter().map(|&i| values[i]).collect(),
                before: before.clone(),
                after: after.clone(),
                highlight: located_here
                    .and_then(|l| l.range)
                    .or(if categories.is_empty() {
                        None
                    } else {
                        located_category
                    }),
                categories,
                positions: positions.clone(),
                title: format!("{sensor} residuals against {} (held-out half)", c.name()),
            })
        })
        .collect()
}

/// Where in the world each of `rows` was: a range sensor's hit point (its true range along its
/// beam from the trajectory's pose at the reading's time), else the robot's position.
fn world_positions(ctx: &Context<'_>, d: &SensorData, rows: &[usize]) -> Vec<[f64; 2]> {
    let meta = &ctx.recording.meta;
    let range = d.covariate(Covariate::Range);
    let bearing = d.covariate(Covariate::Bearing);
    rows.iter()
        .map(|&i| {
            let robot = ctx.trajectory.pose_at(d.t[i]);
            let hit = |mount: Pose, beam_deg: f64| -> Option<[f64; 2]> {
                let r = range?.get(i).copied().filter(|r| r.is_finite())?;
                let sensor = robot.compose(mount.x, mount.y, mount.yaw);
                let b = beam_deg.to_radians();
                Some(sensor.transform([r * b.cos(), r * b.sin()]))
            };
            let point = match d.sensor {
                Sensor::Lidar => meta.lidar.and_then(|m| {
                    let beam = bearing?.get(i).copied()?;
                    hit(Pose::new(m.x_m, m.y_m, m.yaw_rad()), beam)
                }),
                Sensor::Sonar => meta
                    .sonar
                    .as_ref()
                    .and_then(|m| hit(Pose::new(m.x_m, m.y_m, m.yaw_deg.to_radians()), 0.0)),
                Sensor::Odometer | Sensor::Drive => Some([robot.x, robot.y]),
            };
            point.unwrap_or([f64::NAN; 2])
        })
        .collect()
}
