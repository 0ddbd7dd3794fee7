//! `seethru.Scene`: a scene file read and validated as by the command line, with its camera
//! poses, eye and obstacle readable and settable, and renders of its four views.

use std::path::PathBuf;
use std::sync::Arc;

use glam::{DAffine3, DMat4, DVec3};
use numpy::PyArray2;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use seethru::geometry::camera::Camera;
use seethru::measure::option_table::Command;
use seethru::render::frame::Frame;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::{RenderSettings, resized};
use seethru::render::views::View;
use seethru::scene::Scene;
use seethru::scene::limits::{MAX_COORDINATE, MAX_DISPLAY_SIZE, MIN_LENGTH};
use seethru::system::memory::{check_memory, render_estimate};

use crate::errors::{bad_value, to_py};
use crate::frame::PyFrame;
use crate::frame_pool;
use crate::interrupt::detached;
use crate::options::spec_of;

/// Largest deviation of a pose's rotation from orthonormal that is accepted.
const ROTATION_TOLERANCE: f64 = 1e-6;

#[pyclass(name = "Scene", module = "seethru")]
pub struct PyScene {
    pub scene: Scene,
    /// The world and hierarchy of the last render, reused while the geometry is the same.
    pub context: Option<Arc<RenderContext>>,
}

/// A render context for `scene`: `cached` itself, or its world and hierarchy reused when only
/// cameras changed, or a new one.
pub fn context_for(
    cached: Option<Arc<RenderContext>>,
    scene: Scene,
) -> anyhow::Result<Arc<RenderContext>> {
    match cached {
        Some(c) if c.scene == scene => Ok(c),
        Some(c) => Ok(Arc::new(c.with_scene(scene)?)),
        None => Ok(Arc::new(RenderContext::new(scene)?)),
    }
}

fn parse_view(name: &str) -> PyResult<View> {
    View::ALL
        .into_iter()
        .find(|v| v.name() == name)
        .ok_or_else(|| {
            let names: Vec<_> = View::ALL.iter().map(|v| v.name()).collect();
            bad_value(format!("view {name:?} is not one of {}", names.join(", ")))
        })
}

fn pose_array<'py>(py: Python<'py>, pose: &DAffine3) -> Bound<'py, PyArray2<f64>> {
    // glam is column-major; the array is row-major, [R | t; 0 0 0 1].
    let m = DMat4::from(*pose).transpose().to_cols_array();
    PyArray2::from_owned_array(py, Array2::from_shape_vec((4, 4), m.to_vec()).expect("4×4"))
}

/// A rigid transform from a 4×4 row-major matrix, or the reason it is not one.
fn rigid_pose(name: &str, m: [[f64; 4]; 4]) -> PyResult<DAffine3> {
    let bad = |why: &str| bad_value(format!("{name}: {why}"));
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(bad("a 4×4 matrix of finite numbers is needed"));
    }
    if m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(bad(
            "the last row of a rigid transform must be [0, 0, 0, 1]",
        ));
    }
    let pose = DAffine3::from_mat4(DMat4::from_cols_array_2d(&m).transpose());
    let r = pose.matrix3;
    let off_identity = (r.transpose() * r - glam::DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()));
    if off_identity > ROTATION_TOLERANCE || r.determinant() <= 0.0 {
        return Err(bad(&format!(
            "the upper-left 3×3 must be a rotation (orthonormal within {ROTATION_TOLERANCE}, determinant +1)"
        )));
    }
    check_point(name, pose.translation)?;
    Ok(pose)
}

fn check_point(name: &str, p: DVec3) -> PyResult<()> {
    if !p.is_finite() || p.abs().max_element() > MAX_COORDINATE {
        return Err(bad_value(format!(
            "{name}: the position must be finite, each coordinate in [-{MAX_COORDINATE:e}, {MAX_COORDINATE:e}] metres"
        )));
    }
    Ok(())
}

