//! The vocabulary of the scenario checks: a failed check names a key path and what was
//! expected, quoting numbers as the file spells them.

use super::locate::Key;

/// A failed check: where (a key path) and what was expected.
pub(super) struct Invalid {
    pub(super) path: Vec<Key>,
    pub(super) message: String,
}

pub(super) type Check = Result<(), Invalid>;

pub(super) fn fail(path: Vec<Key>, message: impl Into<String>) -> Check {
    Err(Invalid {
        path,
        message: message.into(),
    })
}

/// A number as TOML spells it (`nan`, `inf`, `1e300`), so that messages quote the file's own
/// words: very large or very small magnitudes in exponent form, not hundreds of digits.
pub(super) fn toml_number(v: f64) -> String {
    if v.is_nan() {
        "nan".to_string()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.to_string()
    } else if v != 0.0 && !(1e-6..1e16).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}
