//! `seethru.sequence`: a sequence (`seethru sequence`) as an iterator of measured frames, so
//! that a Python predictor can supply, per display refresh, the eye the compensation uses.
//!
//! Each step does what `measure::sequence::run_sequence` does for one frame with whole
//! driver views (`--frames exr`): the system's loop shows the refresh's image, the truth,
//! `occluded` and `seethru` views are rendered at the frame's instant and measured with
//! `run`'s metrics. The predictor, when given, is asked once per refresh, before the refresh
//! is made; its eye replaces the system's (predicted) head estimate
//! ([`SystemLoop::eye_given`]).

use glam::DVec3;
use numpy::PyArray;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use seethru::measure::metrics::measure;
use seethru::measure::sequence::render_truth_and_occluded;
use seethru::render::footprint::PixelRect;
use seethru::render::frame::Frame;
use seethru::render::settings::{MAX_SPP, RenderSettings};
use seethru::system::options::{Method, Outside, RunOptions, WorkingDistance};
use seethru::system::sequence::head_motion::HeadMotion;
use seethru::system::sequence::predict::Prediction;
use seethru::system::sequence::system_loop::{SequenceOptions, SystemLoop};
use seethru::system::sequence::timeline::Timeline;

use crate::errors::{bad_value, to_py};
use crate::frame::PyFrame;
use crate::interrupt::detached;
use crate::options::{Keywords, choice_of};
use crate::run::json_to_py;
use crate::scene::PyScene;

/// A sequence being stepped through; iterating yields one [`PyStep`] per displayed frame.
#[pyclass(name = "Sequence", module = "seethru")]
pub struct PySequence {
    /// `None` once a step failed (the loop's state is then unknown).
    system: Option<SystemLoop>,
    predictor: Option<Py<PyAny>>,
    next: usize,
    band: u32,
    /// The last refresh made (the predictor is asked once per refresh).
    refresh: Option<i64>,
}

/// One displayed frame: its times, eyes, metrics and images.
#[pyclass(name = "Step", module = "seethru", frozen)]
pub struct PyStep {
    /// Displayed frame index, from 0.
    #[pyo3(get)]
    frame: usize,
    /// When the frame is looked at, s.
    #[pyo3(get)]
    time: f64,
    /// The refresh shown: its index and time, s; the capture and head-sample times, s.
    #[pyo3(get)]
    refresh: i64,
    #[pyo3(get)]
    refresh_time: f64,
    #[pyo3(get)]
    capture_time: f64,
    #[pyo3(get)]
    head_time: f64,
    /// The true eye at `time`, obstacle frame, m (x, y, z).
    #[pyo3(get)]
    eye_true: (f64, f64, f64),
    /// The system's head estimate behind the image shown, obstacle frame, m.
    #[pyo3(get)]
    eye_estimated: (f64, f64, f64),
    /// The eye the compensation used (the predictor's, or the system's), obstacle frame, m.
    #[pyo3(get)]
    eye_used: (f64, f64, f64),
    /// The frame's metrics: `run`'s metrics.json content for this instant.
    #[pyo3(get)]
    metrics: Py<PyAny>,
    /// The truth and `seethru` views at `time` (whole driver views), Frames.
    #[pyo3(get)]
    truth: Py<PyFrame>,
    #[pyo3(get)]
    seethru: Py<PyFrame>,
    /// Misregistration per driver-view pixel, arcmin, NaN outside the display; (h, w) float32.
    #[pyo3(get)]
    misregistration: Py<PyAny>,
}

#[pymethods]
impl PyStep {
    fn __repr__(&self) -> String {
        format!("<seethru.Step frame {} t = {} s>", self.frame, self.time)
    }
}

fn triple(v: DVec3) -> (f64, f64, f64) {
    (v.x, v.y, v.z)
}

#[pymethods]
impl PySequence {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// Frames displayed in all.
    fn __len__(&self) -> usize {
        self.system
            .as_ref()
            .map_or(0, |s| s.options.timeline.frames())
    }

