//! A progress line on stderr for work that takes longer than about a second.

use std::io::{IsTerminal, Write};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

pub struct Progress {
    label: String,
    total: usize,
    done: AtomicUsize,
    start: Instant,
    /// Time of the last line printed, if any was.
    last: Mutex<Option<Instant>>,
    enabled: bool,
}

const QUIET_START: Duration = Duration::from_secs(1);
const REFRESH: Duration = Duration::from_millis(200);

impl Progress {
    /// `enabled` is further limited to a terminal on stderr: logs get no carriage returns.
    pub fn new(label: impl Into<String>, total: usize, enabled: bool) -> Self {
        let enabled = enabled && std::io::stderr().is_terminal();
        Self {
            label: label.into(),
            total,
            done: AtomicUsize::new(0),
            start: Instant::now(),
            last: Mutex::new(None),
            enabled,
        }
    }

    pub fn advance(&self, n: usize) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        if !self.enabled || self.start.elapsed() < QUIET_START {
            return;
        }
        let Ok(mut last) = self.last.try_lock() else {
            return;
        };
        if last.is_some_and(|t| t.elapsed() < REFRESH) {
            return;
        }
        *last = Some(Instant::now());
        let pct = 100.0 * done as f64 / self.total.max(1) as f64;
        let _ = write!(
            std::io::stderr(),
            "\r{}: {pct:5.1}% ({:.1} s)",
            self.label,
            self.start.elapsed().as_secs_f64()
        );
    }

    pub fn finish(&self) {
        if self.last.lock().map(|l| l.is_some()).unwrap_or(false) {
            let _ = writeln!(
                std::io::stderr(),
                "\r{}: done in {:.2} s     ",
                self.label,
                self.start.elapsed().as_secs_f64()
            );
        }
    }
}
