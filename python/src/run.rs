//! `seethru.run`: the see-through system end to end, as `seethru run` computes it, with the
//! views, the metrics (metrics.json's content), the misregistration map and run.json's
//! content returned instead of written.

use std::sync::Arc;

use numpy::ndarray::Array2;
use numpy::{PyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use seethru::geometry::shutter::Shutter;
use seethru::measure::measured_run::{MeasuredRun, measure_run};
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::pipeline::RunResult;
use seethru::system::pipeline::run as run_pipeline;

use crate::errors::to_py;
use crate::frame::PyFrame;
use crate::interrupt::detached;
use crate::options::run_spec;
use crate::scene::{PyScene, context_for};
use seethru::measure::option_table::Command;
use seethru::system::reads::hazard_bound_reads;

/// What one run gives: its six views, its metrics and its report.
#[pyclass(name = "Run", module = "seethru", frozen)]
pub struct PyRun {
    /// truth, occluded, frontal, back, display, seethru → Frame.
    #[pyo3(get)]
    frames: Py<PyDict>,
    /// metrics.json's content.
    #[pyo3(get)]
    metrics: Py<PyAny>,
    /// run.json's content.
    #[pyo3(get)]
    report: Py<PyAny>,
    /// hazards.json's content: each object marked `hazard = true`, how much of it the
    /// obstacle hides and the display shows within `hazard_bound_arcmin`.
    #[pyo3(get)]
    hazards: Py<PyAny>,
    /// Misregistration per driver-view pixel, arcmin; NaN outside the display and on blank
    /// pixels; (height, width) float32 (misregistration.exr's Y).
    #[pyo3(get)]
    misregistration: Py<PyArray2<f32>>,
    /// Driver-view pixels of the display that show nothing of the scene; (height, width) bool.
    #[pyo3(get)]
    missing: Py<PyArray2<bool>>,
}

#[pymethods]
impl PyRun {
    fn __repr__(&self) -> String {
        "<seethru.Run: frames, metrics, report, hazards, misregistration, missing>".to_string()
    }
}

/// JSON as Python objects, through `json.loads` of the text the command line writes: the
/// same dict as reading the file.
pub fn json_to_py(py: Python<'_>, value: &serde_json::Value) -> PyResult<Py<PyAny>> {
    // The library's words name options ("option `fill`"): Python's are the keywords (`fill`).
    let mut value = value.clone();
    seethru::util::option_words::spell_json(&mut value, &seethru::util::option_words::keyword_of);
    let text = serde_json::to_string_pretty(&value).map_err(|e| to_py(e.into()))?;
    Ok(py.import("json")?.call_method1("loads", (text,))?.unbind())
}

/// Runs the see-through system on `scene` with `seethru run`'s options as keywords.
#[pyfunction]
#[pyo3(signature = (scene, **options))]
pub fn run(
    py: Python<'_>,
    scene: &Bound<'_, PyScene>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyRun> {
    let spec = run_spec(options, Command::Run, Vec::new())?;
    if spec.both_eyes {
        return Err(crate::errors::bad_value(
            "eyes=\"both\": seethru.run returns one run: run eyes=\"left\" and eyes=\"right\" (the command line's --eyes both runs each into its own folder)",
        ));
    }
    let (the_scene, cached) = {
        let s = scene.borrow();
        (s.scene.clone(), s.context.clone())
    };
    spec.refuse_ignored(&[hazard_bound_reads(&the_scene)])
        .map_err(crate::options::spelled)?;
    let estimate = run_estimate(&the_scene, &spec.options).map_err(to_py)?;
    check_memory(&estimate, spec.max_memory_gib).map_err(to_py)?;
    let settings = spec.measure;
    let (context, result, measured) = detached(py, move || -> anyhow::Result<_> {
        let ctx = context_for(cached, the_scene)?;
        let result = run_pipeline(&ctx, &spec.options)?;
        let measured = measure_run(&ctx, &spec.options, &result, settings)?;
        Ok((ctx, result, measured))
    })?
    .map_err(to_py)?;
    let shutters = [context.scene.frontal.shutter, context.scene.back.shutter];
    scene.borrow_mut().context = Some(context);
    PyRun::new(py, result, measured, shutters)
}

impl PyRun {
    /// A run's frames, maps, metrics and report handed to Python; `shutters` are its frontal
    /// and back cameras'.
    pub fn new(
        py: Python<'_>,
        result: RunResult,
        measured: MeasuredRun,
        shutters: [Shutter; 2],
    ) -> PyResult<PyRun> {
        let MeasuredRun {
            maps,
            metrics,
            hazards,
            ..
        } = measured;
        let (w, h) = (maps.width as usize, maps.height as usize);
        let misregistration = PyArray::from_owned_array(
            py,
            Array2::from_shape_vec((h, w), maps.misregistration).expect("a map's size"),
        )
        .unbind();
        let missing = PyArray::from_owned_array(
            py,
            Array2::from_shape_vec((h, w), maps.missing).expect("a map's size"),
        )
        .unbind();
        let report = json_to_py(py, &result.report)?;
        let metrics = json_to_py(py, &metrics.to_json())?;
        let hazards = json_to_py(py, &hazards)?;
        let dict = PyDict::new(py);
        // The views rendered over truth made whole first: then truth is theirs no longer, and
        // is handed over without a copy.
        let (occluded, seethru) = (result.occluded.into_whole(), result.seethru.into_whole());
        // The driver's eye sees each view at one instant; the display's image is no camera's.
        let instant = Some(Shutter::INSTANT);
        for (name, frame, shutter) in [
            ("truth", Arc::unwrap_or_clone(result.truth), instant),
            ("occluded", occluded, instant),
            ("frontal", result.frontal, Some(shutters[0])),
            ("back", result.back, Some(shutters[1])),
            ("display", result.display, None),
            ("seethru", seethru, instant),
        ] {
            dict.set_item(name, PyFrame::new(py, name, frame, shutter)?)?;
        }
        Ok(PyRun {
            frames: dict.unbind(),
            metrics,
            report,
            hazards,
            misregistration,
            missing,
        })
    }
}
