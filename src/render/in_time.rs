//! A camera's frame over its shutter's instants when the world moves too (objects on paths,
//! what rides with the vehicle or the head: the context's moving layer).
//!
//! Where the camera's view shows nothing of the moving layer, or its shutter is an instant,
//! the frame is one pass over the context of the frame's instant, each sample traced from
//! the camera's pose at its own instant ([`RenderJob::moving`]). Otherwise the world itself
//! differs from instant to instant: the frame is rendered band by band of rows and slice by
//! slice of the exposure, each over the world placed at its instant (a cheap refit of the
//! moving layer's hierarchy), the camera still exact per row, and each pixel's samples are
//! summed in the order the one pass sums them, so the two agree bit for bit where the world
//! stands still.

use std::sync::Arc;

use anyhow::Result;
use glam::Vec3;
use rayon::prelude::*;

use crate::geometry::shutter::Shutter;
use crate::render::footprint::PixelRect;
use crate::render::frame::{Frame, Rows};
use crate::render::integrator::RenderContext;
use crate::render::render_job::{BAND_ROWS, RenderJob, RenderStats};

/// Memory the instant-by-instant path gives the contexts it holds at once (each holds a copy
/// of the moving layer), bytes: all of a frame's bands for a small moving layer (das's ball,
/// head and obstacle: one pass, no wait between groups of bands), fewer for a large one.
const CONTEXT_BYTES: usize = 256 << 20;

/// Fewest bands rendered at once (so that both threads of a small machine have work).
const MIN_BANDS_AT_ONCE: usize = 16;

/// Bands whose contexts fit [`CONTEXT_BYTES`] together, `context` being one of them.
fn bands_at_once(context: &RenderContext) -> usize {
    let triangle = std::mem::size_of::<obvhs::rt_triangle::RtTriangle>();
    let layer = context
        .moving
        .as_ref()
        .map_or(0, |m| m.accel.bytes() + m.world.triangles.len() * triangle);
    (CONTEXT_BYTES / layer.max(1)).max(MIN_BANDS_AT_ONCE)
}

/// The scene at `t` seconds (the caller's clock), ready to render.
pub type ContextAt<'a> = &'a mut dyn FnMut(f64) -> Result<RenderContext>;

/// Whether `job` over `context` must be rendered instant by instant: its shutter spreads
/// over time and its view shows the moving layer.
pub fn needs_instants(context: &RenderContext, job: &RenderJob) -> bool {
    !job.camera.shutter.is_instant()
        && context
            .moving
            .as_ref()
            .is_some_and(|m| m.accel.shows(job.view))
}

/// Renders `job` (its camera at the frame's instant `t`, with its shutter and motion) into
/// `frame`: over `context`, the world at `t`, or where it must be, over the world at each
/// instant from `context_at`.
pub fn render_in_time(
    context: &RenderContext,
    context_at: ContextAt,
    t: f64,
    job: RenderJob,
    frame: &mut Frame,
) -> Result<RenderStats> {
    // The automatic exposure meters the world of the frame's instant.
    let (camera, metered) = context.exposed(&job);
    let job = job.of_camera(&camera);
    let stats = if needs_instants(context, &job) {
        frame.white_cd_m2 = context.white_cd_m2();
        frame.exposure = None;
        render_by_instant(context_at, t, job, frame)?
    } else {
        context.render_into(job, frame)
    };
    crate::render::sensor_image::record_metering(frame, metered);
    Ok(stats)
}

/// The instant, seconds after the frame's, at which the world of the band of rows starting at
/// `y` (of [`BAND_ROWS`]) is placed for sample `sample` of `spp`: the middle of its rows'
/// readouts, plus the sample's place in the exposure.
pub fn band_instant(shutter: &Shutter, y: u32, height: u32, sample: u32, spp: u32) -> f64 {
    let last = (y + BAND_ROWS).min(height) - 1;
    let readout = (shutter.row_time(y, height) + shutter.row_time(last, height)) / 2.0;
    readout + shutter.sample_time(sample, spp)
}

