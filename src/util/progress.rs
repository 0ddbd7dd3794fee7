//! What long jobs say while they work: a progress bar with ETA on a terminal (indicatif),
//! nothing in logs but the one summary line each command ends with, and silence with
//! `--quiet`.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Set once by the command line's `--quiet`.
static QUIET: AtomicBool = AtomicBool::new(false);

/// Silences progress bars and summary lines for the rest of the process.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
}

/// Whether `--quiet` was given.
pub fn is_quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// The one line a command ends with on stderr (what it wrote, where), unless `--quiet`.
pub fn summary(line: impl std::fmt::Display) {
    if !is_quiet() {
        eprintln!("{line}");
    }
}

/// A progress bar over `total` units of work. Hidden unless `enabled`, stderr is a terminal
/// (logs get no carriage returns) and the process is not quiet. Safe to advance from many
/// threads; the bar never changes what is computed.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    pub fn new(label: impl Into<String>, total: usize, enabled: bool) -> Self {
        let shown = enabled && !is_quiet() && std::io::stderr().is_terminal();
        let bar = if shown {
            let style = ProgressStyle::with_template(
                "{msg:>20} {wide_bar} {percent:>3}%  {elapsed_precise} ETA {eta_precise}",
            )
            .expect("a valid progress template");
            ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr())
                .with_style(style)
                .with_message(label.into())
        } else {
            ProgressBar::hidden()
        };
        Self { bar }
    }

    pub fn advance(&self, n: usize) {
        self.bar.inc(n as u64);
    }

    /// Clears the bar: the command's summary line says what was done.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
