//! `--shard I/K`: the runs one of K machines makes, with no coordination between them.

use std::fmt;
use std::str::FromStr;

use crate::Error;

/// Shard `index` of `count` (1-based): the runs `r` with `r mod count = index − 1`.
///
/// ```
/// use hilsim_dataset::Shard;
/// let s: Shard = "2/3".parse()?;
/// assert_eq!((0..7).filter(|&r| s.contains(r)).collect::<Vec<_>>(), [1, 4]);
/// assert!("0/3".parse::<Shard>().is_err());
/// # Ok::<(), hilsim_dataset::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    index: u64,
    count: u64,
}

impl Shard {
    /// Every run: shard 1 of 1.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// Shard `index` (1-based) of `count`.
    ///
    /// # Errors
    /// `count` is 0, or `index` is not in `1..=count`.
    pub fn new(index: u64, count: u64) -> Result<Self, Error> {
        if count == 0 || index == 0 || index > count {
            return Err(Error::Shard {
                spec: format!("{index}/{count}"),
                message: EXPECTED.to_string(),
            });
        }
        Ok(Self { index, count })
    }

    /// The shard's number, 1-based.
    #[must_use]
    pub fn index(self) -> u64 {
        self.index
    }

    /// The number of shards.
    #[must_use]
    pub fn count(self) -> u64 {
        self.count
    }

    /// Whether run `run` belongs to this shard.
    #[must_use]
    pub fn contains(self, run: u64) -> bool {
        run % self.count == self.index - 1
    }

    /// Whether this is the whole dataset (1/1).
    #[must_use]
    pub fn is_all(self) -> bool {
        self.count == 1
    }
}

const EXPECTED: &str = "expected I/K with 1 ≤ I ≤ K, e.g. 1/4 (shards count from 1: with a \
                        0-based array index use $((INDEX + 1))/K)";

impl FromStr for Shard {
    type Err = Error;

    fn from_str(spec: &str) -> Result<Self, Error> {
        let bad = || Error::Shard {
            spec: spec.to_string(),
            message: EXPECTED.to_string(),
        };
        let (i, k) = spec.split_once('/').ok_or_else(bad)?;
        let parse = |s: &str| {
            // Digits only: `u64::from_str` would also take a leading `+`.
            if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
                return Err(bad());
            }
            s.parse::<u64>().map_err(|_| bad())
        };
        let (index, count) = (parse(i)?, parse(k)?);
        Shard::new(index, count).map_err(|_| bad())
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_runs() {
        let k = 4;
        let shards: Vec<Shard> = (1..=k).map(|i| Shard::new(i, k).unwrap()).collect();
        for r in 0..100 {
            assert_eq!(shards.iter().filter(|s| s.contains(r)).count(), 1);
        }
    }

    #[test]
    fn malformed_shards_are_refused() {
        for bad in [
            "", "1", "1/", "/2", "0/2", "3/2", "1/0", "a/b", "+1/2", "1/2/3", "-1/2",
        ] {
            let err = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(
                err.starts_with(&format!("--shard `{bad}`: expected I/K")),
                "{err}"
            );
        }
        assert_eq!("3/3".parse::<Shard>().unwrap().to_string(), "3/3");
    }
}
