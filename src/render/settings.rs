//! Render settings and their limits: samples per pixel, and image sizes after the
//! command line's overrides.

use anyhow::{Context, Result, bail};

use crate::geometry::camera::Camera;
use crate::scene::source::{MAX_PIXELS, MAX_RESOLUTION};

/// Largest number of samples per pixel accepted.
pub const MAX_SPP: u32 = 4096;

#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    /// Samples per pixel, in [1, MAX_SPP]. Sample 0 is the pixel centre; the others are
    /// jittered deterministically from (pixel, sample).
    pub spp: u32,
    /// Print a progress line on stderr if the render takes over a second.
    pub progress: bool,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 1,
            progress: false,
        }
    }
}

/// Output size of a camera after optional `--width`/`--height` overrides. Given one side
/// only, the other follows the camera's aspect ratio. `flags` names the overrides in errors
/// (in the library's words: "option `width`").
pub fn resized(
    camera: Camera,
    width: Option<u32>,
    height: Option<u32>,
    flags: &str,
) -> Result<Camera> {
    let aspect = camera.width as f64 / camera.height as f64;
    let (w, h) = match (width, height) {
        (None, None) => (camera.width, camera.height),
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, ((w as f64 / aspect).round() as u32).max(1)),
        (None, Some(h)) => (((h as f64 * aspect).round() as u32).max(1), h),
    };
    if width.is_some() || height.is_some() {
        check_resolution(w, h).with_context(|| {
            format!(
                "{flags} gives {w}×{h} (a side not given follows the camera's aspect {})",
                crate::util::number::short(aspect)
            )
        })?;
    } else {
        check_resolution(w, h)?;
    }
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
            "{w}×{h} pixels are out of range: each side in [1, {MAX_RESOLUTION}], at most {MAX_RESOLUTION}×{} in all",
            MAX_PIXELS / MAX_RESOLUTION as u64
        );
    }
    Ok(())
}

pub fn check_spp(spp: u32) -> Result<()> {
    if !(1..=MAX_SPP).contains(&spp) {
        bail!("option `spp` {spp} is out of range [1, {MAX_SPP}]");
    }
    Ok(())
}
