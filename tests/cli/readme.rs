//! The README's walkthrough, run as a user runs it: every command of its `sh` blocks in one
//! working directory, each output line it shows (`# …` under the command) checked against what
//! the command printed. A README that drifts from the tool fails here.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

use super::common::*;

/// One command of a block and the output lines the README shows under it.
struct Step {
    command: String,
    shown: Vec<String>,
}

/// The `sh` blocks of the README's walkthrough section, as steps.
fn walkthrough_blocks() -> Vec<Vec<Step>> {
    let readme = std::fs::read_to_string(repo_file("README.md")).unwrap();
    let start = readme
        .find("## A ten-minute walkthrough")
        .expect("the README has its walkthrough");
    let section = &readme[start..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    let mut blocks = Vec::new();
    let mut lines = section.lines();
    while let Some(line) = lines.next() {
        if line.trim() != "```sh" {
            continue;
        }
        let mut steps: Vec<Step> = Vec::new();
        for line in lines.by_ref() {
            if line.trim() == "```" {
                break;
            }
            if let Some(shown) = line.strip_prefix("# ") {
                steps
                    .last_mut()
                    .expect("an output line follows a command")
                    .shown
                    .push(shown.to_string());
            } else if !line.trim().is_empty() {
                steps.push(Step {
                    command: line.to_string(),
                    shown: Vec::new(),
                });
            }
        }
        blocks.push(steps);
    }
    blocks
}

/// Whether `line` is what the README shows: equal, with `…` standing for any text.
fn matches(shown: &str, line: &str) -> bool {
    let mut parts = shown.split('…');
    let first = parts.next().unwrap_or("");
    let Some(mut rest) = line.strip_prefix(first) else {
        return false;
    };
    let parts: Vec<&str> = parts.collect();
    let Some((last, middle)) = parts.split_last() else {
        return rest.is_empty();
    };
    for part in middle {
        match rest.find(part) {
            Some(i) => rest = &rest[i + part.len()..],
            None => return false,
        }
    }
    rest.ends_with(last)
}

/// Asserts that the lines shown appear in `output`, in order.
fn assert_shown(step: &str, shown: &[String], output: &str) {
    let mut lines = output.lines();
    for want in shown {
        assert!(
            lines.by_ref().any(|line| matches(want, line)),
            "README step `{step}` shows\n  {want}\nwhich is not in (or not in the order of) what it printed:\n{output}"
        );
    }
}

/// A shell with `hilsim` on its PATH, in `dir`.
fn shell(dir: &Path, command: &str) -> Command {
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_hilsim")).parent().unwrap();
    let path = std::env::join_paths(std::iter::once(bin_dir.to_path_buf()).chain(
        std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()),
    ))
    .unwrap();
    let mut sh = Command::new("sh");
    sh.args(["-c", command])
        .current_dir(dir)
        .env_clear()
        .env("PATH", path);
    sh
}

/// A command the README runs in the background (`… &`): its first line names the pty, the rest
/// is read when the block's `wait` comes.
struct Background {
    child: Child,
    reader: BufReader<std::process::ChildStdout>,
    printed: String,
    shown: Vec<String>,
    command: String,
}

#[test]
fn the_readme_walkthrough_prints_what_the_readme_shows() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    std::os::unix::fs::symlink(repo_file("scenarios"), cwd.join("scenarios")).unwrap();
    let blocks = walkthrough_blocks();
    assert!(
        blocks.len() >= 6,
        "the walkthrough has its six steps, found {}",
        blocks.len()
    );
    let mut checked = 0;
    for steps in blocks {
        // The pty a background server printed, standing for the README's `/dev/pts/0`.
        let mut pty: Option<String> = None;
        let mut background: Option<Background> = None;
        for step in steps {
            let command = match &pty {
                Some(p) => step.command.replace("/dev/pts/0", p),
                None => step.command.clone(),
            };
            let shown: Vec<String> = step
                .shown
                .iter()
                .map(|s| match &pty {
                    Some(p) => s.replace("/dev/pts/0", p),
                    None => s.clone(),
                })
                .collect();
            if command.starts_with("cargo build -p hilsim-example-firmware") {
                // Built by the test harness instead, where cargo put it.
                let firmware = super::hil::example_firmware();
                std::fs::create_dir_all(cwd.join("target/debug")).unwrap();
                let link = cwd.join("target/debug/example-firmware");
                if !link.exists() {
                    std::os::unix::fs::symlink(firmware, link).unwrap();
                }
                continue;
            }
            if let Some(command) = command.strip_suffix(" &") {
                let mut child = shell(cwd, command)
                    .stdout(Stdio::piped())
                    .stderr(Stdio::inherit())
                    .spawn()
                    .unwrap();
                let mut reader = BufReader::new(child.stdout.take().unwrap());
                let mut first = String::new();
                reader.read_line(&mut first).unwrap();
                if let Some(p) = first.trim().strip_prefix("serial: ") {
                    pty = Some(p.to_string());
                }
                let first_shown: Vec<String> = step
                    .shown
                    .iter()
                    .take(1)
                    .map(|s| s.replace("/dev/pts/0", pty.as_deref().unwrap_or("")))
                    .collect();
                assert_shown(command, &first_shown, &first);
                background = Some(Background {
                    child,
                    reader,
                    printed: first,
                    shown: shown.into_iter().skip(1).collect(),
                    command: command.to_string(),
                });
                checked += 1;
                continue;
            }
            if command == "wait" {
                let mut bg = background.take().expect("a command runs in the background");
                let mut rest = String::new();
                std::io::Read::read_to_string(&mut bg.reader, &mut rest).unwrap();
                bg.printed.push_str(&rest);
                let status = bg.child.wait().unwrap();
                assert!(status.success(), "`{}`: {status}", bg.command);
                let mut all = bg.shown;
                all.extend(shown);
                assert_shown(&bg.command, &all, &bg.printed);
                checked += 1;
                continue;
            }
            let out = shell(cwd, &command).output().unwrap();
            let printed = format!("{}{}", stdout(&out), stderr(&out));
            assert!(
                out.status.success(),
                "README step `{command}` failed ({}):\n{printed}",
                out.status
            );
            assert_shown(&command, &shown, &printed);
            checked += 1;
        }
        if let Some(mut bg) = background {
            let _ = bg.child.kill();
            panic!("`{}` was left running: the block has no `wait`", bg.command);
        }
    }
    assert!(checked >= 12, "only {checked} commands ran");
}

