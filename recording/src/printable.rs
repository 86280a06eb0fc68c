//! Text from an input (a topic name, a scenario's name, a file's header) made safe to print.
//!
//! A bag or a scenario file comes from anyone: a name holding `ESC [ 2 J` or an OSC title
//! sequence would clear the user's screen or retitle their terminal, and a newline would split a
//! one-line message in two. Every name read from an input goes through [`printable`] before it
//! reaches a terminal or a log.

use std::borrow::Cow;
use std::fmt::Write;

/// `text` with every control character (C0, DEL, C1), every bidirectional override and the
/// byte-order mark written as a visible escape (`\e`, `\n`, `\u{202e}`, ...), so that printing it
/// moves no cursor, sets no colour and starts no new line. Text without them is borrowed as is.
///
/// Long text is cut at `max_chars` characters with `…` and the count of characters left out,
/// so that one hostile name cannot fill a screen.
#[must_use]
pub fn printable_cut(text: &str, max_chars: usize) -> Cow<'_, str> {
    let has_controls = text.chars().any(needs_escape);
    let long = text.chars().nth(max_chars).is_some();
    if !has_controls && !long {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len().min(4 * max_chars) + 8);
    for (shown, c) in text.chars().enumerate() {
        if shown == max_chars {
            let rest = text.chars().count() - shown;
            let _ = write!(out, "… ({rest} more characters)");
            return Cow::Owned(out);
        }
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            '\u{1b}' => out.push_str("\\e"),
            c if needs_escape(c) => {
                let _ = write!(out, "\\u{{{:x}}}", c as u32);
            }
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

/// [`printable_cut`] with room for any name a person would write (200 characters).
#[must_use]
pub fn printable(text: &str) -> Cow<'_, str> {
    printable_cut(text, MAX_NAME_CHARS)
}

/// How much of one name a message shows.
pub const MAX_NAME_CHARS: usize = 200;

fn needs_escape(c: char) -> bool {
    c.is_control()
        // Bidirectional embeddings, overrides and isolates: they reorder what follows on the line.
        || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
        // The byte-order mark, invisible where it is not the first thing in a file.
        || c == '\u{feff}'
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_names_are_borrowed_unchanged() {
        assert!(matches!(
            printable("/scan_front"),
            Cow::Borrowed("/scan_front")
        ));
        assert_eq!(printable("bière à 4 m"), "bière à 4 m");
    }

    #[test]
    fn terminal_sequences_and_line_breaks_become_visible_escapes() {
        let hostile = "/a\u{1b}]0;pwned\u{7}\u{1b}[2J\nnext\u{202e}\u{feff}";
        let shown = printable(hostile);
        assert_eq!(shown, "/a\\e]0;pwned\\u{7}\\e[2J\\nnext\\u{202e}\\u{feff}");
        assert!(!shown.chars().any(needs_escape));
    }

    #[test]
    fn a_long_name_is_cut_and_says_how_much_was_left_out() {
        let long = "x".repeat(1000);
        let shown = printable_cut(&long, 10);
        assert_eq!(shown, "xxxxxxxxxx… (990 more characters)");
    }
}
