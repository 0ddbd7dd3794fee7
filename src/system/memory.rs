//! How much memory a command will need, estimated from its image sizes before anything is
//! allocated, so that a resolution the machine cannot hold is refused with numbers instead
//! of aborting halfway through an allocation.

use anyhow::{Result, bail};

use std::mem::size_of;

use crate::geometry::camera::Camera;
use crate::render::accel::Hit;
use crate::render::frame::Frame;
use crate::render::throughput::BatchRay;
use crate::scene::Scene;
use crate::scene::world::World;
use crate::system::options::RunOptions;

/// Bytes of one frame pixel: every AOV of [`Frame`].
pub const FRAME_BYTES_PER_PIXEL: u64 = Frame::BYTES_PER_PIXEL;

/// Bytes per pixel of the EXR being encoded beside a frame: its channels copied out (17 f32
/// or u32 channels).
const EXR_BYTES_PER_PIXEL: u64 = 17 * 4;

/// Bytes per driver-view pixel of the metrics: misregistration, masks, the SSIM and FLIP
/// working images of the display's bounding box (at most the view).
const METRICS_BYTES_PER_PIXEL: u64 = 64;

/// Memory a command needs beyond the scene: what the estimate counts, for the error message.
#[derive(Clone, Debug, PartialEq)]
pub struct MemoryEstimate {
    pub bytes: u64,
    pub what: String,
}

/// Default limit of `--max-memory`, GiB: a third of a 24 GiB machine.
pub const DEFAULT_MAX_MEMORY_GIB: f64 = 8.0;

fn pixels(camera: &Camera) -> u64 {
    camera.width as u64 * camera.height as u64
}

/// `render`: one view at a time is held and encoded.
pub fn render_estimate(cameras: &[Camera]) -> MemoryEstimate {
    let largest = cameras.iter().max_by_key(|c| pixels(c));
    let bytes = largest.map_or(0, |c| {
        pixels(c) * (FRAME_BYTES_PER_PIXEL + EXR_BYTES_PER_PIXEL)
    });
    MemoryEstimate {
        bytes,
        what: largest.map_or(String::new(), |c| {
            format!("a {}×{} view and its EXR", c.width, c.height)
        }),
    }
}

/// `run`: the six views are held together, written side by side (as many EXRs encoded at
/// once as there are threads, up to all six), and measured.
pub fn run_estimate(scene: &Scene, options: &RunOptions) -> Result<MemoryEstimate> {
    let driver = options.sized_driver(scene.driver)?;
    let frontal = options.sized_frontal(scene.frontal)?;
    let back = options.sized_back(scene.back)?;
    let [dw, dh] = scene.obstacle.display_resolution;
    let display = dw as u64 * dh as u64;
    let frames = 3 * pixels(&driver) + pixels(&frontal) + pixels(&back) + display;
    // A depth sensor's frame and inverse-depth image, at most at the frontal resolution.
    let sensor = if options.method.models_the_scene() {
        pixels(&frontal) * (FRAME_BYTES_PER_PIXEL + 4)
    } else {
        0
    };
    let bytes = frames * (FRAME_BYTES_PER_PIXEL + EXR_BYTES_PER_PIXEL)
        + pixels(&driver) * METRICS_BYTES_PER_PIXEL
        + sensor;
    Ok(MemoryEstimate {
        bytes,
        what: format!(
            "three {}×{} driver views, a {}×{} frontal and a {}×{} back view, their EXRs and the metrics",
            driver.width, driver.height, frontal.width, frontal.height, back.width, back.height
        ),
    })
}

/// Bytes of the metric maps of a driver view of `pixels` pixels, for a command that keeps
/// them beyond a run.
pub fn metric_maps_bytes(pixels: u64) -> u64 {
    pixels * METRICS_BYTES_PER_PIXEL
}

/// `run --eyes both`: one run at a time, plus the first eye's `seethru` and `display` frames
/// kept for the binocular outputs while the second eye runs.
pub fn both_eyes_estimate(scene: &Scene, options: &RunOptions) -> Result<MemoryEstimate> {
    let one = run_estimate(scene, options)?;
    let driver = options.sized_driver(scene.driver)?;
    let [dw, dh] = scene.obstacle.display_resolution;
    let kept = (pixels(&driver) + dw as u64 * dh as u64) * FRAME_BYTES_PER_PIXEL;
    Ok(MemoryEstimate {
        bytes: one.bytes + kept,
        what: format!(
            "{}, and the first eye's seethru and display views",
            one.what
        ),
    })
}

/// Bytes kept per frame of a sequence for frames.csv and the summaries (its times, eyes and
/// metrics; a generous bound).
const SEQUENCE_RECORD_BYTES: u64 = 512;

