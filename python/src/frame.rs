//! `seethru.Frame`: one render's buffers as numpy arrays, without a copy. A render's arrays
//! are writable views of the frame the renderer wrote, owned by their base object
//! ([`FrameBuffers`]), which gives the buffers to [`crate::frame_pool`] for the next render
//! once no frame, array or view of them is left; a capture's images are read-only views of
//! the capture ([`crate::borrowed`]). `Frame._buffer_addresses` records where the buffers
//! are so a test can tell.
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::Ordering;

use glam::Vec3;

use numpy::ndarray::{ArrayView2, ArrayView3, ArrayViewMut2, ArrayViewMut3};
use numpy::{
    IntoPyArray, PyArray, PyArray2, PyArray3, PyArrayMethods, PyReadwriteArray2, PyReadwriteArray3,
    PyUntypedArray,
};
use pyo3::prelude::*;
use seethru::geometry::shutter::Shutter;
use seethru::render::frame::Frame;
use seethru::system::capture::Capture;

use crate::borrowed::{
    CaptureBuffers, FrameBuffers, frame_view, read_only_view, set_frame_array_writeable,
};

use crate::errors::{bad_value, to_py};

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
    /// Linear RGB radiance, (height, width, 3) float32; 1.0 is the PNG's white.
    #[pyo3(get)]
    colour: Py<PyArray3<f32>>,
    /// In a scene lit in physical units (`[sun] illuminance_lux`), the luminance of a colour
    /// of 1.0, cd/m² (`colour` × this is what its EXR holds); None in relative units.
    #[pyo3(get)]
    white_cd_m2: Option<f32>,
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
    /// The owner of a render's buffers (writable, recycled when dropped); None for a
    /// capture's read-only views.
    buffers: Option<Py<FrameBuffers>>,
    /// When the camera's rows see ([`Frame::row_times`]); `None` for a frame read from a
    /// file or the display's image.
    shutter: Option<Shutter>,
}

/// rust-numpy's exclusive borrows of every array of a frame: while they are held, no other
/// Rust code (a render into the same frame, a seethru call reading one of its arrays) can
/// borrow them; and the arrays are not writable from Python (numpy's `flags.writeable` is
/// False), so that a plain write from another thread, while the render runs without the
/// GIL, raises instead of racing with it. Writable again when dropped. A view a user took of
/// an array before the render keeps its own flag: numpy cannot reach it.
pub struct WriteBorrows<'py> {
    _vectors: [PyReadwriteArray3<'py, f32>; 3],
    _scalars: [PyReadwriteArray2<'py, f32>; 2],
    _ids: [PyReadwriteArray2<'py, u32>; 2],
    arrays: Vec<Bound<'py, PyUntypedArray>>,
    buffers: Bound<'py, FrameBuffers>,
}

impl Drop for WriteBorrows<'_> {
    fn drop(&mut self) {
        self.buffers.get().rendering.store(false, Ordering::SeqCst);
        for array in &self.arrays {
            // Each was writable when the render began: a read-only array is refused.
            set_frame_array_writeable(array, true);
        }
    }
}

#[pymethods]
impl PyFrame {
    /// Each row's exposure as (start, end), seconds after the frame's instant (when its last
    /// row is read out), (height, 2) float64, from the camera's shutter keys (a rolling
    /// readout, an exposure; docs/guide/time.md): all zeros for a global shutter with an
    /// instant exposure and for the driver's views; None for a frame read from a file and
    /// for the display's image.
    #[getter]
    fn row_times<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        let shutter = self.shutter?;
        let rows: Vec<[f64; 2]> = shutter
            .row_exposures(self.height)
            .into_iter()
            .map(|(start, end)| [start, end])
            .collect();
        Some(
            numpy::ndarray::Array2::from_shape_fn((rows.len(), 2), |(r, c)| rows[r][c])
                .into_pyarray(py),
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "<seethru.Frame {} {}×{}>",
            self.view, self.width, self.height
        )
    }
}

impl PyFrame {
    /// Hands `frame`'s buffers to numpy: writable arrays over them, whose base object
    /// ([`FrameBuffers`]) owns the frame and gives its buffers to [`crate::frame_pool`] when
    /// no frame, array or view of it is left.
    pub fn new(
        py: Python<'_>,
        view: &str,
        frame: Frame,
        shutter: Option<Shutter>,
    ) -> PyResult<PyFrame> {
        let (w, h) = (frame.width as usize, frame.height as usize);
        let (width, height, white_cd_m2) = (frame.width, frame.height, frame.white_cd_m2);
        let owner = Bound::new(py, FrameBuffers::new(frame))?;
        let mut addresses = HashMap::new();
        let mut vectors = |name: &str, of: fn(&mut Frame) -> &mut [Vec3]| {
            frame_view(&owner, |f| {
                // Vec3 is three f32 (glam's scalar Vec3, 4-byte aligned): the same buffer,
                // read as 3n floats.
                let flat: &mut [f32] = bytemuck::cast_slice_mut(of(f));
                addresses.insert(name.to_string(), flat.as_ptr() as usize);
                ArrayViewMut3::from_shape((h, w, 3), flat).expect("a frame's buffer size")
            })
            .unbind()
        };
        let colour = vectors("colour", |f| &mut f.color);
        let position = vectors("position", |f| &mut f.position);
        let normal = vectors("normal", |f| &mut f.normal);
        let mut scalars = |name: &str, of: fn(&mut Frame) -> &mut [f32]| {
            frame_view(&owner, |f| {
                let v = of(f);
                addresses.insert(name.to_string(), v.as_ptr() as usize);
                ArrayViewMut2::from_shape((h, w), v).expect("a frame's buffer size")
            })
            .unbind()
        };
        let depth = scalars("depth", |f| &mut f.depth);
        let camera_z = scalars("camera_z", |f| &mut f.camera_z);
        let mut ids = |name: &str, of: fn(&mut Frame) -> &mut [u32]| {
            frame_view(&owner, |f| {
                let v = of(f);
                addresses.insert(name.to_string(), v.as_ptr() as usize);
                ArrayViewMut2::from_shape((h, w), v).expect("a frame's buffer size")
            })
            .unbind()
        };
        let object_id = ids("object_id", |f| &mut f.object_id);
        let part_id = ids("part_id", |f| &mut f.part_id);
        Ok(PyFrame {
            view: view.to_string(),
            width,
            height,
            colour,
            white_cd_m2,
            depth,
            camera_z,
            position,
            normal,
            object_id,
            part_id,
            buffer_addresses: addresses,
            buffers: Some(owner.unbind()),
            shutter,
        })
    }