    fn __next__(&mut self, py: Python<'_>) -> PyResult<Option<PyStep>> {
        let Some(system) = self.system.as_mut() else {
            return Ok(None);
        };
        let k = self.next;
        let tl = system.options.timeline;
        if k >= tl.frames() {
            return Ok(None);
        }
        let times = tl.times(k);
        if self.refresh != Some(times.refresh) {
            if let Some(predictor) = &self.predictor {
                let info = PyDict::new(py);
                info.set_item("frame", k)?;
                info.set_item("time", times.display)?;
                info.set_item("refresh", times.refresh)?;
                info.set_item("refresh_time", times.refresh_time)?;
                info.set_item("capture_time", times.capture)?;
                info.set_item("head_time", times.head)?;
                info.set_item(
                    "eye_true",
                    triple(system.rig.eye_in_obstacle(times.display)),
                )?;
                info.set_item(
                    "eye_at_head_time",
                    triple(system.rig.eye_in_obstacle(times.head)),
                )?;
                let eye = predictor.call1(py, (info,))?;
                if !eye.is_none(py) {
                    let v: [f64; 3] = eye.extract(py).map_err(|_| {
                        bad_value(
                            "predictor: return three numbers (x, y, z, obstacle frame, m) or None",
                        )
                    })?;
                    if v.iter().any(|c| !c.is_finite()) {
                        return Err(bad_value(format!(
                            "predictor: the eye must be finite, got {v:?}"
                        )));
                    }
                    system.eye_given = Some(DVec3::from_array(v));
                }
            }
            self.refresh = Some(times.refresh);
        }
        let band = self.band;
        let mut taken = self.system.take().expect("checked above");
        let (taken, result) = detached(py, move || {
            let result = step(&mut taken, k, band);
            (taken, result)
        })?;
        let (shown_estimated, shown_used, truth, seethru, maps, json) = result.map_err(to_py)?;
        let eye_true = taken.rig.eye_in_obstacle(times.display);
        self.system = Some(taken);
        self.next += 1;
        let (w, h) = (maps.width as usize, maps.height as usize);
        let misregistration = PyArray::from_owned_array(
            py,
            Array2::from_shape_vec((h, w), maps.misregistration).expect("a map's size"),
        )
        .into_any()
        .unbind();
        Ok(Some(PyStep {
            frame: k,
            time: times.display,
            refresh: times.refresh,
            refresh_time: times.refresh_time,
            capture_time: times.capture,
            head_time: times.head,
            eye_true: triple(eye_true),
            eye_estimated: triple(shown_estimated),
            eye_used: triple(shown_used),
            metrics: json_to_py(py, &json)?,
            truth: Py::new(py, PyFrame::new(py, "truth", truth))?,
            seethru: Py::new(py, PyFrame::new(py, "seethru", seethru))?,
            misregistration,
        }))
    }
}

type Stepped = (
    DVec3,
    DVec3,
    Frame,
    Frame,
    seethru::measure::metrics::MetricMaps,
    serde_json::Value,
);

/// Frame `k` made and measured as `run_sequence` does with whole driver views.
fn step(system: &mut SystemLoop, k: usize, band: u32) -> anyhow::Result<Stepped> {
    let times = system.options.timeline.times(k);
    let shown = system.show(k)?.clone();
    let ctx = system.context_at(times.display)?;
    let settings = RenderSettings {
        spp: system.options.run.spp,
        progress: false,
    };
    let driver = ctx.scene.driver;
    let mut truth = Frame::new(driver.width, driver.height);
    let occluded = render_truth_and_occluded(&ctx, settings, PixelRect::full(&driver), &mut truth);
    let mut seethru = truth.clone();
    system.render_seethru(&ctx, &mut seethru);
    // Missing pixels are those the frontal camera, where it was at capture, cannot see.
    let mut measured = ctx.scene.clone();
    measured.frontal = shown.frontal;
    let (maps, json) = measure(
        &ctx,
        &measured,
        driver.position(),
        [&truth, &seethru, &occluded],
        band,
    );
    Ok((
        shown.eye_estimated,
        shown.eye_used,
        truth,
        seethru,
        maps,
        json,
    ))
}

