//! The library's errors as Python exceptions: `OSError` when a file could not be read or
//! written, `ValueError` for everything else (bad input), with the command line's message in
//! Python's words: a flag the message names (`--head estimated`) is the keyword
//! (`head estimated`).

use pyo3::PyErr;
use pyo3::exceptions::{PyOSError, PyValueError};
use seethru::system::reads::keyword_names;
use seethru::util::message::{error_text, printable};

/// The one line the command line prints after `error: `, as an exception.
pub fn to_py(error: anyhow::Error) -> PyErr {
    let message = keyword_names(&printable(&error_text(&error)));
    let from_file = error
        .chain()
        .any(|cause| cause.downcast_ref::<std::io::Error>().is_some());
    match from_file {
        true => PyOSError::new_err(message),
        false => PyValueError::new_err(message),
    }
}

/// A bad argument of a Python call.
pub fn bad_value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
