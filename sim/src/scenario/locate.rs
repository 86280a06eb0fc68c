//! Maps a key path such as `world.cylinders[2].radius` back to its line in the TOML source, so
//! that checks made after deserialising can still name the line.

use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// One step of a key path.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Key {
    /// A table key.
    Name(&'static str),
    /// An array element.
    Index(usize),
}

/// Builds a path: `path!["world", "cylinders", 2, "radius"]`.
macro_rules! key_path {
    ($($k:expr),* $(,)?) => { vec![$($crate::scenario::locate::Key::from($k)),*] };
}
pub(crate) use key_path;

impl From<&'static str> for Key {
    fn from(s: &'static str) -> Self {
        Key::Name(s)
    }
}

impl From<usize> for Key {
    fn from(i: usize) -> Self {
        Key::Index(i)
    }
}

/// Renders a path as written in the file's terms: `world.cylinders[2].radius`.
pub(crate) fn display(path: &[Key]) -> String {
    let mut s = String::new();
    for k in path {
        match k {
            Key::Name(n) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(n);
            }
            Key::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// The 1-based line of the deepest part of `path` present in `source`.
pub(crate) fn line_of(source: &str, path: &[Key]) -> Option<usize> {
    let doc = DeTable::parse(source).ok()?;
    let mut offset = doc.span().start;
    let mut value: Option<&Spanned<DeValue<'_>>> = None;
    let mut table: Option<&DeTable<'_>> = Some(doc.get_ref());
    for key in path {
        let next = match (key, table, value.map(|v| v.get_ref())) {
            (Key::Name(n), Some(t), _) => t.iter().find(|(k, _)| k.get_ref() == n).map(|(_, v)| v),
            (Key::Index(i), _, Some(DeValue::Array(a))) => a.get(*i),
            _ => None,
        };
        let Some(next) = next else { break };
        offset = next.span().start;
        table = match next.get_ref() {
            DeValue::Table(t) => Some(t),
            _ => None,
        };
        value = Some(next);
    }
    Some(line_at(source, offset))
}

/// The 1-based line holding byte `offset`.
pub(crate) fn line_at(source: &str, offset: usize) -> usize {
    let end = offset.min(source.len());
    1 + source.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}
