//! Progress of long work on a terminal: a bar on standard error that shows
//! only when standard error is a terminal (quiet in pipes, logs and CI),
//! and only once the work has taken a second. The bars have no colours
//! (their templates name none), so NO_COLOR leaves them as they are.

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

/// Work in named stages (the benchmark's rows): a bar of stages on
/// standard error, redrawn only when a stage starts, so that it costs
/// nothing while a stage measures; rows printed through it keep the bar
/// below them.
pub struct Stages {
    bar: ProgressBar,
}

impl Stages {
    pub fn new(total: u64) -> Stages {
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template("{bar:20} stage {pos}/{len}: {msg}") {
            bar.set_style(style);
        }
        Stages { bar }
    }

    /// The next stage begins.
    pub fn start(&self, what: &str) {
        self.bar.inc(1);
        self.bar.set_message(what.to_string());
    }

    /// Prints a line of output above the bar.
    pub fn println(&self, line: &str) {
        self.bar.suspend(|| println!("{line}"));
    }

    pub fn finish(self) {
        self.bar.finish_and_clear();
    }
}
