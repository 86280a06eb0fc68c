//! map_server's YAML: a handful of flat `key: value` lines, read by hand (the workspace has no
//! YAML library, and this file needs none of YAML beyond scalars, one list and comments).
//!
//! ```yaml
//! image: map.pgm
//! resolution: 0.05
//! origin: [-10.0, -10.0, 0.0]   # or a block list, one `- value` a line
//! negate: 0                     # 0/1 or true/false
//! occupied_thresh: 0.65
//! free_thresh: 0.196
//! mode: trinary                 # optional: trinary (the default), scale or raw
//! ```
//!
//! Other keys are ignored, as map_server ignores them; a key given twice is an error.

use std::path::Path;

use super::pixels::{Mode, Rules};
use super::MapError;

/// What a map's YAML says.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MapYaml {
    pub image: String,
    pub resolution_m: f64,
    pub origin: [f64; 2],
    pub rules: Rules,
}

/// One key's value and the line it is on.
struct Entry {
    line: usize,
    value: Value,
}

enum Value {
    Scalar(String),
    List(Vec<String>),
}

/// Reads the YAML `text` of the file `path`.
pub(super) fn parse(text: &str, path: &Path) -> Result<MapYaml, MapError> {
    let fail = |line: usize, message: String| MapError::format(path, Some(line), message);
    let mut entries: Vec<(String, Entry)> = Vec::new();
    // The key whose block list is being read, if any.
    let mut open_list: Option<usize> = None;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = strip_comment(raw);
        let trimmed = content.trim();
        if trimmed.is_empty() || (i == 0 && trimmed == "---") {
            continue;
        }
        if trimmed == "..." {
            break;
        }
        if let Some(item) = trimmed.strip_prefix('-').filter(|_| open_list.is_some()) {
            if let Some(Entry {
                value: Value::List(items),
                ..
            }) = open_list.and_then(|k| entries.get_mut(k)).map(|(_, e)| e)
            {
                items.push(item.trim().to_string());
            }
            continue;
        }
        if content.starts_with([' ', '\t']) {
            // Nested under a key map_server does not read: ignored with it.
            if entries.last().is_some_and(|(k, _)| !is_known(k)) {
                continue;
            }
            return Err(fail(
                line,
                format!("unexpected indented line {:?}", trimmed),
            ));
        }
        open_list = None;
        let Some((key, value)) = trimmed.split_once(':') else {
            return Err(fail(
                line,
                format!("expected `key: value`, found {:?}", trimmed),
            ));
        };
        let (key, value) = (key.trim(), value.trim());
        if entries.iter().any(|(k, _)| k == key) {
            return Err(fail(line, format!("`{key}` is given twice")));
        }
        let value = if value.is_empty() {
            open_list = Some(entries.len());
            Value::List(Vec::new())
        } else if let Some(inner) = value.strip_prefix('[') {
            let Some(inner) = inner.strip_suffix(']') else {
                return Err(fail(
                    line,
                    format!("`{key}`: a list must close with `]` on the same line"),
                ));
            };
            Value::List(inner.split(',').map(|s| s.trim().to_string()).collect())
        } else {
            Value::Scalar(unquote(value).map_err(|m| fail(line, format!("`{key}`: {m}")))?)
        };
        entries.push((key.to_string(), Entry { line, value }));
    }
    let get = |key: &str| -> Result<&Entry, MapError> {
        entries
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, e)| e)
            .ok_or_else(|| {
                MapError::format(path, None, format!("no `{key}` (map_server needs it)"))
            })
    };
    let scalar = |key: &str| -> Result<(&str, usize), MapError> {
        let entry = get(key)?;
        match &entry.value {
            Value::Scalar(s) => Ok((s.as_str(), entry.line)),
            Value::List(_) => Err(fail(entry.line, format!("`{key}` must be a single value"))),
        }
    };
    let number = |key: &str| -> Result<(f64, usize), MapError> {
        let (text, line) = scalar(key)?;
        parse_number(text).map(|v| (v, line)).ok_or_else(|| {
            fail(
                line,
                format!("`{key}` must be a finite number, not {text:?}"),
            )
        })
    };

    let (image, image_line) = scalar("image")?;
    if image.is_empty() {
        return Err(fail(image_line, "`image` is empty".to_string()));
    }
    let (resolution_m, line) = number("resolution")?;
    if resolution_m <= 0.0 {
        return Err(fail(
            line,
            format!("`resolution` must be positive, not {resolution_m}"),
        ));
    }
    let origin_entry = get("origin")?;
    let origin: Vec<f64> = match &origin_entry.value {
        Value::List(items) => items.iter().map(|s| parse_number(s)).collect::<Option<_>>(),
        Value::Scalar(_) => None,
    }
    .filter(|v: &Vec<f64>| v.len() == 3)
    .ok_or_else(|| {
        fail(
            origin_entry.line,
            "`origin` must be three finite numbers [x, y, yaw]".to_string(),
        )
    })?;
    if origin[2] != 0.0 {
        return Err(fail(
            origin_entry.line,
            format!(
                "`origin`'s yaw is {}, not 0: a rotated map is not supported (map_server ignores \
                 the yaw in most versions, so such a map would not be where it says); rotate the \
                 image instead",
                origin[2]
            ),
        ));
    }
    let (occupied_thresh, occ_line) = number("occupied_thresh")?;
    let (free_thresh, free_line) = number("free_thresh")?;
    for (key, v, line) in [
        ("occupied_thresh", occupied_thresh, occ_line),
        ("free_thresh", free_thresh, free_line),
    ] {
        if !(0.0..=1.0).contains(&v) {
            return Err(fail(
                line,
                format!("`{key}` must be within [0, 1], not {v}"),
            ));
        }
    }
    if free_thresh > occupied_thresh {
        return Err(fail(
            free_line,
            format!("`free_thresh` {free_thresh} is above `occupied_thresh` {occupied_thresh}"),
        ));
    }
    let (negate, line) = scalar("negate")?;
    let negate = match negate {
        "true" | "True" | "TRUE" => true,
        "false" | "False" | "FALSE" => false,
        other => match other.parse::<i64>() {
            Ok(v) => v != 0,
            Err(_) => {
                return Err(fail(
                    line,
                    format!("`negate` must be 0, 1, true or false, not {other:?}"),
                ))
            }
        },
    };
    let mode = match entries.iter().find(|(k, _)| k == "mode") {
        None => Mode::Trinary,
        Some(_) => match scalar("mode")? {
            ("trinary", _) => Mode::Trinary,
            ("scale", _) => Mode::Scale,
            ("raw", _) => Mode::Raw,
            (other, line) => {
                return Err(fail(
                    line,
                    format!("`mode` must be trinary, scale or raw, not {other:?}"),
                ))
            }
        },
    };
    Ok(MapYaml {
        image: image.to_string(),
        resolution_m,
        origin: [origin[0], origin[1]],
        rules: Rules {
            mode,
            negate,
            occupied_thresh,
            free_thresh,
        },
    })
}

