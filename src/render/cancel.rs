//! Cancelling renders from outside the command line (the Python package's Ctrl-C): while a
//! request is held, every band of every render skips its pixels, so a long render returns
//! within one band's time. A render that overlapped a request ([`epoch`] changed) holds an
//! unfinished frame and must be discarded by its caller; the command line never requests.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// Requests ever made: a render that sees it change was (partly) cancelled.
static EPOCH: AtomicU64 = AtomicU64::new(0);
/// Requests held now.
static HELD: AtomicUsize = AtomicUsize::new(0);

/// A cancellation request, held until it is dropped (when the cancelled work has returned).
pub struct Request(());

impl Request {
    pub fn new() -> Request {
        EPOCH.fetch_add(1, Ordering::SeqCst);
        HELD.fetch_add(1, Ordering::SeqCst);
        Request(())
    }
}

impl Default for Request {
    fn default() -> Self {
        Request::new()
    }
}

impl Drop for Request {
    fn drop(&mut self) {
        HELD.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Whether renders should stop now (checked between bands).
pub fn requested() -> bool {
    HELD.load(Ordering::Relaxed) > 0
}

/// The number of requests made so far: read it before a render and after; if it changed, the
/// render's frame is unfinished.
pub fn epoch() -> u64 {
    EPOCH.load(Ordering::SeqCst)
}
