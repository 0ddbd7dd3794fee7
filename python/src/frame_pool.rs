//! Recycled frame buffers: when Python drops the last reference to a [`crate::frame::PyFrame`]
//! and its arrays, the frame's buffers come back here ([`crate::borrowed::FrameBuffers`]'s
//! `Drop`), and the next `Scene.render` of the same size renders into them instead of
//! allocating new ones. A loop `for ...: f = scene.render(...)` then reuses memory the
//! kernel has already faulted in: a new 640×360 frame is 12 MB, which glibc maps fresh
//! (and unmaps on free) for every call, and faulting it in cost the render about a third of
//! its time.
//!
//! A buffer is only recycled once nothing can see it: numpy keeps the owner alive as the
//! base of every array and view of it, so a frame or array Python still holds is never
//! handed out again. Results do not depend on what a recycled buffer held: a render writes
//! every field of every pixel of its frame.
//!
//! Bounded ([`MAX_FRAMES`], [`MAX_BYTES`]; the oldest are freed first) and thread-safe (one
//! mutex, held only to push or pop).

use std::sync::Mutex;

use seethru::render::frame::Frame;

/// Most frames kept for reuse.
pub const MAX_FRAMES: usize = 8;
/// Most bytes of buffers kept for reuse (a 1280×720 frame is 48 MB).
pub const MAX_BYTES: u64 = 256 << 20;

/// Freed frames, oldest first.
static POOL: Mutex<Vec<Frame>> = Mutex::new(Vec::new());

fn pool() -> std::sync::MutexGuard<'static, Vec<Frame>> {
    // A panic while holding it left a list of whole frames: still usable.
    POOL.lock().unwrap_or_else(|e| e.into_inner())
}

/// Bytes of `frame`'s buffers.
pub fn bytes(frame: &Frame) -> u64 {
    frame.width as u64 * frame.height as u64 * Frame::BYTES_PER_PIXEL
}

/// A `width`×`height` frame to render into: a recycled one of that size (holding an earlier
/// render's pixels) or a new one (zeroed by the allocator, so its pages are faulted in by the
/// render's threads as they write them, not one by one here). Either way every pixel must be
/// written before the frame is shown.
pub fn take(width: u32, height: u32) -> Frame {
    let recycled = {
        let mut free = pool();
        let newest = free
            .iter()
            .rposition(|f| (f.width, f.height) == (width, height));
        newest.map(|i| free.remove(i))
    };
    recycled.unwrap_or_else(|| zeroed(width, height))
}

/// Keeps `frame` for reuse, freeing the oldest frames beyond the bounds.
pub fn give(frame: Frame) {
    if frame.depth.is_empty() || bytes(&frame) > MAX_BYTES {
        return;
    }
    let evicted = {
        let mut free = pool();
        free.push(frame);
        let mut evicted = Vec::new();
        while free.len() > MAX_FRAMES || free.iter().map(bytes).sum::<u64>() > MAX_BYTES {
            evicted.push(free.remove(0));
        }
        evicted
    };
    // Freed after the lock is released (unmapping 50 MB takes a while).
    drop(evicted);
}

/// (frames, bytes) kept now.
fn kept() -> (usize, u64) {
    let free = pool();
    (free.len(), free.iter().map(bytes).sum())
}

/// A frame whose buffers come from `alloc_zeroed` (`vec![0; n]` of a type the standard
/// library knows is zero when all its bits are): fresh pages from the kernel that nobody
/// touches until the render writes them.
fn zeroed(width: u32, height: u32) -> Frame {
    let n = width as usize * height as usize;
    let vectors = || -> Vec<glam::Vec3> { bytemuck::allocation::cast_vec(vec![0.0f32; 3 * n]) };
    Frame {
        width,
        height,
        color: vectors(),
        white_cd_m2: None,
        exposure: None,
        depth: vec![0.0; n],
        camera_z: vec![0.0; n],
        position: vectors(),
        normal: vectors(),
        object_id: vec![0; n],
        part_id: vec![0; n],
    }
}

/// `seethru.frame_pool()`: what is kept for reuse, and the bounds; with `clear=True`, frees
/// it first.
#[pyo3::pyfunction]
#[pyo3(signature = (clear=false))]
pub fn frame_pool(
    py: pyo3::Python<'_>,
    clear: bool,
) -> pyo3::PyResult<pyo3::Bound<'_, pyo3::types::PyDict>> {
    use pyo3::types::PyDictMethods;
    if clear {
        drop(std::mem::take(&mut *pool()));
    }
    let (frames, bytes) = kept();
    let dict = pyo3::types::PyDict::new(py);
    dict.set_item("frames", frames)?;
    dict.set_item("bytes", bytes)?;
    dict.set_item("max_frames", MAX_FRAMES)?;
    dict.set_item("max_bytes", MAX_BYTES)?;
    Ok(dict)
}