/// The YAML map_saver writes, with `mode` (as ROS 2's does) and every number in the shortest
/// form that reads back to the same `f64`.
pub(super) fn render(image: &str, resolution_m: f64, origin: [f64; 2]) -> String {
    format!(
        "image: {}\nmode: trinary\nresolution: {resolution_m:?}\norigin: [{:?}, {:?}, 0.0]\n\
         negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
        quote(image),
        origin[0],
        origin[1]
    )
}

fn is_known(key: &str) -> bool {
    matches!(
        key,
        "image" | "resolution" | "origin" | "negate" | "occupied_thresh" | "free_thresh" | "mode"
    )
}

/// `line` without a comment: `#` at the start or after a space, outside quotes.
fn strip_comment(line: &str) -> &str {
    let mut quote = None;
    let mut prev = ' ';
    for (i, c) in line.char_indices() {
        match quote {
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if c == '"' || c == '\'' => quote = Some(c),
            None if c == '#' && prev.is_whitespace() => return &line[..i],
            None => {}
        }
        prev = c;
    }
    line
}

/// A scalar as written: plain, `'single'` (`''` a quote) or `"double"` (`\"` and `\\`).
fn unquote(value: &str) -> Result<String, String> {
    if let Some(inner) = value.strip_prefix('\'') {
        let inner = inner
            .strip_suffix('\'')
            .ok_or("a quoted value must close its quote")?;
        return Ok(inner.replace("''", "'"));
    }
    if let Some(inner) = value.strip_prefix('"') {
        let inner = inner
            .strip_suffix('"')
            .ok_or("a quoted value must close its quote")?;
        let mut out = String::new();
        let mut chars = inner.chars();
        while let Some(c) = chars.next() {
            if c == '\\' {
                match chars.next() {
                    Some(e @ ('"' | '\\' | '/')) => out.push(e),
                    Some(e) => return Err(format!("the escape \\{e} is not supported")),
                    None => return Err("a value cannot end in \\".to_string()),
                }
            } else {
                out.push(c);
            }
        }
        return Ok(out);
    }
    Ok(value.to_string())
}

