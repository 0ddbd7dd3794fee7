//! `seethru.sequence`: a sequence (`seethru sequence`) as an iterator of measured frames, so
//! that a Python predictor can supply, per display refresh, the eye the compensation uses.
//!
//! The frames are the library's [`SequenceStepper`]'s, the stepper `seethru sequence` drives,
//! with whole driver views (`--frames exr`). The keywords are `seethru sequence`'s flags that
//! concern the simulated loop, in snake case, with the same ranges and the same refusals
//! ([`sequence_reads`]). The predictor, when given, is asked once per refresh, before the
//! refresh is made; its eye replaces the system's (predicted) head estimate
//! ([`seethru::system::sequence::system_loop::SystemLoop::eye_given`]).

use std::collections::VecDeque;
use std::path::PathBuf;

use glam::DVec3;
use numpy::PyArray;
use numpy::ndarray::Array2;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use seethru::geometry::shutter::Shutter;
use seethru::measure::image_metrics::Flip;
use seethru::measure::option_table::MAX_LATENCY_MS;
use seethru::measure::sequence::{Measuring, SequenceStepper};
use seethru::measure::sequence_records::FrameRecord;
use seethru::render::frame::Frame;
use seethru::scene::Scene;
use seethru::scene::head_path::HeadPath;
use seethru::system::memory::{check_memory, sequence_estimate};
use seethru::system::options::{HeadSource, RunOptions};
use seethru::system::reads::{ReadWhen, first_ignored, hazard_bound_reads, sequence_reads};
use seethru::system::sequence::head_motion::{HeadMotion, HeadPreset};
use seethru::system::sequence::predict::Prediction;
use seethru::system::sequence::system_loop::SequenceOptions;
use seethru::system::sequence::timeline::Timeline;
use seethru::util::number::short;

use crate::errors::{bad_value, to_py};
use crate::frame::PyFrame;
use crate::interrupt::detached;
use crate::options::{Keywords, real_in};
use crate::run::json_to_py;
use crate::scene::PyScene;
use seethru::measure::option_table::Command;

/// Longest latency, ms; most camera latencies in one sequence (as `seethru sequence`).
const MAX_LATENCIES: usize = 64;

/// A sequence being stepped through; iterating yields one [`PyStep`] per displayed frame,
/// the frames of every camera latency one after the other.
#[pyclass(name = "Sequence", module = "seethru")]
pub struct PySequence {
    /// The latency being stepped (ms) and its stepper; `None` once a step failed (the
    /// loop's state is then unknown) or every latency is done.
    current: Option<(f64, SequenceStepper)>,
    /// The latencies still to run, ms, with their options.
    pending: VecDeque<(f64, SequenceOptions)>,
    scene: Scene,
    how: Measuring,
    hazard_bound_arcmin: f64,
    predictor: Option<Py<PyAny>>,
    /// Frames in all, over every latency.
    frames: usize,
    /// The last refresh made (the predictor is asked once per refresh).
    refresh: Option<i64>,
}

/// One displayed frame: its times, eyes, metrics and images (a row of frames.csv).
#[pyclass(name = "Step", module = "seethru", frozen)]
pub struct PyStep {
    /// The frontal capture to display latency of this frame's sequence, ms.
    #[pyo3(get)]
    latency_camera: f64,
    /// Displayed frame index, from 0 (in its latency's sequence).
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
    /// The image-based head estimate's confidence in [0, 1]; None for another head source.
    #[pyo3(get)]
    head_confidence: Option<f64>,
    /// The yaw fit of the image-based estimate on the mesh face (`[camera.driver] face =
    /// "mesh"`): the fitted yaw from facing the back camera, degrees (positive towards the
    /// driver's left), and its margin in [0, 0.05]; None for the ellipsoid face or another
    /// head source.
    #[pyo3(get)]
    head_yaw_deg: Option<f64>,
    #[pyo3(get)]
    head_fit_margin: Option<f64>,
    /// The mesh face's true yaw from facing the back camera at `head_time`, degrees; None
    /// for the ellipsoid face.
    #[pyo3(get)]
    head_yaw_true_deg: Option<f64>,
    /// The working distance the compensation used, m (d2 auto); None otherwise.
    #[pyo3(get)]
    d2_used: Option<f64>,
    /// The vehicle's pivot, world, m; its yaw, degrees.
    #[pyo3(get)]
    vehicle_position: (f64, f64, f64),
    #[pyo3(get)]
    vehicle_yaw_deg: f64,
    /// The frame's metrics: `run`'s metrics.json content for this instant.
    #[pyo3(get)]
    metrics: Py<PyAny>,
    /// Every `hazard = true` object's visibility, in scene order (frames.csv's hazard
    /// columns), a list of dicts.
    #[pyo3(get)]
    hazards: Py<PyAny>,
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
        format!(
            "<seethru.Step latency {} ms frame {} t = {} s>",
            self.latency_camera, self.frame, self.time
        )
    }
}

