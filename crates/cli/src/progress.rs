//! Progress of long work on a terminal: a bar on standard error that shows
//! only when standard error is a terminal (quiet in pipes, logs and CI),
//! and only once the work has taken a second.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::time::{Duration, Instant};

/// Work shown as a bar after its first second.
pub struct Progress {
    bar: Option<ProgressBar>,
    total: u64,
    template: &'static str,
    started: Instant,
}

impl Progress {
    /// `template`: an indicatif template, e.g. `"{bar} {pos}/{len} words"`.
    pub fn new(total: u64, template: &'static str) -> Progress {
        Progress { bar: None, total, template, started: Instant::now() }
    }

    /// Sets how far the work is; draws the bar once a second has passed.
    pub fn set(&mut self, done: u64) {
        if self.bar.is_none() && self.started.elapsed() >= Duration::from_secs(1) {
            let bar = ProgressBar::with_draw_target(Some(self.total), ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template(self.template) {
                bar.set_style(style);
            }
            self.bar = Some(bar);
        }
        if let Some(bar) = &self.bar {
            bar.set_position(done.min(self.total));
        }
    }

    /// Removes the bar.
    pub fn finish(self) {
        if let Some(bar) = self.bar {
            bar.finish_and_clear();
        }
    }
}
