//! Progress on a terminal, the one set-up every command's status line or bar uses: drawn only
//! where it is wanted (a terminal), cleared when done or on an error.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};

/// A status line (a spinner and a message) or a bar of `len` steps; nothing when not shown.
/// Cleared when dropped.
pub struct Progress(Option<ProgressBar>);

impl Progress {
    /// On stderr when it is a terminal and `wanted`. `template` is indicatif's, with `{rate}`
    /// for the steps a second (`{:.2}`).
    pub fn on_stderr(wanted: bool, len: Option<u64>, template: &str) -> Self {
        let shown = wanted && std::io::stderr().is_terminal();
        Self::new(shown, len, ProgressDrawTarget::stderr, template)
    }

    /// On stdout when `shown` (the caller knows it is a terminal); see [`Progress::on_stderr`].
    pub fn on_stdout(shown: bool, len: Option<u64>, template: &str) -> Self {
        Self::new(shown, len, ProgressDrawTarget::stdout, template)
    }

    fn new(
        shown: bool,
        len: Option<u64>,
        target: fn() -> ProgressDrawTarget,
        template: &str,
    ) -> Self {
        Self(shown.then(|| {
            let bar = ProgressBar::with_draw_target(len, target());
            if let Ok(style) = ProgressStyle::with_template(template) {
                bar.set_style(style.with_key(
                    "rate",
                    |state: &ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = write!(w, "{:.2}", state.per_sec());
                    },
                ));
            }
            bar
        }))
    }

    /// Redraws the spinner by itself, for stages that report nothing while they work.
    #[must_use]
    pub fn ticking(self) -> Self {
        if let Some(bar) = &self.0 {
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
        }
        self
    }

    /// Whether anything is drawn.
    pub fn is_shown(&self) -> bool {
        self.0.is_some()
    }

    /// Shows `message` at once.
    pub fn message(&self, message: impl Into<std::borrow::Cow<'static, str>>) {
        if let Some(bar) = &self.0 {
            bar.set_message(message);
            bar.tick();
        }
    }

    /// One more step done.
    pub fn inc(&self) {
        if let Some(bar) = &self.0 {
            bar.inc(1);
        }
    }

    /// A whole line above the bar.
    pub fn println(&self, line: impl AsRef<str>) {
        if let Some(bar) = &self.0 {
            bar.println(line);
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}
