//! Progress of the long commands (`faults`, `montecarlo`, `bench`) on stderr.
//!
//! On a terminal, an `indicatif` bar. Off a terminal (stderr redirected to a file or a pipe, as
//! in CI or `nohup`), where a bar draws nothing, a plain line every
//! [`DEFAULT_INTERVAL_S`] seconds and one at the end:
//!
//! ```text
//! host-sim faults: 12/50 runs, 1m05s elapsed, about 3m26s left
//! host-sim faults: 50/50 runs done in 4m31s
//! ```
//!
//! The estimate of what remains is the elapsed time scaled by the work left,
//! `t·(n − k)/k` after `k` of `n` items (items of equal cost; none is given before the first
//! item is done). The interval is set by the environment variable [`INTERVAL_ENV`] (seconds,
//! a positive number; `HOST_SIM_PROGRESS_S=0.2 host-sim faults …`), which also lets the tests
//! see the lines of a short run.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal as _;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Seconds between two progress lines off a terminal, unless [`INTERVAL_ENV`] says otherwise.
pub const DEFAULT_INTERVAL_S: f64 = 5.0;

/// The environment variable holding the interval between progress lines off a terminal, s.
pub const INTERVAL_ENV: &str = "HOST_SIM_PROGRESS_S";

/// How progress is shown.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    /// Nothing.
    Hidden,
    /// An `indicatif` bar (stderr is a terminal).
    Bar,
    /// A plain line to stderr every given interval and at the end.
    Lines(Duration),
}

impl Mode {
    /// [`Mode::Bar`] when stderr is a terminal, else [`Mode::Lines`] at the interval of
    /// [`INTERVAL_ENV`] (or [`DEFAULT_INTERVAL_S`] when it is unset or not a positive
    /// number); [`Mode::Hidden`] when `shown` is false.
    #[must_use]
    pub fn for_stderr(shown: bool) -> Self {
        if !shown {
            Self::Hidden
        } else if std::io::stderr().is_terminal() {
            Self::Bar
        } else {
            Self::Lines(interval())
        }
    }
}

/// The interval of [`INTERVAL_ENV`], else [`DEFAULT_INTERVAL_S`].
fn interval() -> Duration {
    std::env::var(INTERVAL_ENV)
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0 && *s < 1e6)
        .map_or(Duration::from_secs_f64(DEFAULT_INTERVAL_S), |s| {
            Duration::from_secs_f64(s)
        })
}

/// `1h02m03s`, `4m05s` or `6.0s`.
#[must_use]
pub fn duration(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s < 60.0 {
        return format!("{s:.1}s");
    }
    let whole = s.round() as u64;
    let (h, m, sec) = (whole / 3600, (whole / 60) % 60, whole % 60);
    if h > 0 {
        format!("{h}h{m:02}m{sec:02}s")
    } else {
        format!("{m}m{sec:02}s")
    }
}

/// The line of `done` of `total` items after `elapsed` (see the module docs).
#[must_use]
pub fn line(label: &str, what: &str, done: u64, total: u64, elapsed: Duration) -> String {
    let left = if done == 0 {
        "no estimate of what is left yet".to_string()
    } else {
        let rest = elapsed.as_secs_f64() * total.saturating_sub(done) as f64 / done as f64;
        format!("about {} left", duration(Duration::from_secs_f64(rest)))
    };
    format!(
        "host-sim {label}: {done}/{total} {what}, {} elapsed, {left}",
        duration(elapsed)
    )
}

/// What the ticker thread and the counting threads share.
struct Shared {
    label: String,
    what: String,
    total: u64,
    done: AtomicU64,
    start: Instant,
    /// Set when the work is over; the ticker waits on it.
    stop: Mutex<bool>,
    wake: Condvar,
}

impl Shared {
    fn line(&self) -> String {
        line(
            &self.label,
            &self.what,
            self.done.load(Ordering::Relaxed),
            self.total,
            self.start.elapsed(),
        )
    }
}