    /// The frame's buffers to render `view` at `width`×`height` into (`Scene.render(out=)`),
    /// with rust-numpy's exclusive borrow of each of its arrays, held by the caller while it
    /// writes; or the reason it cannot be written, as a ValueError.
    pub fn render_target<'py>(
        &self,
        py: Python<'py>,
        view: &str,
        width: u32,
        height: u32,
        shutter: Shutter,
    ) -> PyResult<(Py<FrameBuffers>, WriteBorrows<'py>)> {
        let Some(buffers) = &self.buffers else {
            return Err(bad_value(format!(
                "out: this {} frame's arrays are read-only views of a capture; pass a frame returned by Scene.render",
                self.view
            )));
        };
        // Checked before the arrays' flags, which a render in progress has cleared.
        if buffers.get().rendering.load(Ordering::SeqCst) {
            return Err(bad_value(
                "out: frame.colour is in use by another call (a render into it in another thread); wait for it to return",
            ));
        }
        if self.view != view {
            return Err(bad_value(format!(
                "out: the frame is a {:?} view and this render is {view:?}; pass a frame rendered from the same view",
                self.view
            )));
        }
        if self.shutter.is_some_and(|s| s != shutter) {
            return Err(bad_value(
                "out: the frame's camera reads its rows at other times (its shutter keys); pass a frame rendered with this scene's camera",
            ));
        }
        if (self.width, self.height) != (width, height) {
            return Err(bad_value(format!(
                "out: the frame is {}×{} and this render is {width}×{height} (width×height); pass a frame of the same size",
                self.width, self.height
            )));
        }
        fn borrow<'py, T: numpy::Element, D: numpy::ndarray::Dimension>(
            name: &str,
            array: &Bound<'py, PyArray<T, D>>,
        ) -> PyResult<numpy::PyReadwriteArray<'py, T, D>> {
            array.try_readwrite().map_err(|e| match e {
                numpy::BorrowError::NotWriteable => bad_value(format!(
                    "out: frame.{name} is read-only (its flags.writeable is False); pass a frame whose arrays are all writable"
                )),
                _ => bad_value(format!(
                    "out: frame.{name} is in use by another call (a render into it, or a seethru call reading it in another thread); wait for it to return"
                )),
            })
        }
        let mut borrows = WriteBorrows {
            _vectors: [
                borrow("colour", self.colour.bind(py))?,
                borrow("position", self.position.bind(py))?,
                borrow("normal", self.normal.bind(py))?,
            ],
            _scalars: [
                borrow("depth", self.depth.bind(py))?,
                borrow("camera_z", self.camera_z.bind(py))?,
            ],
            _ids: [
                borrow("object_id", self.object_id.bind(py))?,
                borrow("part_id", self.part_id.bind(py))?,
            ],
            arrays: Vec::new(),
            buffers: buffers.bind(py).clone(),
        };
        buffers.get().rendering.store(true, Ordering::SeqCst);
        for array in [
            self.colour.bind(py).as_untyped(),
            self.position.bind(py).as_untyped(),
            self.normal.bind(py).as_untyped(),
            self.depth.bind(py).as_untyped(),
            self.camera_z.bind(py).as_untyped(),
            self.object_id.bind(py).as_untyped(),
            self.part_id.bind(py).as_untyped(),
        ] {
            set_frame_array_writeable(array, false);
            borrows.arrays.push(array.clone());
        }
        Ok((buffers.clone_ref(py), borrows))
    }

    /// Read-only numpy views of the buffers of the frame `pick` chooses in `owner`'s
    /// capture: no copy ([`read_only_view`]).
    pub fn view_of(
        owner: &Bound<'_, CaptureBuffers>,
        view: &str,
        pick: fn(&Capture) -> &Frame,
        shutter: Shutter,
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
            white_cd_m2: frame.white_cd_m2,
            depth,
            camera_z,
            position,
            normal,
            object_id,
            part_id,
            buffer_addresses: addresses,
            buffers: None,
            shutter: Some(shutter),
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
    PyFrame::new(py, &name, frame, None)
}
