//! Progress on stderr with indicatif, shown only when stderr is a terminal (quiet when piped).

use gyrolab_eval::Progress;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;

/// A progress bar on stderr (hidden when stderr is not a terminal or `quiet`).
pub struct Bar(ProgressBar);

impl Bar {
    /// A bar of unknown length until [`Progress::begin`].
    pub fn new(quiet: bool) -> Bar {
        if quiet || !std::io::stderr().is_terminal() {
            return Bar(ProgressBar::hidden());
        }
        let bar = ProgressBar::new(0);
        if let Ok(style) = ProgressStyle::with_template("{spinner} [{bar:30}] {pos}/{len} {msg}") {
            bar.set_style(style.progress_chars("=> "));
        }
        Bar(bar)
    }

    /// A spinner with a message (for work of unknown length).
    pub fn spinner(message: String) -> Bar {
        if !std::io::stderr().is_terminal() {
            return Bar(ProgressBar::hidden());
        }
        let b = ProgressBar::new_spinner();
        b.set_message(message);
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        Bar(b)
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Progress for Bar {
    fn begin(&self, steps: u64) {
        self.0.set_length(steps);
    }
    fn message(&self, text: &str) {
        self.0.set_message(text.to_string());
    }
    fn advance(&self, steps: u64) {
        self.0.inc(steps);
    }
}
