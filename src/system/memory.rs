//! How much memory a command will need, estimated from its image sizes before anything is
//! allocated, so that a resolution the machine cannot hold is refused with numbers instead
//! of aborting halfway through an allocation.

use anyhow::{Result, bail};

use crate::geometry::camera::Camera;
use crate::render::frame::Frame;
use crate::scene::Scene;
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

/// Refuses an estimate above `limit_gib`, saying what it counts and how to proceed.
pub fn check_memory(estimate: &MemoryEstimate, limit_gib: f64) -> Result<()> {
    let gib = estimate.bytes as f64 / (1u64 << 30) as f64;
    if gib > limit_gib {
        bail!(
            "this needs about {gib:.1} GiB ({}), more than --max-memory {limit_gib} GiB: lower the resolution, or raise --max-memory if the machine has the memory",
            estimate.what
        );
    }
    Ok(())
}