/// [`render_in_time`]'s instant-by-instant path, whatever the view shows: each band of
/// [`BAND_ROWS`] rows and each slice of the exposure over the world placed at its instant
/// ([`band_instant`]), each sample traced from the camera's pose at its own row's instant.
/// Where the world stands still it is [`RenderJob::moving`]'s one pass, bit for bit; a moving
/// object is placed at most 1.5 rows' readout (0.06 ms for 30 ms over 720 rows) from its
/// row's instant.
pub fn render_by_instant(
    context_at: ContextAt,
    t: f64,
    job: RenderJob,
    frame: &mut Frame,
) -> Result<RenderStats> {
    let camera = *job.camera;
    assert_eq!((frame.width, frame.height), (camera.width, camera.height));
    let shutter = camera.shutter;
    let region = job.region.unwrap_or_else(|| PixelRect::full(&camera));
    let spp = job.settings.spp;
    // Slices of the exposure, each its own render; without one, every sample at once.
    let samples: Vec<Option<u32>> = if shutter.exposure_s > 0.0 {
        (0..spp).map(Some).collect()
    } else {
        vec![None]
    };
    let start = std::time::Instant::now();
    let mut stats = RenderStats::default();
    // The region's columns, from the start of its first band (bands start at multiples of
    // BAND_ROWS, so that a pixel's instant does not depend on the region).
    let y0 = region.y0 / BAND_ROWS * BAND_ROWS;
    let width = (region.x1 - region.x0) as usize;
    let mut scratch = Frame::new(region.x1 - region.x0, region.y1 - y0);
    let mut sums = vec![Vec3::ZERO; scratch.color.len()];
    for &sample in &samples {
        let mut one = job;
        one.sample = sample;
        let pixels = one.pixels();
        let bands: Vec<Rows> = scratch.bands_mut_at(BAND_ROWS, region.x0, y0);
        // A global shutter's bands share one instant per slice.
        let instant = |b: &Rows| {
            let y = if shutter.is_rolling() { b.y } else { 0 };
            band_instant(&shutter, y, camera.height, sample.unwrap_or(0), spp)
        };
        let mut bands = bands.into_iter().peekable();
        let mut at_once = MIN_BANDS_AT_ONCE;
        while bands.peek().is_some() {
            let mut work: Vec<(Arc<RenderContext>, Rows)> = Vec::new();
            while work.len() < at_once
                && let Some(band) = bands.next()
            {
                let dt = instant(&band);
                let context = match work.last() {
                    Some((context, last)) if instant(last) == dt => context.clone(),
                    _ => Arc::new(context_at(t + dt)?),
                };
                at_once = bands_at_once(&context);
                work.push((context, band));
            }
            let done: Vec<RenderStats> = work
                .into_par_iter()
                .map(|(context, band)| context.render_bands_of(&one, &pixels, region, vec![band]))
                .collect();
            for s in done {
                stats.primary_rays += s.primary_rays;
                stats.shadow_rays += s.shadow_rays;
            }
        }
        // The first sample's AOVs, every sample's colour summed in order.
        for y in region.y0..region.y1 {
            let (i, j) = (frame.index(region.x0, y), scratch.index(0, y - y0));
            if sample.is_none_or(|s| s == 0) {
                frame.copy_pixels(i, &scratch, j, width);
            }
            for (sum, c) in sums[j..j + width]
                .iter_mut()
                .zip(&scratch.color[j..j + width])
            {
                *sum += *c;
            }
        }
    }
    if samples.len() > 1 {
        for y in region.y0..region.y1 {
            let (i, j) = (frame.index(region.x0, y), scratch.index(0, y - y0));
            let sums = &sums[j..j + width];
            for (c, sum) in frame.color[i..i + width].iter_mut().zip(sums) {
                *c = *sum / spp as f32;
            }
        }
    }
    crate::render::sensor_image::deliver_through_sensor(&camera, frame, region, None);
    stats.seconds = start.elapsed().as_secs_f64();
    Ok(stats)
}
