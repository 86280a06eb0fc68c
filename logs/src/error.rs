//! The one error type of the log readers.

/// Why a log could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LogError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// What the system said.
        source: std::io::Error,
    },
    /// The file (after decompression) is larger than a reader holds.
    #[error("{path}: more than {limit} bytes of text; split the log")]
    TooLarge {
        /// The file.
        path: String,
        /// The limit, bytes.
        limit: u64,
    },
    /// The file is not UTF-8 text.
    #[error("{path}: not text (not UTF-8)")]
    NotText {
        /// The file.
        path: String,
    },
    /// The log has more lines than a reader holds.
    #[error("{origin}: more than {limit} lines; split the log")]
    TooManyLines {
        /// The log.
        origin: String,
        /// The limit.
        limit: usize,
    },
    /// A line that cannot be read, in a format that allows no bad line.
    #[error("{origin}:{line}: {message}")]
    Line {
        /// The log.
        origin: String,
        /// The line's number, from 1.
        line: usize,
        /// What was expected.
        message: String,
    },
    /// The log holds too little to make a recording.
    #[error("{origin}: {message}")]
    Empty {
        /// The log.
        origin: String,
        /// What is missing.
        message: String,
    },
    /// Poses asked of a CoreSLAM log, which has encoder counts.
    #[error("--poses is for CARMEN logs; a CoreSLAM log has encoder counts, not poses")]
    PosesOfCoreSlam,
    /// The recording cannot be written where asked.
    #[error(transparent)]
    Recording(#[from] hilsim_recording::Error),
    /// An option out of its range.
    #[error("option {name}: {message}")]
    Option {
        /// The option.
        name: &'static str,
        /// What it must be.
        message: String,
    },
}
