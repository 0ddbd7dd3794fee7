//! Metrics of a `seethru` frame against the `truth` (docs/DESIGN.md §6), over every pixel of the
//! driver's view where the display is: misregistration, border mismatch, PSNR/SSIM/FLIP and
//! missing pixels, each mean beside the coverage it was taken over.
//!
//! Every display pixel counts. A pixel that shows sky (in the truth, in `seethru`, or both)
//! has a misregistration like any other: the angle at the eye between the direction shown
//! and the direction the truth has (a direction at infinity is as well defined as a point).
//! Only blank pixels — display pixels whose crop point is outside the frontal view — have
//! none; they are counted, and every region reports its `coverage` beside its means. The
//! image metrics see them as the black they show.
//!
//! The steps: each display pixel's geometry (measure/misregistration.rs), the image metrics
//! (measure/image_metrics.rs), and their statistics as metrics.json (measure/metrics_json.rs).

use glam::DVec3;

use crate::measure::image_metrics::{DisplayImages, Flip};
use crate::measure::luminance::luminance_metrics;
use crate::measure::metrics_json::{Metrics, display_metrics};
use crate::measure::misregistration::{Measured, measure_display_pixels};
use crate::render::frame_over::FrameView;
use crate::render::integrator::RenderContext;
use crate::scene::Scene;

/// Per-pixel results over the driver's view (NaN / false outside the display region).
pub struct MetricMaps {
    pub width: u32,
    pub height: u32,
    /// Angle at the eye between what `seethru` shows and what the truth has, arc-minutes; NaN
    /// outside the display and on blank pixels.
    pub misregistration: Vec<f32>,
    /// Display pixels whose truth point (or sky direction) the frontal camera cannot see.
    pub missing: Vec<bool>,
    /// Pixels where the driver sees the display.
    pub display: Vec<bool>,
    /// Display pixels that show nothing (their crop point is outside the frontal image).
    pub blank: Vec<bool>,
    /// SSIM and FLIP per pixel (NaN outside the display), for statistics over parts of it.
    pub ssim: Vec<f64>,
    pub flip: Vec<f64>,
}

#[cfg(test)]
impl MetricMaps {
    /// Maps for the tests of what reads them: the given misregistration and masks, no pixel
    /// missing, SSIM and FLIP not computed (NaN).
    pub(crate) fn of_masks(
        [width, height]: [u32; 2],
        misregistration: Vec<f32>,
        display: Vec<bool>,
        blank: Vec<bool>,
    ) -> MetricMaps {
        let n = misregistration.len();
        assert_eq!(n, width as usize * height as usize);
        MetricMaps {
            width,
            height,
            misregistration,
            missing: vec![false; n],
            display,
            blank,
            ssim: vec![f64::NAN; n],
            flip: vec![f64::NAN; n],
        }
    }
}

/// Computes the maps and the metrics (metrics.json). `truth`, `seethru` and `occluded` are frames of the
/// driver's camera at `driver_eye` (as rendered by `run`); `band` is the border band width in
/// display pixels.
pub fn measure(
    ctx: &RenderContext,
    scene: &Scene,
    driver_eye: DVec3,
    frames: [FrameView<'_>; 3],
    band: u32,
) -> (MetricMaps, Metrics) {
    measure_with(ctx, scene, driver_eye, frames, band, Flip::Computed)
}

/// [`measure`], with FLIP computed or not.
pub fn measure_with(
    ctx: &RenderContext,
    scene: &Scene,
    driver_eye: DVec3,
    frames: [FrameView<'_>; 3],
    band: u32,
    flip: Flip,
) -> (MetricMaps, Metrics) {
    let [truth, seethru, occluded] = frames;
    let display = display_mask(ctx, occluded);
    // Every statistic is over display pixels, taken in index order (row by row): the same
    // sums as a pass over the whole frame, without visiting the rest of it. What is kept per
    // display pixel is kept in that order (index k of `on_display`), not over the frame.
    let on_display: Vec<usize> = (0..display.len()).filter(|&i| display[i]).collect();
    let measured = measure_display_pixels(ctx, scene, driver_eye, frames, &on_display, band);
    let images = DisplayImages::score(truth, seethru, &on_display, &scene.driver, flip);
    let width = truth.width() as usize;
    let mut metrics = display_metrics(scene, width, &measured, &images, band, flip);
    if let Some(photometry) = &scene.photometry {
        let border: Vec<bool> = measured
            .iter()
            .map(|m| m.sides.iter().any(|&s| s))
            .collect();
        metrics.luminance = Some(luminance_metrics(
            photometry,
            truth,
            seethru,
            &on_display,
            &border,
        ));
    }
    let maps = MetricMaps::of(truth, display, &on_display, &measured, &images);
    (maps, metrics)
}

/// Which pixels of `occluded` (the driver's view with the obstacle) show the display.
fn display_mask(ctx: &RenderContext, occluded: FrameView<'_>) -> Vec<bool> {
    let (w, h) = (occluded.width() as usize, occluded.height() as usize);
    let mut display: Vec<bool> = Vec::with_capacity(w * h);
    for y in 0..h as u32 {
        let parts = occluded.row(|f| &f.part_id, y);
        for (ids, parts) in occluded.row(|f| &f.object_id, y).iter().zip(parts) {
            let shown = ids.iter().zip(parts);
            display.extend(shown.map(|(&o, &p)| ctx.world.is_display(o, p)));
        }
    }
    display
}

impl MetricMaps {
    /// The maps of frames like `truth`, given the pixels that show the `display`, those
    /// pixels' indices `on_display`, and their `measured` geometry and `images` scores.
    fn of(
        truth: FrameView<'_>,
        display: Vec<bool>,
        on_display: &[usize],
        measured: &[Measured],
        images: &DisplayImages,
    ) -> MetricMaps {
        let (w, h) = (truth.width() as usize, truth.height() as usize);
        let mut misregistration = vec![f32::NAN; w * h];
        let mut missing = vec![false; w * h];
        let mut blank = vec![false; w * h];
        for (&i, m) in on_display.iter().zip(measured) {
            misregistration[i] = m.misregistration;
            missing[i] = m.missing.is_some();
            blank[i] = m.class.blank;
        }
        MetricMaps {
            width: w as u32,
            height: h as u32,
            misregistration,
            missing,
            display,
            blank,
            ssim: images.scatter(&images.ssim, w * h),
            flip: images.scatter(&images.flip, w * h),
        }
    }
}
