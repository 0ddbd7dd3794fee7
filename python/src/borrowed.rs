//! numpy arrays over buffers Rust keeps, without a copy: the one module of the package with
//! `unsafe` (rust-numpy's `borrow_from_array`, which cannot check that the memory outlives the
//! array). Two owners are the arrays' `base` objects and keep the memory alive:
//!
//! - [`CaptureBuffers`]: a capture's images, viewed read-only. A capture is kept whole for
//!   `score`, which reads the same buffers through a shared reference, and the capture's
//!   fingerprint is over them.
//! - [`FrameBuffers`]: a render's frame, viewed writable (numpy arrays a user may change, as
//!   the arrays of a render always were). The frame is never resized or reallocated while
//!   the owner lives; it is written only by `Scene.render(..., out=frame)`, which holds
//!   rust-numpy's exclusive borrow of every array while it renders. When the owner is freed
//!   (no frame, array or view of it is left), its buffers go to [`crate::frame_pool`].
#![allow(unsafe_code)]

use std::sync::{Arc, Mutex, MutexGuard};

use numpy::ndarray::{ArrayView, ArrayViewMut, Dimension};
use numpy::npyffi::flags::NPY_ARRAY_WRITEABLE;
use numpy::{Element, PyArray, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use seethru::render::frame::Frame;
use seethru::system::capture::Capture;

use crate::frame_pool;

/// The owner of a capture's buffers and the base object of the arrays that view them.
/// Frozen: nothing changes the capture after it is made (no `&mut` to it exists).
#[pyclass(name = "_CaptureBuffers", module = "seethru", frozen)]
pub struct CaptureBuffers {
    pub capture: Arc<Capture>,
}

/// A read-only array over the buffer `pick` chooses in `owner`'s capture.
pub fn read_only_view<'py, T: Element, D: Dimension>(
    owner: &Bound<'py, CaptureBuffers>,
    pick: impl for<'a> FnOnce(&'a Capture) -> ArrayView<'a, T, D>,
) -> Bound<'py, PyArray<T, D>> {
    let view = pick(&owner.get().capture);
    // SAFETY: `view` is of memory in the `Capture` that `owner` holds in an `Arc` and never
    // changes or reallocates (a frozen pyclass hands out shared references only, and no
    // other owner of the `Arc` mutates it); numpy keeps `owner` alive as the array's base
    // for as long as the array (or a view of it) lives.
    let array = unsafe { PyArray::borrow_from_array(&view, owner.clone().into_any()) };
    array.readwrite().make_nonwriteable();
    array
}

/// The owner of a render's frame and the base object of the arrays that view it. On drop,
/// its buffers are kept for the next render of the same size ([`frame_pool::give`]).
#[pyclass(name = "_FrameBuffers", module = "seethru", frozen)]
pub struct FrameBuffers {
    frame: Mutex<Frame>,
    /// A render writes the frame now (`Scene.render(out=)`, between its checks and its
    /// return): its arrays are read-only to Python meanwhile.
    pub rendering: std::sync::atomic::AtomicBool,
}

impl FrameBuffers {
    pub fn new(frame: Frame) -> FrameBuffers {
        FrameBuffers {
            frame: Mutex::new(frame),
            rendering: std::sync::atomic::AtomicBool::new(false),
        }
    }

    /// The frame, to render into. Only `Scene.render(out=)` calls it, holding rust-numpy's
    /// exclusive borrow of every array of the frame (so no other Rust code reads them) for
    /// as long as it writes; the buffers' sizes must not change.
    pub fn frame(&self) -> MutexGuard<'_, Frame> {
        self.frame.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Drop for FrameBuffers {
    fn drop(&mut self) {
        let frame = self.frame.get_mut().unwrap_or_else(|e| e.into_inner());
        frame_pool::give(std::mem::replace(frame, Frame::new(0, 0)));
    }
}

/// Sets or clears numpy's WRITEABLE flag of `array`, an array of a frame ([`frame_view`]):
/// cleared while a render writes the frame, so that Python cannot write it meanwhile, set
/// again after. numpy's own `setflags(write=True)` refuses (the arrays' base, the frame's
/// owner, exposes no buffer for numpy to check), hence the flag bit itself.
pub fn set_frame_array_writeable(array: &Bound<'_, PyUntypedArray>, writeable: bool) {
    // SAFETY: `array` is a live numpy array (the `Bound` keeps it alive, the GIL is held), so
    // its object may be written; the flag is set back only on arrays `frame_view` made over
    // the frame's mutable buffers, which are writable memory for as long as the array lives.
    unsafe {
        let object = array.as_array_ptr();
        if writeable {
            (*object).fields.flags |= NPY_ARRAY_WRITEABLE;
        } else {
            (*object).fields.flags &= !NPY_ARRAY_WRITEABLE;
        }
    }
}

/// A writable array over the buffer `pick` chooses in `owner`'s frame.
pub fn frame_view<'py, T: Element, D: Dimension>(
    owner: &Bound<'py, FrameBuffers>,
    pick: impl for<'a> FnOnce(&'a mut Frame) -> ArrayViewMut<'a, T, D>,
) -> Bound<'py, PyArray<T, D>> {
    let mut frame = owner.get().frame();
    let view = pick(&mut frame);
    // SAFETY: `view` is of a buffer of the `Frame` that `owner` holds and never resizes or
    // reallocates (`FrameBuffers::frame` is used only to write pixels in place); numpy keeps
    // `owner` alive as the array's base for as long as the array (or a view of it) lives, and
    // the buffer is recycled only when `owner` is dropped. The pointer comes from a mutable
    // view, so numpy's writes through it are writes the frame allows.
    unsafe { PyArray::borrow_from_array(&view, owner.clone().into_any()) }
}
