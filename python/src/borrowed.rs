//! Read-only numpy arrays over the buffers of a capture, without a copy: the one module of
//! the package with `unsafe` (rust-numpy's `borrow_from_array`, which cannot check that the
//! memory outlives the array). A capture is kept whole for `score`, so its images cannot be
//! handed over to numpy as a render's are ([`crate::frame`]); numpy views them instead, with
//! the [`CaptureBuffers`] object that owns them as the arrays' base. They are read-only:
//! `score` reads the same buffers through a shared reference, and the capture's fingerprint
//! is over them.
#![allow(unsafe_code)]

use std::sync::Arc;

use numpy::ndarray::{ArrayView, Dimension};
use numpy::{Element, PyArray, PyArrayMethods};
use pyo3::prelude::*;
use seethru::system::capture::Capture;

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