/// A progress display over `total` items, counted from any thread (see the module docs).
pub struct Progress {
    shared: Arc<Shared>,
    bar: Option<ProgressBar>,
    ticker: Option<JoinHandle<()>>,
    finished: bool,
}

impl Progress {
    /// Progress over `total` `what` (a plural noun: `runs`, `datasets`) of the command `label`,
    /// shown as `mode` says.
    #[must_use]
    pub fn new(label: &str, what: &str, total: u64, mode: Mode) -> Self {
        let shared = Arc::new(Shared {
            label: label.to_string(),
            what: what.to_string(),
            total,
            done: AtomicU64::new(0),
            start: Instant::now(),
            stop: Mutex::new(false),
            wake: Condvar::new(),
        });
        let bar = (mode == Mode::Bar).then(|| {
            let bar = ProgressBar::new(total);
            bar.set_style(
                ProgressStyle::with_template(&format!(
                    "{{bar:40}} {{pos}}/{{len}} {what} ({{elapsed}}, about {{eta}} left)"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar
        });
        let ticker = match mode {
            Mode::Lines(every) => {
                let s = Arc::clone(&shared);
                Some(std::thread::spawn(move || ticker(&s, every)))
            }
            Mode::Hidden | Mode::Bar => None,
        };
        Self {
            shared,
            bar,
            ticker,
            finished: false,
        }
    }

    /// Counts `n` more items done.
    pub fn inc(&self, n: u64) {
        self.shared.done.fetch_add(n, Ordering::Relaxed);
        if let Some(b) = &self.bar {
            b.inc(n);
        }
    }

    /// Writes a line of its own (above the bar on a terminal; nothing when hidden).
    pub fn note(&self, message: &str) {
        match (&self.bar, &self.ticker) {
            (Some(b), _) => b.println(message),
            (None, Some(_)) => eprintln!("{message}"),
            (None, None) => {}
        }
    }

    /// Ends the display: clears the bar, or writes the last line (`done in …`, or how far it
    /// got).
    pub fn finish(mut self) {
        self.end();
    }

    fn end(&mut self) {
        if self.finished {
            return;
        }
        self.finished = true;
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
        if let Some(t) = self.ticker.take() {
            if let Ok(mut stop) = self.shared.stop.lock() {
                *stop = true;
            }
            self.shared.wake.notify_all();
            let _ = t.join();
            let s = &self.shared;
            let done = s.done.load(Ordering::Relaxed);
            if done >= s.total {
                eprintln!(
                    "host-sim {}: {done}/{} {} done in {}",
                    s.label,
                    s.total,
                    s.what,
                    duration(s.start.elapsed())
                );
            } else {
                eprintln!("{} (stopped)", s.line());
            }
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.end();
    }
}

/// Writes a line every `every` until told to stop.
fn ticker(s: &Shared, every: Duration) {
    let Ok(mut stop) = s.stop.lock() else {
        return;
    };
    loop {
        let Ok((guard, timeout)) = s.wake.wait_timeout(stop, every) else {
            return;
        };
        stop = guard;
        if *stop {
            return;
        }
        if timeout.timed_out() {
            eprintln!("{}", s.line());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_a_person_writes_them() {
        assert_eq!(duration(Duration::from_millis(6_040)), "6.0s");
        assert_eq!(duration(Duration::from_secs(245)), "4m05s");
        assert_eq!(duration(Duration::from_secs(3723)), "1h02m03s");
    }

    #[test]
    fn the_estimate_scales_the_elapsed_time_by_the_work_left() {
        // 10 of 40 runs in 60 s: 30 more at 6 s each.
        let l = line("faults", "runs", 10, 40, Duration::from_secs(60));
        assert_eq!(
            l,
            "host-sim faults: 10/40 runs, 1m00s elapsed, about 3m00s left"
        );
        let l = line("faults", "runs", 0, 40, Duration::from_secs(3));
        assert!(l.ends_with("no estimate of what is left yet"), "{l}");
    }
}
