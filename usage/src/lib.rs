//! A command line's usage error as one line, `<what>; see <command path> --help`, as every other
//! error of the tool is, for scripts that read one line of stderr. clap's own rendering spans
//! several lines with a usage block; this keeps its facts (the argument, the value, the valid
//! values, a suggestion) and drops the rest. Values the user typed are shown terminal-safe.
#![warn(missing_docs)]

use std::ffi::OsString;

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::Command;

/// `err` as one line: what is wrong, then `see <path> --help`, where `path` is `root`'s name
/// followed by the subcommands named in `args` (the program's own name first, as
/// `std::env::args_os` gives them).
#[must_use]
pub fn error_line(err: &clap::Error, root: Command, args: &[OsString]) -> String {
    let (path, cmd) = command_path(root, args);
    let text = |kind| match err.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        Some(ContextValue::Strings(v)) if !v.is_empty() => Some(v.join(", ")),
        Some(ContextValue::StyledStr(s)) => Some(s.to_string()),
        _ => None,
    };
    let typed = |kind| text(kind).map(|s| hilsim_recording::printable(&s).into_owned());
    let valid = text(ContextKind::ValidValue)
        .map(|v| format!(" (expected one of: {v})"))
        .unwrap_or_default();
    let suggestion = text(ContextKind::SuggestedArg)
        .or_else(|| text(ContextKind::SuggestedSubcommand))
        .map(|s| format!(" (did you mean `{s}`?)"))
        .unwrap_or_default();
    let what = match (
        err.kind(),
        text(ContextKind::InvalidArg),
        typed(ContextKind::InvalidValue),
    ) {
        (ErrorKind::MissingRequiredArgument, Some(arg), _) => format!("missing {arg}"),
        (ErrorKind::InvalidValue, Some(arg), Some(value)) if value.is_empty() => {
            format!("{arg}: a value is required{valid}")
        }
        (ErrorKind::InvalidValue, Some(arg), Some(value)) => {
            format!("{arg}: invalid value `{value}`{valid}")
        }
        (ErrorKind::ValueValidation, Some(arg), Some(value)) => {
            let why = std::error::Error::source(err)
                .map(|e| format!(": {e}"))
                .unwrap_or_default();
            format!("{arg}: invalid value `{value}`{why}")
        }
        (ErrorKind::UnknownArgument, _, _) => match typed(ContextKind::InvalidArg) {
            Some(arg) if arg.starts_with('-') => format!("unknown option `{arg}`{suggestion}"),
            Some(arg) => format!("unexpected argument `{arg}`{suggestion}"),
            None => "unexpected argument".to_string(),
        },
        (ErrorKind::InvalidSubcommand, _, _) => match typed(ContextKind::InvalidSubcommand) {
            Some(sub) => format!("unknown command `{sub}`{suggestion}"),
            None => "unknown command".to_string(),
        },
        (
            ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand,
            _,
            _,
        ) => {
            let subs: Vec<&str> = cmd.get_subcommands().map(Command::get_name).collect();
            let subs: Vec<&str> = subs.into_iter().filter(|name| *name != "help").collect();
            format!("missing a command (one of: {})", subs.join(", "))
        }
        (ErrorKind::ArgumentConflict, Some(arg), _) => match text(ContextKind::PriorArg) {
            Some(prior) if prior == arg => format!("{arg} given more than once"),
            Some(prior) => format!("{arg} cannot be used with {prior}"),
            None => format!("{arg} cannot be used with the other arguments given"),
        },
        _ => clap_wording(err),
    };
    format!("{what}; see {path} --help")
}

/// clap's own wording of `err`, its lines joined, without the usage block.
fn clap_wording(err: &clap::Error) -> String {
    let rendered = err.render().to_string();
    let lines = rendered.lines().map(str::trim).filter(|l| {
        !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information")
    });
    let lines: Vec<&str> = lines
        .map(|l| l.strip_prefix("error: ").unwrap_or(l))
        .collect();
    lines.join(" ").replace('\n', " ")
}

/// `root`'s name followed by the subcommands named in `args` (`hilsim dataset merge`), and the
/// last of them.
fn command_path(root: Command, args: &[OsString]) -> (String, Command) {
    let mut path = root.get_name().to_string();
    let mut cmd = root;
    for arg in args.iter().skip(1) {
        let Some(arg) = arg.to_str() else { break };
        if arg.starts_with('-') {
            continue;
        }
        let Some(sub) = cmd.find_subcommand(arg).cloned() else {
            break;
        };
        path.push(' ');
        path.push_str(sub.get_name());
        cmd = sub;
    }
    (path, cmd)
}

#[cfg(test)]
mod tests {
    use clap::{Arg, Command};

    use super::*;

    fn tool() -> Command {
        Command::new("tool").subcommand(
            Command::new("run")
                .arg(Arg::new("out").long("out").required(true))
                .arg(
                    Arg::new("via")
                        .long("via")
                        .value_parser(["memory", "serial"]),
                ),
        )
    }

    fn line(args: &[&str]) -> String {
        let args: Vec<OsString> = args.iter().map(OsString::from).collect();
        let err = tool().try_get_matches_from(&args).unwrap_err();
        error_line(&err, tool(), &args)
    }

    #[test]
    fn names_the_subcommand_to_ask_for_help() {
        assert_eq!(
            line(&["tool", "run"]),
            "missing --out <out>; see tool run --help"
        );
        assert_eq!(
            line(&["tool", "run", "--out", "x", "--via", "pty"]),
            "--via <via>: invalid value `pty` (expected one of: memory, serial); see tool run --help"
        );
        assert_eq!(
            line(&["tool", "walk"]),
            "unknown command `walk`; see tool --help"
        );
    }

    #[test]
    fn a_typed_value_is_shown_terminal_safe() {
        let shown = line(&["tool", "run", "--out", "x", "--via", "\u{1b}[31m"]);
        assert!(!shown.contains('\u{1b}'), "{shown}");
    }
}
