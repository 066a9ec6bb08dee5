//! The progress bar of a long headless command: on standard error when it
//! is a terminal (a bar, the percentage, the elapsed time and the ETA),
//! nothing at all when it is not (a pipe, a file, CI).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// Steps of the bar: fractions are shown to 0.1 %.
const STEPS: u64 = 1000;

pub struct Progress {
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A bar labelled `what` when standard error is a terminal; otherwise
    /// one that draws nothing.
    pub fn on_stderr(what: &str) -> Progress {
        if !std::io::stderr().is_terminal() {
            return Progress { bar: None };
        }
        let bar = ProgressBar::with_draw_target(Some(STEPS), ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template("{msg} [{wide_bar}] {percent:>3}%  {elapsed} elapsed, ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
        bar.set_style(style);
        bar.set_message(what.to_string());
        Progress { bar: Some(bar) }
    }

    /// The callback for `render`: the fraction done, 0..=1 (`None` when
    /// there is no bar, so the renderer does not even call it).
    pub fn callback(&self) -> Option<impl Fn(f64) + Sync + '_> {
        let bar = self.bar.as_ref()?;
        Some(move |f: f64| bar.set_position((f.clamp(0.0, 1.0) * STEPS as f64) as u64))
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