/// `name` as a YAML scalar: plain when it reads back as itself, else double-quoted.
fn quote(name: &str) -> String {
    let plain = name
        .chars()
        .all(|c| c.is_alphanumeric() || "._-+/~()".contains(c))
        && !name.starts_with(['-', '~']);
    if plain {
        name.to_string()
    } else {
        format!("\"{}\"", name.replace('\\', "\\\\").replace('"', "\\\""))
    }
}

/// A finite number as YAML writes one (`1`, `-0.5`, `.5`, `1e-3`, `+2`).
fn parse_number(text: &str) -> Option<f64> {
    let t = text.trim();
    let ok = !t.is_empty()
        && t.chars()
            .all(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'));
    ok.then(|| t.parse::<f64>().ok())
        .flatten()
        .filter(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    const MAP_SAVER: &str = "image: map.pgm\nresolution: 0.050000\n\
        origin: [-100.000000, -100.000000, 0.000000]\nnegate: 0\noccupied_thresh: 0.65\n\
        free_thresh: 0.196\n\n";

    fn read(text: &str) -> Result<MapYaml, MapError> {
        parse(text, Path::new("map.yaml"))
    }

    fn error(text: &str) -> String {
        read(text).unwrap_err().to_string()
    }

    #[test]
    fn map_savers_yaml_reads() {
        let map = read(MAP_SAVER).unwrap();
        assert_eq!(map.image, "map.pgm");
        assert_eq!(map.resolution_m, 0.05);
        assert_eq!(map.origin, [-100.0, -100.0]);
        assert_eq!(map.rules.mode, Mode::Trinary);
        assert!(!map.rules.negate);
        assert_eq!(map.rules.occupied_thresh, 0.65);
        assert_eq!(map.rules.free_thresh, 0.196);
    }

    #[test]
    fn block_lists_quotes_comments_and_other_keys_read() {
        let text = "# a map\nimage: 'my map.png'  # the image\nmode: scale\nresolution: .1\n\
            origin:\n  - 1\n  - -2.5e0\n  - 0\nnegate: true\noccupied_thresh: 0.9\n\
            free_thresh: 0.1\nextra:\n  nested: 1\n";
        let map = read(text).unwrap();
        assert_eq!(map.image, "my map.png");
        assert_eq!(map.rules.mode, Mode::Scale);
        assert_eq!(map.origin, [1.0, -2.5]);
        assert!(map.rules.negate);
    }

    #[test]
    fn rendered_yaml_reads_back_exactly() {
        for name in ["map.pgm", "a b#c.pgm", "q\"uote\\.pgm", "-dash.pgm"] {
            let text = render(name, 0.1 + 0.2, [-1.0 / 3.0, 1e-17]);
            let map = read(&text).unwrap();
            assert_eq!(map.image, name);
            assert_eq!(map.resolution_m, 0.1 + 0.2);
            assert_eq!(map.origin, [-1.0 / 3.0, 1e-17]);
        }
    }

    #[test]
    fn bad_yaml_names_the_file_and_line() {
        assert_eq!(
            error(&MAP_SAVER.replace("0.000000]", "0.5]"))
                .split(':')
                .take(2)
                .collect::<Vec<_>>(),
            ["map.yaml", "3"]
        );
        assert!(error(&MAP_SAVER.replace("0.000000]", "0.5]")).contains("yaw"));
        assert!(
            error(&MAP_SAVER.replace("resolution: 0.050000", "resolution: -1"))
                .starts_with("map.yaml:2: `resolution` must be positive")
        );
        assert!(error(&MAP_SAVER.replace("negate: 0\n", "")).starts_with("map.yaml: no `negate`"));
        assert!(error(&format!("{MAP_SAVER}negate: 1\n")).contains("`negate` is given twice"));
        assert!(error(&MAP_SAVER.replace("origin: [", "origin: [1, ")).contains("three"));
        assert!(error(&MAP_SAVER.replace("0.65", "nan")).contains("finite number"));
        assert!(error(&MAP_SAVER.replace("0.65", "0.1")).contains("above"));
        assert!(error(&format!("{MAP_SAVER}mode: fancy\n")).contains("trinary, scale or raw"));
        assert!(error("just text\n").starts_with("map.yaml:1: expected `key: value`"));
    }
}
