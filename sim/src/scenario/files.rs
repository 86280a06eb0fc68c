//! Reading the files a scenario names beside it (`[world] map`, `[robot] path`,
//! `[sensors.lidar] schedule`), relative to the scenario file's directory.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::error::ScenarioError;
use super::schema::{Scenario, ScenarioFiles};
use crate::occupancy::OccupancyMap;
use crate::recorded_path::RecordedPath;
use crate::scan_schedule::ScanSchedule;

/// Where a file named in the scenario at `origin` is: relative to the scenario's directory.
#[must_use]
pub fn beside(origin: &Path, file: &Path) -> PathBuf {
    if file.is_absolute() {
        file.to_path_buf()
    } else {
        origin.parent().unwrap_or(Path::new("")).join(file)
    }
}

/// Reads every file `scenario` names; its errors name the file read.
pub(super) fn read(scenario: &Scenario, origin: &Path) -> Result<ScenarioFiles, ScenarioError> {
    let map = match &scenario.world.map {
        Some(file) => {
            let at = beside(origin, file);
            let map = OccupancyMap::load(&at).map_err(|err| ScenarioError {
                file: at.clone(),
                line: None,
                message: err.to_string(),
            })?;
            Some(Arc::new(map))
        }
        None => None,
    };
    let path = match &scenario.robot.path {
        Some(file) => Some(Arc::new(RecordedPath::load(&beside(origin, file))?)),
        None => None,
    };
    let schedule = match scenario
        .sensors
        .lidar
        .as_ref()
        .and_then(|l| l.schedule.as_ref())
    {
        Some(file) => Some(Arc::new(ScanSchedule::load(&beside(origin, file))?)),
        None => None,
    };
    Ok(ScenarioFiles {
        map,
        path,
        schedule,
    })
}