#[test]
fn the_readme_check_reads_ellipses_as_any_text() {
    assert!(matches("a … b", "a 12 b"));
    assert!(matches("a …", "a anything"));
    assert!(matches("… s", "7.61 s"));
    assert!(!matches("a … b", "a 12 c"));
    assert!(!matches("exact", "exact but longer"));
    assert!(matches("x (…, …) y", "x (1, 2) y"));
}

/// The Markdown files a user reads: the README, ARCHITECTURE, `docs/`, the crates' own pages.
fn doc_pages() -> Vec<std::path::PathBuf> {
    let root = root();
    let mut pages = vec![root.join("README.md"), root.join("ARCHITECTURE.md")];
    let mut dirs = vec![root.join("docs")];
    for entry in std::fs::read_dir(&root).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() && path.join("Cargo.toml").is_file() {
            dirs.push(path);
        }
    }
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() && dir.ends_with("docs") {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                pages.push(path);
            }
        }
    }
    pages
}

/// A heading's anchor as GitHub makes it: lower case, punctuation dropped, spaces to hyphens.
fn anchor_of(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

#[test]
fn every_link_between_the_docs_resolves() {
    let mut broken = Vec::new();
    for page in doc_pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for (i, _) in text.match_indices("](") {
            let rest = &text[i + 2..];
            let Some(end) = rest.find(')') else { continue };
            let link = &rest[..end];
            if link.contains("://") || link.starts_with("mailto:") || link.contains(' ') {
                continue;
            }
            let (file, anchor) = link.split_once('#').unwrap_or((link, ""));
            let target = if file.is_empty() {
                page.clone()
            } else {
                page.parent().unwrap().join(file)
            };
            if !target.exists() {
                broken.push(format!("{}: {link} (no such file)", page.display()));
                continue;
            }
            if !anchor.is_empty() && target.extension().is_some_and(|e| e == "md") {
                let headings = std::fs::read_to_string(&target).unwrap();
                let found = headings
                    .lines()
                    .filter(|l| l.starts_with('#'))
                    .any(|l| anchor_of(l.trim_start_matches('#')) == anchor);
                if !found {
                    broken.push(format!("{}: {link} (no such heading)", page.display()));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// Every `.rs` file of the workspace's crates and tests (not `target/`).
fn sources() -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    let mut dirs = vec![root()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                if !name.starts_with('.') && name != "target" {
                    dirs.push(path);
                }
            } else if name.ends_with(".rs") {
                files.push(path);
            }
        }
    }
    files
}

/// Where `text` names a piece of the project's history: an issue, a session or a round of work,
/// or one trial of a self-test by its number ("issue 12", "session 3", "trial 14").
fn history_words(text: &str) -> Vec<String> {
    let lower = text.to_lowercase();
    let mut found = Vec::new();
    for word in [
        "issue ", "issue #", "session ", "round ", "trial ", "trials ",
    ] {
        for (i, _) in lower.match_indices(word) {
            let after = &lower[i + word.len()..];
            let starts_word = i == 0 || !lower[..i].ends_with(|c: char| c.is_alphanumeric());
            if starts_word && after.starts_with(|c: char| c.is_ascii_digit()) {
                let digits =
                    after.len() - after.trim_start_matches(|c: char| c.is_ascii_digit()).len();
                found.push(lower[i..i + word.len() + digits].to_string());
            }
        }
    }
    found
}

#[test]
fn docs_and_comments_describe_the_tool_not_its_history() {
    let mut named = Vec::new();
    let pages = doc_pages()
        .into_iter()
        .filter(|p| !p.ends_with("history.md"));
    // This file names the words it looks for.
    let sources = sources()
        .into_iter()
        .filter(|p| !p.ends_with("tests/cli/readme.rs"));
    for file in pages.chain(sources) {
        let text = std::fs::read_to_string(&file).unwrap();
        for (n, line) in text.lines().enumerate() {
            for words in history_words(line) {
                named.push(format!("{}:{}: {words}", file.display(), n + 1));
            }
        }
    }
    assert!(
        named.is_empty(),
        "history words (they belong in the git log or docs/history.md):\n{}",
        named.join("\n")
    );
    assert_eq!(
        history_words("see issue 12 and session 3"),
        ["issue 12", "session 3"]
    );
    assert!(history_words("the trial's seed; a round trip; tissue 5").is_empty());
}
