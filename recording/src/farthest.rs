//! The farthest lidar reading of a recording directory, read as streams.

use std::convert::Infallible;

use crate::{
    CommandSample, Error, LidarSample, OdometrySample, RecordingDir, SampleSink, SonarSample,
    TruthSample,
};

impl RecordingDir {
    /// The farthest lidar reading, at least `at_least` metres; the recording is checked on the
    /// way, as a whole read would (see [`RecordingDir::check`]).
    ///
    /// # Errors
    /// The first malformed file, naming it and the line.
    pub fn farthest_lidar_range_m(&self, at_least: f64) -> Result<f64, Error> {
        let mut farthest = Farthest(at_least);
        self.check(&mut farthest)?;
        Ok(farthest.0)
    }
}

struct Farthest(f64);

impl SampleSink for Farthest {
    type Error = Infallible;
    fn lidar(&mut self, r: &LidarSample) -> Result<(), Infallible> {
        self.0 = self.0.max(r.range_m);
        Ok(())
    }
    fn command(&mut self, _: &CommandSample) -> Result<(), Infallible> {
        Ok(())
    }
    fn odometry(&mut self, _: &OdometrySample) -> Result<(), Infallible> {
        Ok(())
    }
    fn sonar(&mut self, _: &SonarSample) -> Result<(), Infallible> {
        Ok(())
    }
    fn truth(&mut self, _: &TruthSample) -> Result<(), Infallible> {
        Ok(())
    }
}
