//! Work run with the GIL released, interruptible by Ctrl-C: the work runs on a thread of its
//! own (its renders on the library's rayon pool) while the calling thread checks Python's
//! signals every few milliseconds; on Ctrl-C it asks the renderer to stop between bands
//! (`seethru::render::cancel`), waits for the work to return and raises `KeyboardInterrupt`.

use std::sync::mpsc;
use std::time::Duration;

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use seethru::render::cancel;

/// How often the waiting thread looks at Python's signals.
const SIGNAL_CHECK: Duration = Duration::from_millis(20);

/// Runs `job` with the GIL released; its result, or the exception of a Ctrl-C (or of a
/// Ctrl-C in another thread that cancelled this job's renders too).
pub fn detached<T: Send>(py: Python<'_>, job: impl FnOnce() -> T + Send) -> PyResult<T> {
    let epoch = cancel::epoch();
    let (result, interrupted) = py.detach(|| {
        std::thread::scope(|scope| {
            let (send, receive) = mpsc::channel();
            let worker = scope.spawn(move || {
                let _ = send.send(job());
            });
            let mut interrupted: Option<(PyErr, cancel::Request)> = None;
            let result = loop {
                match receive.recv_timeout(SIGNAL_CHECK) {
                    Ok(result) => break Some(result),
                    Err(mpsc::RecvTimeoutError::Disconnected) => break None,
                    Err(mpsc::RecvTimeoutError::Timeout) if interrupted.is_none() => {
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            interrupted = Some((e, cancel::Request::new()));
                        }
                    }
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                }
            };
            let panicked = worker.join().is_err();
            // The request is held until the job has returned, then dropped here.
            let interrupted = interrupted.map(|(e, _request)| e);
            match (result, panicked) {
                (Some(result), false) => (Some(result), interrupted),
                _ => (None, interrupted),
            }
        })
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    if cancel::epoch() != epoch {
        return Err(PyRuntimeError::new_err(
            "cancelled: a Ctrl-C in another thread stopped the renders running at the time",
        ));
    }
    result.ok_or_else(|| PyRuntimeError::new_err("internal error: the render panicked"))
}
