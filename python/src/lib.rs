//! `seethru._native`: the Python extension module of the `seethru` package. Scenes, renders
//! and runs of the library, with every buffer handed to numpy without a copy; the pure-Python
//! part (`python/seethru/__init__.py`) re-exports it with the documentation.
// One module, `borrowed`, allows it (numpy views of a capture's and a render's buffers), with
// its reasons.
#![deny(unsafe_code)]

mod borrowed;
mod capture;
mod dataset;
mod errors;
mod frame;
mod frame_pool;
mod interrupt;
mod measures;
mod option_table;
mod options;
mod run;
mod scene;
mod sequence;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::PyScene>()?;
    m.add_class::<frame::PyFrame>()?;
    m.add_class::<run::PyRun>()?;
    m.add_class::<capture::PyCapture>()?;
    m.add_class::<borrowed::CaptureBuffers>()?;
    m.add_class::<borrowed::FrameBuffers>()?;
    m.add_function(wrap_pyfunction!(frame_pool::frame_pool, m)?)?;
    m.add_function(wrap_pyfunction!(capture::capture, m)?)?;
    m.add_function(wrap_pyfunction!(capture::score, m)?)?;
    m.add_function(wrap_pyfunction!(capture::load_capture, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::dataset, m)?)?;
    m.add_function(wrap_pyfunction!(option_table::options, m)?)?;
    m.add_function(wrap_pyfunction!(option_table::spec, m)?)?;
    m.add_class::<sequence::PySequence>()?;
    m.add_class::<sequence::PyStep>()?;
    m.add_function(wrap_pyfunction!(sequence::sequence, m)?)?;
    m.add_function(wrap_pyfunction!(frame::read_frame, m)?)?;
    m.add_function(wrap_pyfunction!(measures::compare, m)?)?;
    m.add_function(wrap_pyfunction!(measures::ratio, m)?)?;
    m.add_function(wrap_pyfunction!(measures::analyze, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
