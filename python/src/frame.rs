//! `seethru.Frame`: one render's buffers as numpy arrays. Each array takes over the Rust
//! allocation it was rendered into (`PyArray::from_owned_array`), or, for a capture's
//! images, views it read-only ([`crate::borrowed`]): no pixel is copied, and
//! `Frame._buffer_addresses` records where the allocations were so a test can tell.

use std::collections::HashMap;
use std::path::PathBuf;

use glam::Vec3;
use numpy::ndarray::{Array2, Array3, ArrayView2, ArrayView3};
use numpy::{PyArray, PyArray2, PyArray3};
use pyo3::prelude::*;
use seethru::render::frame::Frame;
use seethru::system::capture::Capture;

use crate::borrowed::{CaptureBuffers, read_only_view};

use crate::errors::to_py;

/// One rendered view: colour and every AOV, row 0 at the top, as in the CLI's EXR.
#[pyclass(name = "Frame", module = "seethru", frozen)]
pub struct PyFrame {
    /// The view's name (truth, occluded, frontal, back, display, seethru, or the EXR's stem).
    #[pyo3(get)]
    view: String,
    #[pyo3(get)]
    width: u32,
    #[pyo3(get)]
    height: u32,
    /// Linear RGB radiance, (height, width, 3) float32 (EXR R, G, B).
    #[pyo3(get)]
    colour: Py<PyArray3<f32>>,
    /// Distance along the pixel-centre ray, metres, +inf for sky; (height, width) float32.
    #[pyo3(get)]
    depth: Py<PyArray2<f32>>,
    /// Depth along the camera's viewing axis, metres, +inf for sky; (height, width) float32.
    #[pyo3(get)]
    camera_z: Py<PyArray2<f32>>,
    /// World position of the visible point, metres, NaN for sky; (height, width, 3) float32.
    #[pyo3(get)]
    position: Py<PyArray3<f32>>,
    /// Unit world normal facing the camera (sky: back along the ray); (height, width, 3).
    #[pyo3(get)]
    normal: Py<PyArray3<f32>>,
    /// Object id (scene object index + 1, obstacle last, 0 sky); (height, width) uint32.
    #[pyo3(get)]
    object_id: Py<PyArray2<u32>>,
    /// Part id (box face, cap, mesh group; 0 sky); (height, width) uint32.
    #[pyo3(get)]
    part_id: Py<PyArray2<u32>>,
    /// Where each buffer's Rust allocation started, by attribute name.
    #[pyo3(get, name = "_buffer_addresses")]
    buffer_addresses: HashMap<String, usize>,
}

#[pymethods]
impl PyFrame {
    fn __repr__(&self) -> String {
        format!(
            "<seethru.Frame {} {}×{}>",
            self.view, self.width, self.height
        )
    }
}

impl PyFrame {
    /// Hands `frame`'s buffers to numpy.
    pub fn new(py: Python<'_>, view: &str, frame: Frame) -> PyFrame {
        let (w, h) = (frame.width as usize, frame.height as usize);
        let mut addresses = HashMap::new();
        let mut vectors = |name: &str, v: Vec<Vec3>| {
            // Vec3 is three f32 (glam's scalar Vec3, 4-byte aligned): the same allocation,
            // read as 3n floats.
            let flat: Vec<f32> = bytemuck::allocation::cast_vec(v);
            addresses.insert(name.to_string(), flat.as_ptr() as usize);
            let array = Array3::from_shape_vec((h, w, 3), flat).expect("a frame's buffer size");
            PyArray::from_owned_array(py, array).unbind()
        };
        let colour = vectors("colour", frame.color);
        let position = vectors("position", frame.position);
        let normal = vectors("normal", frame.normal);
        let mut scalars = |name: &str, v: Vec<f32>| {
            addresses.insert(name.to_string(), v.as_ptr() as usize);
            let array = Array2::from_shape_vec((h, w), v).expect("a frame's buffer size");
            PyArray::from_owned_array(py, array).unbind()
        };
        let depth = scalars("depth", frame.depth);
        let camera_z = scalars("camera_z", frame.camera_z);
        let mut ids = |name: &str, v: Vec<u32>| {
            addresses.insert(name.to_string(), v.as_ptr() as usize);
            let array = Array2::from_shape_vec((h, w), v).expect("a frame's buffer size");
            PyArray::from_owned_array(py, array).unbind()
        };
        let object_id = ids("object_id", frame.object_id);
        let part_id = ids("part_id", frame.part_id);
        PyFrame {
            view: view.to_string(),
            width: frame.width,
            height: frame.height,
            colour,
            depth,
            camera_z,
            position,
            normal,
            object_id,
            part_id,
            buffer_addresses: addresses,
        }
    }

    /// Read-only numpy views of the buffers of the frame `pick` chooses in `owner`'s
    /// capture: no copy ([`read_only_view`]).
    pub fn view_of(
        owner: &Bound<'_, CaptureBuffers>,
        view: &str,
        pick: fn(&Capture) -> &Frame,
    ) -> PyFrame {
        let frame = pick(&owner.get().capture);
        let (w, h) = (frame.width as usize, frame.height as usize);
        let mut addresses = HashMap::new();
        let mut vectors = |name: &str, of: fn(&Frame) -> &[Vec3]| {
            addresses.insert(name.to_string(), of(frame).as_ptr() as usize);
            read_only_view(owner, |c| {
                let flat: &[f32] = bytemuck::cast_slice(of(pick(c)));
                ArrayView3::from_shape((h, w, 3), flat).expect("a frame's buffer size")
            })
            .unbind()
        };
        let colour = vectors("colour", |f| &f.color);
        let position = vectors("position", |f| &f.position);
        let normal = vectors("normal", |f| &f.normal);
        let mut scalars = |name: &str, of: fn(&Frame) -> &[f32]| {
            addresses.insert(name.to_string(), of(frame).as_ptr() as usize);
            read_only_view(owner, |c| {
                ArrayView2::from_shape((h, w), of(pick(c))).expect("a frame's buffer size")
            })
            .unbind()
        };
        let depth = scalars("depth", |f| &f.depth);
        let camera_z = scalars("camera_z", |f| &f.camera_z);
        let mut ids = |name: &str, of: fn(&Frame) -> &[u32]| {
            addresses.insert(name.to_string(), of(frame).as_ptr() as usize);
            read_only_view(owner, |c| {
                ArrayView2::from_shape((h, w), of(pick(c))).expect("a frame's buffer size")
            })
            .unbind()
        };
        let object_id = ids("object_id", |f| &f.object_id);
        let part_id = ids("part_id", |f| &f.part_id);
        PyFrame {
            view: view.to_string(),
            width: frame.width,
            height: frame.height,
            colour,
            depth,
            camera_z,
            position,
            normal,
            object_id,
            part_id,
            buffer_addresses: addresses,
        }
    }
}

/// Reads an EXR the command line wrote (`seethru render`/`run`) as a Frame.
#[pyfunction]
pub fn read_frame(py: Python<'_>, path: PathBuf) -> PyResult<PyFrame> {
    let frame = py
        .detach(|| seethru::io::frame_files::read_exr(&path))
        .map_err(to_py)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(PyFrame::new(py, &name, frame))
}
