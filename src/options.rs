//! Options shared by the commands: resolution overrides, samples, threads.

use anyhow::{Result, bail};

use crate::camera::Camera;
use crate::render::MAX_SPP;
use crate::scene_file::{MAX_PIXELS, MAX_RESOLUTION};

/// Output size of a camera after optional `--width`/`--height` overrides. Given one side
/// only, the other follows the camera's aspect ratio.
pub fn resized(camera: Camera, width: Option<u32>, height: Option<u32>) -> Result<Camera> {
    let aspect = camera.width as f64 / camera.height as f64;
    let (w, h) = match (width, height) {
        (None, None) => (camera.width, camera.height),
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, ((w as f64 / aspect).round() as u32).max(1)),
        (None, Some(h)) => (((h as f64 * aspect).round() as u32).max(1), h),
    };
    check_resolution(w, h)?;
    Ok(camera.with_resolution(w, h))
}

pub fn check_resolution(w: u32, h: u32) -> Result<()> {
    if w == 0
        || h == 0
        || w > MAX_RESOLUTION
        || h > MAX_RESOLUTION
        || w as u64 * h as u64 > MAX_PIXELS
    {
        bail!(
            "resolution {w}×{h} is out of range: each side in [1, {MAX_RESOLUTION}], at most {MAX_PIXELS} pixels"
        );
    }
    Ok(())
}

pub fn check_spp(spp: u32) -> Result<()> {
    if !(1..=MAX_SPP).contains(&spp) {
        bail!("--spp {spp} is out of range [1, {MAX_SPP}]");
    }
    Ok(())
}

/// Runs `job` on a pool of `threads` workers (all cores if `None`). Images do not depend on it.
pub fn with_threads<T: Send>(threads: Option<usize>, job: impl FnOnce() -> T + Send) -> Result<T> {
    if let Some(n) = threads
        && !(1..=1024).contains(&n)
    {
        bail!("--threads {n} is out of range [1, 1024]");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?;
    Ok(pool.install(job))
}
