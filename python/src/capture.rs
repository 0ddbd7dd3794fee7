//! `seethru.capture` and `seethru.score`: the "bring your own method" protocol without files.
//! A capture holds what a real system's algorithm receives (images as arrays, the head
//! tracker's output and the calibration as dicts); a score shows a method's display map
//! and/or image on the display and measures it exactly as `seethru score` does.

use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;
use numpy::ndarray::ArrayView2;
use numpy::{PyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use seethru::io::frame_files::ExrContent;
use seethru::io::output_paths::{Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::capture_files::{capture_spec, recapture, write_scoreable_capture};
use seethru::measure::hazard::HAZARD_BOUND_ARCMIN;
use seethru::measure::measured_run::{MeasureSettings, measure_run};
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::system::capture::{
    Capture, DisplayImage, DisplayMap, capture as capture_views, score as score_display,
};
use seethru::system::display::Filter;
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::options::RunOptions;

use crate::borrowed::{CaptureBuffers, read_only_view};
use crate::errors::{bad_value, to_py};
use crate::frame::PyFrame;
use crate::interrupt::detached;
use crate::options::{choice_of, int_in, run_spec};
use crate::run::{PyRun, json_to_py};
use crate::scene::{PyScene, context_for};
use seethru::measure::option_table::{Command, Value, option};

/// What a see-through system's algorithm receives; its truth stays inside for `score`.
#[pyclass(name = "Capture", module = "seethru", frozen)]
pub struct PyCapture {
    inner: Arc<Capture>,
    context: Arc<RenderContext>,
    options: RunOptions,
    /// The frontal camera's image (colour is the method's input), a Frame of read-only
    /// views of the capture's buffers (no copy; `score` reads the same buffers).
    #[pyo3(get)]
    frontal: Py<PyFrame>,
    /// The back camera's image, a Frame of read-only views.
    #[pyo3(get)]
    back: Py<PyFrame>,
    /// The depth sensor's inverse depth, 1/m (0: no return), (h, w) float32; None unless
    /// captured with depth=True; a read-only view.
    #[pyo3(get)]
    inverse_depth: Option<Py<PyArray2<f32>>>,
    /// The head tracker's output (head.json's "head").
    #[pyo3(get)]
    head: Py<PyAny>,
    /// calibration.json's content (OpenCV's conventions).
    #[pyo3(get)]
    calibration: Py<PyAny>,
    /// 16 hex digits over the images, head and calibration.
    #[pyo3(get)]
    fingerprint: String,
    /// The display's (width, height) in pixels: a map is (height, width, 2).
    #[pyo3(get)]
    display_resolution: (u32, u32),
}

#[pymethods]
impl PyCapture {
    fn __repr__(&self) -> String {
        format!("<seethru.Capture {}>", self.fingerprint)
    }

    /// Writes the capture folder `seethru capture` writes (`exr` as its `--exr`), which
    /// `seethru score` and `seethru.load_capture` read. The scene must be its file's: a scene
    /// changed in memory has no file to capture again from.
    #[pyo3(signature = (path, exr="all"))]
    fn save(&self, py: Python<'_>, path: PathBuf, exr: &str) -> PyResult<()> {
        let exr: ExrContent = choice_of("exr", exr)?;
        let (captured, context, options) = (
            self.inner.clone(),
            self.context.clone(),
            self.options.clone(),
        );
        detached(py, move || -> anyhow::Result<()> {
            check_paths(&[], &[Output::folder("path", &path)])?;
            let scene = &context.scene;
            if Scene::load(&scene.path)? != *scene {
                anyhow::bail!(
                    "the capture's scene was changed in memory since it was read from {}: a capture folder names a scene file that makes it again (write the changes to a scene file and capture from it)",
                    scene.path.display()
                );
            }
            let spec = capture_spec(&scene.path, None, captured.depth.is_some(), &options)?;
            let staged = StagedDir::new(&path)?;
            write_scoreable_capture(staged.path(), &captured, &spec, exr)?;
            staged.commit()
        })?
        .map_err(to_py)
    }
}

/// Renders what the system receives under `seethru run`'s options (`seethru capture`).
#[pyfunction]
#[pyo3(signature = (scene, depth=false, **options))]
pub fn capture(
    py: Python<'_>,
    scene: &Bound<'_, PyScene>,
    depth: bool,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyCapture> {
    let depth_given = match depth {
        true => vec![(option("depth").expect("in the table"), Value::Switch(true))],
        false => Vec::new(),
    };
    let choices = run_spec(options, Command::Capture, depth_given)?;
    let (the_scene, cached) = {
        let s = scene.borrow();
        (s.scene.clone(), s.context.clone())
    };
    let estimate = run_estimate(&the_scene, &choices.options).map_err(to_py)?;
    check_memory(&estimate, choices.max_memory_gib).map_err(to_py)?;
    let options = choices.options.clone();
    let (context, captured) = detached(py, move || -> anyhow::Result<_> {
        let ctx = context_for(cached, the_scene)?;
        let captured = capture_views(&ctx, &choices.options, depth)?;
        Ok((ctx, captured))
    })?
    .map_err(to_py)?;
    scene.borrow_mut().context = Some(context.clone());
    py_capture(py, context, options, captured)
}

/// A capture folder written by `seethru capture` (or `Capture.save`), captured again from its
/// specification and checked against its fingerprint, as `seethru score` reads it.
#[pyfunction]
pub fn load_capture(py: Python<'_>, path: PathBuf) -> PyResult<PyCapture> {
    let again = detached(py, move || recapture(&path))?.map_err(to_py)?;
    py_capture(py, Arc::new(again.ctx), again.options, again.capture)
}

/// The Python object of a capture made under `options` in `context`.
fn py_capture(
    py: Python<'_>,
    context: Arc<RenderContext>,
    options: RunOptions,
    captured: Capture,
) -> PyResult<PyCapture> {
    // The capture is kept whole for `score`: numpy views its images, read-only, no copy.
    let captured = Arc::new(captured);
    let owner = Bound::new(
        py,
        CaptureBuffers {
            capture: captured.clone(),
        },
    )?;
    let scene = &context.scene;
    let frontal = PyFrame::view_of(&owner, "frontal", |c| &c.frontal, scene.frontal.shutter);
    let back = PyFrame::view_of(&owner, "back", |c| &c.back, scene.back.shutter);
    let (frontal, back) = (Py::new(py, frontal)?, Py::new(py, back)?);
    let inverse_depth = captured.depth.as_ref().map(|d| {
        let (w, h) = (d.camera.width as usize, d.camera.height as usize);
        read_only_view(&owner, |c| {
            let d = c.depth.as_ref().expect("checked above");
            ArrayView2::from_shape((h, w), &d.inverse_depth[..]).expect("a depth map")
        })
        .unbind()
    });
    let head = serde_json::to_value(&captured.head).map_err(|e| to_py(e.into()))?;
    let [dw, dh] = context.scene.obstacle.display_resolution;
    Ok(PyCapture {
        head: json_to_py(py, &head)?,
        calibration: json_to_py(py, &captured.calibration)?,
        fingerprint: captured.fingerprint.clone(),
        inner: captured,
        context,
        options,
        frontal,
        back,
        inverse_depth,
        display_resolution: (dw, dh),
    })
}

/// A (h, w, channels) float32 array's size and values, or why it is not one.
fn pixels_of(
    name: &str,
    array: &PyReadonlyArray3<'_, f32>,
    channels: usize,
) -> PyResult<(u32, u32, Vec<f32>)> {
    let shape = array.shape();
    if shape[2] != channels {
        return Err(bad_value(format!(
            "{name} has shape {shape:?}: (display height, display width, {channels}) is needed"
        )));
    }
    let values = array.as_array().iter().copied().collect();
    Ok((shape[1] as u32, shape[0] as u32, values))
}

/// Measures a method's display map (frontal pixel per display pixel, OpenCV's remap
/// convention, NaN shows nothing) and/or display image (linear RGB, or the display's codes
/// with `display_codes`) as `seethru score`.
#[pyfunction]
#[pyo3(signature = (capture, map=None, display_image=None, filter="bilinear", band=5, display_codes=false))]
#[allow(clippy::too_many_arguments)]
pub fn score(
    py: Python<'_>,
    capture: &Bound<'_, PyCapture>,
    map: Option<PyReadonlyArray3<'_, f32>>,
    display_image: Option<PyReadonlyArray3<'_, f32>>,
    filter: &str,
    band: i64,
    display_codes: bool,
) -> PyResult<PyRun> {
    let filter: Filter = choice_of("filter", filter)?;
    let band = int_in("band", band, 1, 1000)? as u32;
    if map.is_none() && display_image.is_none() {
        return Err(bad_value("score needs map=, display_image= or both"));
    }
    if map.is_none() && filter != Filter::Bilinear {
        return Err(bad_value(
            "filter resamples the frontal image at the map's points: it needs map=",
        ));
    }
    let map = map
        .map(|m| {
            pixels_of("map", &m, 2).map(|(width, height, v)| DisplayMap {
                width,
                height,
                xy: v.chunks_exact(2).map(|p| [p[0], p[1]]).collect(),
                fingerprint: None,
            })
        })
        .transpose()?;
    let image = display_image
        .map(|i| {
            pixels_of("display_image", &i, 3).map(|(width, height, v)| DisplayImage {
                width,
                height,
                color: v
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2]))
                    .collect(),
                codes: display_codes,
            })
        })
        .transpose()?;
    if display_codes && image.is_none() {
        return Err(bad_value(
            "display_codes says what display_image= holds: it needs display_image=",
        ));
    }
    let c = capture.get();
    let (inner, context) = (c.inner.clone(), c.context.clone());
    let shutters = [context.scene.frontal.shutter, context.scene.back.shutter];
    let mut options = c.options.clone();
    options.filter = filter;
    let settings = MeasureSettings {
        band,
        hazard_bound_arcmin: HAZARD_BOUND_ARCMIN,
    };
    let (result, measured) = detached(py, move || -> anyhow::Result<_> {
        let scored = score_display(&context, &options, &inner, map.as_ref(), image.as_ref())?;
        let measured = measure_run(&context, &options, &scored.run, settings)?;
        Ok((scored.run, measured))
    })?
    .map_err(to_py)?;
    PyRun::new(py, result, measured, shutters)
}
