//! The library's errors as Python exceptions: `OSError` when a file could not be read or
//! written, `ValueError` for everything else (bad input), with the library's message in
//! Python's words: an option the message names ("option `head` estimated") is the keyword
//! (`head estimated`), as the command line's is its flag (`--head estimated`).

use pyo3::PyErr;
use pyo3::exceptions::{PyOSError, PyValueError};
use seethru::util::message::{error_text, printable};
use seethru::util::option_words::as_keywords;

/// The one line the command line prints after `error: `, as an exception.
pub fn to_py(error: anyhow::Error) -> PyErr {
    let message = printable(&as_keywords(&error_text(&error)));
    let from_file = error
        .chain()
        .any(|cause| cause.downcast_ref::<std::io::Error>().is_some());
    match from_file {
        true => PyOSError::new_err(message),
        false => PyValueError::new_err(message),
    }
}

/// A bad argument of a Python call (in Python's words, where it holds the library's).
pub fn bad_value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(as_keywords(&message.into()))
}

/// An error reading the input file `path`: an `OSError` when the file could not be read at all
/// (absent, a folder, no permission), else as [`to_py`] (a bad key: `ValueError`).
pub fn input_error(path: &std::path::Path, error: anyhow::Error) -> PyErr {
    let unreadable = std::fs::File::open(path).is_err() || !path.is_file();
    match unreadable {
        true => PyOSError::new_err(printable(&as_keywords(&error_text(&error)))),
        false => to_py(error),
    }
}
