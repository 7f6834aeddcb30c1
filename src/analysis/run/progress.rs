//! How a run shows its progress: a bar on a terminal, plain lines every few seconds when
//! stderr is a file or a pipe (batch and Slurm logs), or nothing.
//!
//! Both show the simulated time against the end time, the steps taken and an ETA from the
//! simulated-time rate since the start (or the resume) of the run:
//! ```text
//! ETA = (t_end - t) / rate,   rate = (t - t_start) / wall seconds since the start
//! ```
//! Steps are counted as taken (split and cut steps count one each), so the time, not the
//! step count, measures how far the run is.

use crate::output::{console, readable};
use indicatif::{ProgressBar, ProgressStyle};
use std::time::{Duration, Instant};

/// How a run (or a sweep) reports its progress on stderr.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum Mode {
    /// Nothing (`--quiet`, tests, the cases of a sweep).
    #[default]
    Off,
    /// A bar redrawn in place (stderr is a terminal).
    Bar,
    /// A plain line at most every `every` (stderr is a file or a pipe), and one at the end.
    Lines { every: Duration },
}

impl Mode {
    /// The mode for stderr as it is: a bar on a terminal, else a line every `every`.
    pub fn for_stderr(quiet: bool, every: Duration) -> Mode {
        use std::io::IsTerminal;
        if quiet {
            Mode::Off
        } else if std::io::stderr().is_terminal() {
            Mode::Bar
        } else {
            Mode::Lines { every }
        }
    }
}

/// The bar's resolution: its position counts thousandths of the end time.
const BAR_LENGTH: u64 = 1000;

/// The progress of one run.
pub struct Progress {
    mode: Mode,
    bar: ProgressBar,
    name: String,
    end_time: f64,
    /// The simulated time and the instant the rate is measured from.
    start_time: f64,
    start: Instant,
    last_line: Option<Instant>,
}

impl Progress {
    /// The progress of run `name` from simulated time `start_time` (0, or the checkpoint's)
    /// to `end_time`.
    pub fn new(mode: Mode, name: &str, start_time: f64, end_time: f64) -> Progress {
        let bar = match mode {
            Mode::Bar => {
                let bar = ProgressBar::new(BAR_LENGTH);
                bar.set_style(
                    ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {msg}")
                        .expect("valid template")
                        .progress_chars("=> "),
                );
                bar
            }
            Mode::Off | Mode::Lines { .. } => ProgressBar::hidden(),
        };
        Progress {
            mode,
            bar,
            name: name.to_string(),
            end_time,
            start_time,
            start: Instant::now(),
            last_line: None,
        }
    }

    /// Measures the rate from simulated time `time` and now on (a resumed run).
    pub fn start_at(&mut self, time: f64) {
        self.start_time = time;
        self.start = Instant::now();
    }

    /// The run has reached simulated time `time` after `steps` steps.
    pub fn update(&mut self, time: f64, steps: usize) {
        match self.mode {
            Mode::Off => {}
            Mode::Bar => {
                let fraction = (time / self.end_time).clamp(0.0, 1.0);
                self.bar.set_position((fraction * BAR_LENGTH as f64) as u64);
                self.bar.set_message(self.status(time, steps));
            }
            Mode::Lines { every } => {
                let now = Instant::now();
                let due = self
                    .last_line
                    .is_none_or(|last| now.duration_since(last) >= every);
                if due {
                    self.last_line = Some(now);
                    console::err(format_args!("{}: {}", self.name, self.status(time, steps)));
                }
            }
        }
    }

    /// `t = 1.2e-5 / 4e-5 (30 %), 209 steps, ETA 3 s`.
    pub fn status(&self, time: f64, steps: usize) -> String {
        let percent = 100.0 * time / self.end_time;
        let mut text = format!(
            "t = {} / {} ({percent:.0} %), {steps} step{}",
            readable(time),
            readable(self.end_time),
            if steps == 1 { "" } else { "s" }
        );
        let elapsed = self.start.elapsed().as_secs_f64();
        if let Some(eta) = eta(self.start_time, time, self.end_time, elapsed) {
            text.push_str(&format!(", ETA {}", duration_in_words(eta)));
        }
        text
    }

    /// The run ended (done, stopped early or failed): the bar is cleared; the lines end
    /// with the last state when one was printed.
    pub fn finish(&mut self, time: f64, steps: usize) {
        self.bar.finish_and_clear();
        if matches!(self.mode, Mode::Lines { .. }) && self.last_line.is_some() {
            console::err(format_args!("{}: {}", self.name, self.status(time, steps)));
        }
    }
}

/// Seconds until `end` at the rate from `start` to `time` in `elapsed` wall seconds; None
/// before the rate is known (no time simulated yet, or no measurable wall time).
pub fn eta(start: f64, time: f64, end: f64, elapsed: f64) -> Option<f64> {
    let simulated = time - start;
    (simulated > 0.0 && elapsed > 0.0).then(|| ((end - time) / simulated * elapsed).max(0.0))
}

/// `42 s`, `3 min 20 s`, `2 h 05 min`.
pub fn duration_in_words(seconds: f64) -> String {
    let s = seconds.round() as u64;
    if s < 60 {
        format!("{s} s")
    } else if s < 3600 {
        format!("{} min {:02} s", s / 60, s % 60)
    } else {
        format!("{} h {:02} min", s / 3600, (s % 3600) / 60)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Goal: the ETA extrapolates the simulated-time rate. Reference: a run that simulated
    /// a quarter of its time in 10 s needs 30 s more; a resumed run measures from its
    /// resume time.
    #[test]
    fn eta_extrapolates_the_simulated_time_rate() {
        assert_eq!(eta(0.0, 0.25, 1.0, 10.0), Some(30.0));
        assert_eq!(eta(0.5, 0.75, 1.0, 10.0), Some(10.0));
        assert_eq!(eta(0.0, 0.0, 1.0, 10.0), None);
        assert_eq!(duration_in_words(42.4), "42 s");
        assert_eq!(duration_in_words(200.0), "3 min 20 s");
        assert_eq!(duration_in_words(7500.0), "2 h 05 min");
    }
}