impl PyScene {
    fn camera_mut(&mut self, view: &str) -> PyResult<&mut Camera> {
        Ok(match parse_view(view)? {
            View::Truth | View::Occluded => &mut self.scene.driver,
            View::Frontal => &mut self.scene.frontal,
            View::Back => &mut self.scene.back,
        })
    }
}

#[pymethods]
impl PyScene {
    /// Reads and validates a scene file (TOML), exactly as the command line does.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyScene> {
        let scene = py
            .detach(|| Scene::load(&path))
            .map_err(|e| crate::errors::input_error(&path, e.into()))?;
        Ok(PyScene {
            scene,
            context: None,
        })
    }

    /// An independent copy (its own poses), sharing the built world while the geometry is
    /// the same.
    fn copy(&self) -> PyScene {
        PyScene {
            scene: self.scene.clone(),
            context: self.context.clone(),
        }
    }

    /// The scene file this was read from.
    #[getter]
    fn path(&self) -> PathBuf {
        self.scene.path.clone()
    }

    /// What reading the scene dropped or doubted, one line each: the features of an
    /// OpenDRIVE map its importer skips (the command line prints them as `warning:` lines).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.scene.warnings.clone()
    }

    /// The driver's eye, world frame, metres: the driver camera's centre. Setting it moves
    /// the driver camera, keeping its orientation, and the driver's head (the objects riding
    /// with it, the face the back camera films) with it.
    #[getter]
    fn eye(&self) -> (f64, f64, f64) {
        self.scene.eye().into()
    }

    #[setter]
    fn set_eye(&mut self, eye: (f64, f64, f64)) -> PyResult<()> {
        let p = DVec3::from(eye);
        check_point("eye", p)?;
        self.scene.move_eye(p);
        Ok(())
    }

    /// world_from_camera of the driver camera, a 4×4 float64 array (camera looks down -z).
    #[getter]
    fn driver_pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        pose_array(py, &self.scene.driver.world_from_camera)
    }

    #[setter]
    fn set_driver_pose(&mut self, pose: [[f64; 4]; 4]) -> PyResult<()> {
        self.camera_mut("truth")?.world_from_camera = rigid_pose("driver_pose", pose)?;
        Ok(())
    }

    /// world_from_camera of the frontal camera (the compensation keeps its `[calibration]`).
    #[getter]
    fn frontal_pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        pose_array(py, &self.scene.frontal.world_from_camera)
    }

    #[setter]
    fn set_frontal_pose(&mut self, pose: [[f64; 4]; 4]) -> PyResult<()> {
        self.camera_mut("frontal")?.world_from_camera = rigid_pose("frontal_pose", pose)?;
        Ok(())
    }

    /// world_from_camera of the back camera (the compensation keeps its `[calibration]`).
    #[getter]
    fn back_pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        pose_array(py, &self.scene.back.world_from_camera)
    }

    #[setter]
    fn set_back_pose(&mut self, pose: [[f64; 4]; 4]) -> PyResult<()> {
        self.camera_mut("back")?.world_from_camera = rigid_pose("back_pose", pose)?;
        Ok(())
    }

    /// world_from_obstacle, 4×4 float64 (display centre at the origin, driver on +z).
    /// Setting it moves the obstacle and its display only: the cameras stay where they are.
    #[getter]
    fn obstacle_pose<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        pose_array(py, &self.scene.obstacle.world_from_obstacle)
    }

    #[setter]
    fn set_obstacle_pose(&mut self, pose: [[f64; 4]; 4]) -> PyResult<()> {
        self.scene.obstacle.world_from_obstacle = rigid_pose("obstacle_pose", pose)?;
        Ok(())
    }

    /// Display (width, height), metres, each in [1e-6, 100].
    #[getter]
    fn display_size(&self) -> (f64, f64) {
        (self.scene.obstacle.width, self.scene.obstacle.height)
    }

    #[setter]
    fn set_display_size(&mut self, size: (f64, f64)) -> PyResult<()> {
        for (side, v) in [("width", size.0), ("height", size.1)] {
            if !(v.is_finite() && (MIN_LENGTH..=MAX_DISPLAY_SIZE).contains(&v)) {
                return Err(bad_value(format!(
                    "display_size: {side} {v} is out of range [{MIN_LENGTH:e}, {MAX_DISPLAY_SIZE}] metres"
                )));
            }
        }
        (self.scene.obstacle.width, self.scene.obstacle.height) = size;
        Ok(())
    }

    /// The (width, height) in pixels a view renders at without overrides.
    fn resolution(&self, view: &str) -> PyResult<(u32, u32)> {
        let camera = parse_view(view)?.camera(&self.scene);
        Ok((camera.width, camera.height))
    }

    /// Renders one view (truth, occluded, frontal, back) as `seethru render` does, into a
    /// new frame (its buffers recycled from frames Python has dropped, [`crate::frame_pool`])
    /// or, with `out`, into that frame's own arrays, which it returns.
    /// The size, samples and memory bound are the option table's (`seethru render`'s flags).
    #[pyo3(signature = (view, width=None, height=None, spp=None, max_memory=None, out=None))]
    #[allow(clippy::too_many_arguments)]
    fn render(
        slf: &Bound<'_, Self>,
        view: &str,
        width: Option<Bound<'_, PyAny>>,
        height: Option<Bound<'_, PyAny>>,
        spp: Option<Bound<'_, PyAny>>,
        max_memory: Option<Bound<'_, PyAny>>,
        out: Option<Bound<'_, PyFrame>>,
    ) -> PyResult<Py<PyFrame>> {
        let py = slf.py();
        let view = parse_view(view)?;
        let spec = spec_of(
            Command::Render,
            &[
                ("width", width.as_ref()),
                ("height", height.as_ref()),
                ("spp", spp.as_ref()),
                ("max_memory", max_memory.as_ref()),
            ],
        )?;
        let options = &spec.options;
        let (width, height, spp) = (options.width, options.height, options.spp);
        let (scene, cached) = {
            let this = slf.borrow();
            (this.scene.clone(), this.context.clone())
        };
        let camera = resized(
            view.camera(&scene),
            width,
            height,
            "option `width`/option `height`",
        )
        .map_err(to_py)?;
        let settings = RenderSettings {
            spp,
            progress: false,
        };
        let render = move |frame: &mut Frame| -> anyhow::Result<Arc<RenderContext>> {
            let context = context_for(cached, scene)?;
            context.render_into(
                RenderJob::new(&camera, view.bit())
                    .settings(settings)
                    .label(view.name()),
                frame,
            );
            Ok(context)
        };
        match out {
            Some(out) => {
                // Held until the render has returned: no other call can borrow the arrays.
                let (buffers, _borrows) = out.get().render_target(
                    py,
                    view.name(),
                    camera.width,
                    camera.height,
                    camera.shutter,
                )?;
                let buffers = buffers.get();
                let context = detached(py, move || render(&mut buffers.frame()))?.map_err(to_py)?;
                slf.borrow_mut().context = Some(context);
                Ok(out.unbind())
            }
            None => {
                check_memory(&render_estimate(&[camera]), spec.max_memory_gib).map_err(to_py)?;
                let (context, frame) = detached(py, move || -> anyhow::Result<_> {
                    let mut frame = frame_pool::take(camera.width, camera.height);
                    let context = render(&mut frame)?;
                    Ok((context, frame))
                })?
                .map_err(to_py)?;
                slf.borrow_mut().context = Some(context);
                Py::new(
                    py,
                    PyFrame::new(py, view.name(), frame, Some(camera.shutter))?,
                )
            }
        }
    }

    fn __repr__(&self) -> String {
        format!("<seethru.Scene {}>", self.scene.path.display())
    }
}