/// A sequence of `scene` with `seethru sequence`'s options (and defaults) as keywords; the
/// predictor, if given, is called once per refresh with a dict of its times and the true
/// eye, and returns the eye to compensate for (or None for the system's own).
#[pyfunction]
#[pyo3(signature = (scene, predictor=None, **options))]
pub fn sequence(
    py: Python<'_>,
    scene: &Bound<'_, PyScene>,
    predictor: Option<Py<PyAny>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PySequence> {
    if let Some(p) = &predictor
        && !p.bind(py).is_callable()
    {
        return Err(bad_value("predictor: a callable is needed (or None)"));
    }
    let mut k = Keywords::new(options)?;
    let duration = k.real("duration", 4.0, 1e-6, 3600.0)?;
    let fps = k.real("fps", 60.0, 1e-6, 1000.0)?;
    let display_hz = k.real("display_hz", fps, 1e-6, 1000.0)?;
    let speed = k.real("speed", 0.0, 0.0, 300.0)?;
    let yaw_rate = k.real("yaw_rate", 0.0, -180.0, 180.0)?;
    let sway_cm = k.real("sway_cm", 3.0, 0.0, 50.0)?;
    let sway_hz = k.real("sway_hz", 0.5, 1e-6, 20.0)?;
    let lean_cm = k.real("lean_cm", 10.0, 0.0, 50.0)?;
    let lean_s = k.real("lean_s", 0.3, 1e-6, 10.0)?;
    let lean_at = k.real("lean_at", 0.5, 0.0, 3600.0)?;
    let latency_camera = k.real("latency_camera", 0.0, 0.0, 1e4)?;
    let latency_tracking = k.real("latency_tracking", 0.0, 0.0, 1e4)?;
    let d2 = k.real_or_inf("d2", f64::INFINITY, 1e-6, 1e6)?;
    let width = k.int("width", 640, 1, 16384)? as u32;
    let spp = k.int("spp", 1, 1, MAX_SPP as i64)? as u32;
    let band = k.int("band", 5, 1, 1000)? as u32;
    let head = text(&mut k, "head", "still")?;
    let method = text(&mut k, "method", "planar")?;
    let outside = text(&mut k, "outside", "black")?;
    k.finish()?;
    let head = match head.as_str() {
        "still" => HeadMotion::Still,
        "sway" => HeadMotion::Sway {
            amplitude: sway_cm / 100.0,
            frequency: sway_hz,
        },
        "lean" => HeadMotion::Lean {
            distance: lean_cm / 100.0,
            duration: lean_s,
            start: lean_at,
        },
        other => {
            return Err(bad_value(format!(
                "head={other:?} is not one of still, sway, lean"
            )));
        }
    };
    let run = RunOptions {
        method: choice_of::<Method>("method", &method)?,
        d2: match d2 {
            f64::INFINITY => WorkingDistance::Infinity,
            m => WorkingDistance::Metres(m),
        },
        width: Some(width),
        frontal_width: Some(width),
        spp,
        outside: choice_of::<Outside>("outside", &outside)?,
        ..RunOptions::default()
    };
    let options = SequenceOptions {
        run,
        timeline: Timeline {
            duration,
            fps,
            display_hz,
            latency_camera: latency_camera / 1e3,
            latency_tracking: latency_tracking / 1e3,
        },
        speed: speed / 3.6,
        yaw_rate: yaw_rate.to_radians(),
        head,
        predict: Prediction::None,
        reproject: false,
        byo: Default::default(),
    };
    let the_scene = scene.borrow().scene.clone();
    let system = detached(py, move || SystemLoop::new(&the_scene, options))?.map_err(to_py)?;
    Ok(PySequence {
        system: Some(system),
        predictor,
        next: 0,
        band,
        refresh: None,
    })
}

/// A string keyword with its default.
fn text(k: &mut Keywords<'_>, key: &'static str, default: &str) -> PyResult<String> {
    k.string(key)
        .map(|v| v.unwrap_or_else(|| default.to_string()))
}