fn triple(v: DVec3) -> (f64, f64, f64) {
    (v.x, v.y, v.z)
}

/// What one step hands back from the detached render.
type Stepped = (FrameRecord, Frame, Frame, Vec<f32>, serde_json::Value);

#[pymethods]
impl PySequence {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    /// Frames displayed in all (over every camera latency).
    fn __len__(&self) -> usize {
        self.frames
    }

    fn __next__(&mut self, py: Python<'_>) -> PyResult<Option<PyStep>> {
        loop {
            match &self.current {
                Some((_, stepper)) if stepper.next_frame().is_some() => break,
                None if self.pending.is_empty() => return Ok(None),
                _ => {}
            }
            // The next latency's sequence.
            self.current = None;
            let Some((ms, options)) = self.pending.pop_front() else {
                return Ok(None);
            };
            let (scene, how, bound) = (self.scene.clone(), self.how, self.hazard_bound_arcmin);
            let stepper = detached(py, move || {
                SequenceStepper::new(&scene, options, how, bound)
            })?
            .map_err(|e| {
                self.pending.clear();
                to_py(e)
            })?;
            self.current = Some((ms, stepper));
            self.refresh = None;
        }
        let (ms, mut stepper) = self.current.take().expect("checked above");
        let k = stepper.next_frame().expect("checked above");
        let system = &mut stepper.system;
        let times = system.options.timeline.times(k);
        if self.refresh != Some(times.refresh) {
            if let Some(predictor) = &self.predictor {
                let info = PyDict::new(py);
                info.set_item("latency_camera", ms)?;
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
        let (stepper, result) = detached(py, move || {
            let result = step(&mut stepper);
            (stepper, result)
        })?;
        let (record, truth, seethru, misregistration, json) = match result {
            Ok(stepped) => stepped,
            Err(e) => {
                self.pending.clear();
                return Err(to_py(e));
            }
        };
        let (w, h) = (truth.width as usize, truth.height as usize);
        self.current = Some((ms, stepper));
        let misregistration = PyArray::from_owned_array(
            py,
            Array2::from_shape_vec((h, w), misregistration).expect("a map's size"),
        )
        .into_any()
        .unbind();
        let hazards = serde_json::to_value(&record.hazards).map_err(|e| to_py(e.into()))?;
        Ok(Some(PyStep {
            latency_camera: ms,
            frame: k,
            time: times.display,
            refresh: times.refresh,
            refresh_time: times.refresh_time,
            capture_time: times.capture,
            head_time: times.head,
            eye_true: triple(record.eye_true),
            eye_estimated: triple(record.eye_estimated),
            eye_used: triple(record.eye_used),
            head_confidence: record.head_confidence,
            head_yaw_deg: record.head_pose.map(|p| p.yaw_deg),
            head_fit_margin: record.head_pose.map(|p| p.margin),
            head_yaw_true_deg: record.head_yaw_true_deg,
            d2_used: record.d2_used,
            vehicle_position: triple(record.vehicle_position),
            vehicle_yaw_deg: record.vehicle_yaw_deg,
            metrics: json_to_py(py, &json)?,
            hazards: json_to_py(py, &hazards)?,
            truth: Py::new(
                py,
                PyFrame::new(py, "truth", truth, Some(Shutter::INSTANT))?,
            )?,
            seethru: Py::new(
                py,
                PyFrame::new(py, "seethru", seethru, Some(Shutter::INSTANT))?,
            )?,
            misregistration,
        }))
    }
}

/// The stepper's next frame, its record, views, misregistration and metrics owned.
fn step(stepper: &mut SequenceStepper) -> anyhow::Result<Stepped> {
    let step = stepper.step()?.expect("a frame is left");
    let images = step.images.expect("measured");
    Ok((
        step.record.clone(),
        images.truth.clone(),
        images.seethru.clone(),
        images.maps.misregistration.clone(),
        images.metrics.to_json(),
    ))
}

/// The keywords of [`sequence`], in `seethru sequence --help`'s order.
pub const SEQUENCE_KEYS: [&str; 37] = [
    "duration",
    "fps",
    "display_hz",
    "head",
    "head_path",
    "sway_cm",
    "sway_hz",
    "lean_cm",
    "lean_s",
    "lean_at",
    "latency_camera",
    "latency_tracking",
    "predict",
    "reproject",
    "method",
    "d2",
    "head_source",
    "head_bias_cm",
    "head_jitter_cm",
    "seed",
    "feature_width",
    "require_confident_head",
    "min_head_confidence",
    "speed",
    "yaw_rate",
    "outside",
    "filter",
    "display",
    "width",
    "height",
    "frontal_width",
    "back_width",
    "spp",
    "band",
    "flip",
    "hazard_bound_arcmin",
    "max_memory",
];

/// `latency_camera`: ms in [0, 10000], one number or a list of up to 64, each once.
fn latencies(k: &mut Keywords<'_>) -> PyResult<Vec<f64>> {
    let range = || {
        bad_value(format!(
            "latency_camera must be milliseconds in [0, {MAX_LATENCY_MS}], one number or a list of up to {MAX_LATENCIES}"
        ))
    };
    let Some(v) = k.any("latency_camera") else {
        return Ok(vec![0.0]);
    };
    let values: Vec<f64> = match v.extract::<f64>() {
        Ok(one) => vec![one],
        Err(_) => v.extract().map_err(|_| range())?,
    };
    if values.is_empty() || values.len() > MAX_LATENCIES {
        return Err(range());
    }
    for (i, &ms) in values.iter().enumerate() {
        real_in("latency_camera", ms, 0.0, MAX_LATENCY_MS)?;
        // As on the command line, where each latency has a folder named by its short value.
        if let Some(first) = values[..i].iter().find(|&&m| short(m) == short(ms)) {
            return Err(bad_value(format!(
                "latencies {first} and {ms} ms are the same to 6 digits: give each once"
            )));
        }
    }
    Ok(values)
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
    let head: HeadPreset = k.choice("head", HeadPreset::Still)?;
    let head_path = k.string("head_path")?.map(PathBuf::from);
    if head_path.is_some() && k.given("head") {
        return Err(bad_value(
            "head_path cannot be used with head (a recorded path is the head's motion)",
        ));
    }
    let sway_cm = k.real("sway_cm", 3.0, 0.0, 50.0)?;
    let sway_hz = k.real("sway_hz", 0.5, 1e-6, 20.0)?;
    let lean_cm = k.real("lean_cm", 10.0, 0.0, 50.0)?;
    let lean_s = k.real("lean_s", 0.3, 1e-6, 10.0)?;
    let lean_at = k.real("lean_at", 0.5, 0.0, 3600.0)?;
    let latency_camera = latencies(&mut k)?;
    let latency_tracking = k.real("latency_tracking", 0.0, 0.0, MAX_LATENCY_MS)?;
    let predict: Prediction = k.choice("predict", Prediction::None)?;
    let reproject = k.flag("reproject")?;
    // The options a sequence shares with a run: read by the option table, with its
    // ranges, refusals and the sequence's defaults (`COMMAND_DEFAULTS`).
    let spec = k.spec(Command::Sequence)?;
    let head_source: HeadSource = k.choice("head_source", HeadSource::Oracle)?;
    let flip = Flip::asked(k.flag("flip")?);
    let given: Vec<String> = SEQUENCE_KEYS
        .iter()
        // A switch given False is absent, as a flag left off the command line.
        .filter(|&&key| k.given(key) && (key != "reproject" || reproject))
        .map(|key| key.to_string())
        .collect();
    k.finish()?;
    let run = RunOptions {
        head: head_source,
        ..spec.options.clone()
    };
    // As `seethru sequence`: a setting the others make it ignore is refused.
    let refuse = |rules: &[ReadWhen]| -> PyResult<()> {
        match first_ignored(rules, |option| given.iter().any(|g| g == option)) {
            Some(r) => Err(bad_value(r.keyword_refusal())),
            None => Ok(()),
        }
    };
    refuse(&sequence_reads(
        &run,
        head_path.is_none().then_some(head),
        false,
    ))?;
    let head = match (&head_path, head) {
        (Some(path), _) => {
            let path = path.clone();
            let loaded = py.detach(|| HeadPath::load(&path)).map_err(|e| {
                // The file could not be read (absent, a folder, no permission): an OSError.
                match std::fs::File::open(&path).is_err() || !path.is_file() {
                    true => PyOSError::new_err(to_py(e).value(py).to_string()),
                    false => to_py(e),
                }
            })?;
            HeadMotion::Path(loaded)
        }
        (None, HeadPreset::Still) => HeadMotion::Still,
        (None, HeadPreset::Sway) => HeadMotion::Sway {
            amplitude: sway_cm / 100.0,
            frequency: sway_hz,
        },
        (None, HeadPreset::Lean) => HeadMotion::Lean {
            distance: lean_cm / 100.0,
            duration: lean_s,
            start: lean_at,
        },
    };
    let the_scene = scene.borrow().scene.clone();
    refuse(&[hazard_bound_reads(&the_scene)])?;
    if let HeadMotion::Path(path) = &head {
        path.check_in_world(&the_scene.obstacle.world_from_obstacle)
            .map_err(to_py)?;
    }
    let all: VecDeque<(f64, SequenceOptions)> = latency_camera
        .iter()
        .map(|&ms| {
            let options = SequenceOptions {
                run: run.clone(),
                timeline: Timeline {
                    duration,
                    fps,
                    display_hz,
                    latency_camera: ms / 1e3,
                    latency_tracking: latency_tracking / 1e3,
                },
                head: head.clone(),
                predict,
                reproject,
                byo: Default::default(),
            };
            (ms, options)
        })
        .collect();
    // Every latency's timeline is checked before anything is rendered.
    for (_, o) in &all {
        o.timeline.validate().map_err(to_py)?;
    }
    let first = &all[0].1;
    let estimate = sequence_estimate(
        &the_scene,
        &first.run,
        first.timeline.frames() as u64,
        first.timeline.fps,
        all.len() as u64,
    )
    .map_err(to_py)?;
    check_memory(&estimate, spec.max_memory_gib).map_err(to_py)?;
    let frames = all.iter().map(|(_, o)| o.timeline.frames()).sum();
    let how = Measuring {
        metrics: true,
        full_frames: true,
        band: spec.measure.band,
        progress: false,
        flip,
    };
    let mut sequence = PySequence {
        current: None,
        pending: all,
        scene: the_scene,
        how,
        hazard_bound_arcmin: spec.measure.hazard_bound_arcmin,
        predictor,
        frames,
        refresh: None,
    };
    // The first latency's system is made now, so that its errors are raised here.
    let (ms, options) = sequence.pending.pop_front().expect("one latency at least");
    let scene = sequence.scene.clone();
    let bound = spec.measure.hazard_bound_arcmin;
    let stepper = detached(py, move || {
        SequenceStepper::new(&scene, options, how, bound)
    })?
    .map_err(to_py)?;
    sequence.current = Some((ms, stepper));
    Ok(sequence)
}
