//! The tables merged by time into the order the messages are written, holding one row of each
//! table (one revolution of the lidar's) ahead: what an export holds does not grow with the
//! recording.

use hilsim_recording::{CommandSample, LidarSample, OdometrySample, SonarSample, TruthSample};

use super::source::Stream;
use crate::Error;

/// The most readings one `/scan` message holds: a longer revolution (rows of one `rev`) is sent
/// as several scans. A Neato revolution has 360; the bound keeps what is held for a scan small
/// whatever the file says.
pub const MAX_SCAN_READINGS: usize = 100_000;

/// A stream with its next sample taken out and looked at.
pub(super) struct Head<'a, T> {
    pub(super) next: Option<T>,
    rest: Stream<'a, T>,
}

impl<'a, T> Head<'a, T> {
    pub(super) fn new(mut rest: Stream<'a, T>) -> Result<Self, Error> {
        let next = rest.next().transpose()?;
        Ok(Self { next, rest })
    }

    /// The next sample, the one after it taken out.
    pub(super) fn take(&mut self) -> Result<Option<T>, Error> {
        let next = self.rest.next().transpose()?;
        Ok(std::mem::replace(&mut self.next, next))
    }
}

/// The lidar's rows a revolution at a time (consecutive rows of one `rev`, at most
/// [`MAX_SCAN_READINGS`]).
pub(super) struct Revolutions<'a> {
    rows: Head<'a, LidarSample>,
    pub(super) current: Vec<LidarSample>,
}

impl<'a> Revolutions<'a> {
    pub(super) fn new(rows: Stream<'a, LidarSample>) -> Result<Self, Error> {
        let mut revolutions = Self {
            rows: Head::new(rows)?,
            current: Vec::new(),
        };
        revolutions.advance()?;
        Ok(revolutions)
    }

    /// Moves to the next revolution (empty at the end).
    pub(super) fn advance(&mut self) -> Result<(), Error> {
        self.current.clear();
        while let Some(next) = &self.rows.next {
            let full = self.current.len() == MAX_SCAN_READINGS;
            if full
                || self
                    .current
                    .first()
                    .is_some_and(|first| first.rev != next.rev)
            {
                break;
            }
            self.current.extend(self.rows.take()?);
        }
        Ok(())
    }
}

/// What the next message is made from.
pub(super) enum Next {
    /// The revolution [`Merge::revolution`] holds.
    Scan,
    Command(CommandSample),
    Odometry(OdometrySample),
    Sonar(SonarSample),
    Truth(TruthSample),
}

/// The tables merged by time, holding one row of each (one revolution of the lidar's) ahead.
/// At one time a scan comes first, then a command, the odometry, the sonar and the truth (as a
/// stable sort of the tables in that order would put them).
pub(super) struct Merge<'a> {
    scans: Revolutions<'a>,
    /// Whether the revolution held has been given out (it is left until the next call).
    scan_given: bool,
    commands: Head<'a, CommandSample>,
    odometry: Head<'a, OdometrySample>,
    sonar: Head<'a, SonarSample>,
    truth: Head<'a, TruthSample>,
}

impl<'a> Merge<'a> {
    pub(super) fn new(
        lidar: Stream<'a, LidarSample>,
        commands: Stream<'a, CommandSample>,
        odometry: Stream<'a, OdometrySample>,
        sonar: Stream<'a, SonarSample>,
        truth: Stream<'a, TruthSample>,
    ) -> Result<Self, Error> {
        Ok(Self {
            scans: Revolutions::new(lidar)?,
            scan_given: false,
            commands: Head::new(commands)?,
            odometry: Head::new(odometry)?,
            sonar: Head::new(sonar)?,
            truth: Head::new(truth)?,
        })
    }

    /// The revolution of the last [`Next::Scan`].
    pub(super) fn revolution(&self) -> &[LidarSample] {
        &self.scans.current
    }

    /// The next message's time and what it is made from; `None` at the end of every table.
    pub(super) fn next(&mut self) -> Result<Option<(f64, Next)>, Error> {
        if std::mem::take(&mut self.scan_given) {
            self.scans.advance()?;
        }
        let times = [
            self.scans.current.first().map(|s| s.t_s),
            self.commands.next.map(|c| c.t_s),
            self.odometry.next.map(|o| o.t_s),
            self.sonar.next.map(|s| s.t_s),
            self.truth.next.map(|p| p.t_s),
        ];
        // The earliest time; a tie goes to the first in `times`' order.
        let mut earliest: Option<(usize, f64)> = None;
        for (i, t) in times.into_iter().enumerate() {
            if let Some(t) = t {
                if earliest.is_none_or(|(_, e)| t.total_cmp(&e).is_lt()) {
                    earliest = Some((i, t));
                }
            }
        }
        let Some((which, t_s)) = earliest else {
            return Ok(None);
        };
        let next = match which {
            0 => {
                self.scan_given = true;
                Some(Next::Scan)
            }
            1 => self.commands.take()?.map(Next::Command),
            2 => self.odometry.take()?.map(Next::Odometry),
            3 => self.sonar.take()?.map(Next::Sonar),
            _ => self.truth.take()?.map(Next::Truth),
        };
        Ok(next.map(|next| (t_s, next)))
    }
}