/// Bytes per preview pixel a sequence keeps until the end: the truth and seethru panels
/// (sRGB) and the misregistration (f32).
const PREVIEW_BYTES_PER_PIXEL: u64 = 3 + 3 + 4;

/// Longest side of a preview panel and the preview's highest frame rate (the preview's own
/// limits, `measure::sequence_files`), for the estimate's bound.
const PREVIEW_SIDE: u64 = 320;
const PREVIEW_FPS: f64 = 30.0;

/// `sequence`: one frame of the system at a time (as `run` holds them), the preview panels of
/// every previewed frame, and the records of every frame of all `sequences` (one per camera
/// latency) of `frames` frames at `fps`.
pub fn sequence_estimate(
    scene: &Scene,
    options: &RunOptions,
    frames: u64,
    fps: f64,
    sequences: u64,
) -> Result<MemoryEstimate> {
    let one = run_estimate(scene, options)?;
    let driver = options.sized_driver(scene.driver)?;
    let panel = (driver.width as u64).min(PREVIEW_SIDE) * (driver.height as u64).min(PREVIEW_SIDE);
    let every = (fps / PREVIEW_FPS).ceil().max(1.0) as u64;
    let previewed = frames.div_ceil(every);
    let preview = previewed.saturating_mul(panel * PREVIEW_BYTES_PER_PIXEL);
    let records = frames
        .saturating_mul(sequences)
        .saturating_mul(SEQUENCE_RECORD_BYTES);
    Ok(MemoryEstimate {
        bytes: one.bytes.saturating_add(preview).saturating_add(records),
        what: format!(
            "{}, {previewed} preview frames and the records of {sequences}×{frames} frames",
            one.what
        ),
    })
}

/// Bytes per triangle of a grown scene, an upper bound: its object's copy in the scene, the
/// world's triangle, its BVH share and the build's working arrays (peak RSS against 1×:
/// 333 bytes on das grown 50×, 576 grown 1000×, docs/reference/benchmark.md).
const GROWN_TRIANGLE_BYTES: u64 = 640;

/// `bench`: the trace-only batches at `width`×`height` (primary, shadow and incoherent rays
/// of 24 bytes, at most one of each per pixel; the packet and per-ray primary hits and the
/// incoherent hits; the packet and per-ray shadow flags and the incoherent ones) and one shaded frame, all held while the scene grown
/// `grow`× is traced; then the `run` it times at the scene's own sizes, with the batches
/// still held.
/// With `flatten`, the instanced meshes count as the triangles they flatten to.
pub fn bench_estimate(
    scene: &Scene,
    width: u32,
    height: u32,
    grow: f64,
    flatten: bool,
) -> Result<MemoryEstimate> {
    let pixels = width as u64 * height as u64;
    let per_pixel = 3 * size_of::<BatchRay>() as u64
        + 3 * size_of::<Option<Hit>>() as u64
        + 3 * size_of::<bool>() as u64
        + FRAME_BYTES_PER_PIXEL;
    let world = World::build(scene)?;
    let flattened = if flatten { world.instanced_count() } else { 0 };
    let triangles = (world.triangles.len() + flattened) as u64;
    let grown = (triangles as f64 * grow).ceil() as u64;
    let run = run_estimate(scene, &RunOptions::default())?;
    Ok(MemoryEstimate {
        bytes: pixels
            .saturating_mul(per_pixel)
            .saturating_add(grown.saturating_mul(GROWN_TRIANGLE_BYTES))
            .saturating_add(run.bytes),
        what: format!(
            "{width}×{height} rays and hits, a scene of about {grown} triangles, and a run: {}",
            run.what
        ),
    })
}

/// The largest of several estimates (commands that run them one after another).
pub fn largest(estimates: impl IntoIterator<Item = MemoryEstimate>) -> MemoryEstimate {
    estimates
        .into_iter()
        .max_by_key(|e| e.bytes)
        .unwrap_or(MemoryEstimate {
            bytes: 0,
            what: String::new(),
        })
}

/// Refuses an estimate above `limit_gib`, saying what it counts and how to proceed.
pub fn check_memory(estimate: &MemoryEstimate, limit_gib: f64) -> Result<()> {
    let gib = estimate.bytes as f64 / (1u64 << 30) as f64;
    if gib > limit_gib {
        // Three significant digits: a small limit must not read "needs 0.0 GiB, more than 0.001".
        let decimals = (2.0 - gib.log10().floor()).clamp(1.0, 9.0) as usize;
        bail!(
            "this needs about {gib:.decimals$} GiB ({}), more than option `max_memory` {limit_gib} GiB: lower the resolution, or raise option `max_memory` if the machine has the memory",
            estimate.what
        );
    }
    Ok(())
}
