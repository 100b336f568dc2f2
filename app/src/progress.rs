//! Progress of one long run: simulated time, steps per second and an ETA, on standard error.
//! Shown only once a run has lasted [`RunProgress::DELAY`], so short runs stay silent.

use crate::study::sweep::Progress as Mode;
use clearance_joint::scene::runner::Progress;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// The progress display of a single run, fed by [`Simulation::run_with_progress`](clearance_joint::scene::runner::Simulation::run_with_progress).
pub struct RunProgress {
    mode: Mode,
    start: Instant,
    last_shown: Option<Instant>,
    calls: u64,
    bar: Option<ProgressBar>,
    lines: Vec<String>,
    keep_lines: bool,
}

impl RunProgress {
    /// Wall time before anything is shown.
    pub const DELAY: Duration = Duration::from_secs(2);
    /// Interval between two lines in `Lines` mode (a bar is redrawn more often).
    pub const LINE_EVERY: Duration = Duration::from_secs(10);
    /// The clock is read every this many steps (a step takes microseconds).
    const CHECK_EVERY: u64 = 256;

    /// A display in `mode`: `Auto` is a bar when standard error is a terminal and nothing
    /// otherwise (a log file gets no progress of a single run unless `Lines` is asked for).
    pub fn new(mode: Mode) -> RunProgress {
        let mode = match mode {
            Mode::Auto if std::io::stderr().is_terminal() => Mode::Bar,
            Mode::Auto => Mode::Quiet,
            m => m,
        };
        RunProgress {
            mode,
            start: Instant::now(),
            last_shown: None,
            calls: 0,
            bar: None,
            lines: Vec::new(),
            keep_lines: false,
        }
    }

    /// A `Lines` display that keeps its lines instead of printing them (for tests).
    pub fn recording() -> RunProgress {
        let mut p = RunProgress::new(Mode::Lines);
        p.keep_lines = true;
        p
    }

    /// The lines kept by a [`recording`](Self::recording) display.
    pub fn recorded(&self) -> &[String] {
        &self.lines
    }

    /// Called after every internal step; reads the clock every few hundred steps.
    pub fn update(&mut self, p: &Progress) {
        self.calls += 1;
        if self.mode == Mode::Quiet || !self.calls.is_multiple_of(Self::CHECK_EVERY) {
            return;
        }
        self.update_at(p, Instant::now());
    }

    /// [`update`](Self::update) at wall-clock time `now`.
    pub fn update_at(&mut self, p: &Progress, now: Instant) {
        let elapsed = now.saturating_duration_since(self.start);
        if elapsed < Self::DELAY || self.mode == Mode::Quiet {
            return;
        }
        let text = status(p, elapsed.as_secs_f64());
        match self.mode {
            Mode::Bar => {
                let bar = self.bar.get_or_insert_with(|| {
                    let b = ProgressBar::new(1000);
                    if let Ok(style) = ProgressStyle::with_template("[{bar:20}] {msg}") {
                        b.set_style(style.progress_chars("=> "));
                    }
                    b
                });
                bar.set_position((1000.0 * (p.t / p.end).clamp(0.0, 1.0)) as u64);
                bar.set_message(text);
            }
            _ => {
                if self
                    .last_shown
                    .is_none_or(|t| now.saturating_duration_since(t) >= Self::LINE_EVERY)
                {
                    self.last_shown = Some(now);
                    if self.keep_lines {
                        self.lines.push(text);
                    } else {
                        eprintln!("{text}");
                    }
                }
            }
        }
    }

    /// Clears the bar.
    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}

/// `t = 12.5/100 s (12.5 %), 4.1e5 steps/s, ETA 3 min 2 s`: the ETA from the simulated time
/// covered per wall second so far (short enough for an 80-column terminal with the bar).
pub fn status(p: &Progress, elapsed_s: f64) -> String {
    use clearance_joint::error::sig4;
    let rate = p.steps as f64 / elapsed_s.max(1e-9);
    let sim_per_s = p.t / elapsed_s.max(1e-9);
    let eta = if sim_per_s > 0.0 {
        duration_text((p.end - p.t).max(0.0) / sim_per_s)
    } else {
        "unknown".into()
    };
    format!(
        "t = {}/{} s ({} %), {} steps/s, ETA {eta}",
        sig4(p.t),
        sig4(p.end),
        sig4(100.0 * p.t / p.end),
        sig4(rate)
    )
}

/// `42 s`, `3 min 2 s`, `2 h 5 min`.
fn duration_text(s: f64) -> String {
    if !s.is_finite() {
        return "unknown".into();
    }
    let s = s.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {} s", s / 60, s % 60),
        _ => format!("{} h {} min", s / 3600, (s % 3600) / 60),
    }
}
