//! A camera's frame over its shutter's instants when the world moves too (objects on paths,
//! what rides with the vehicle or the head: the context's moving layer).
//!
//! Where the camera's view shows nothing of the moving layer, or its shutter is an instant,
//! the frame is one pass over the context of the frame's instant, each sample traced from
//! the camera's pose at its own instant ([`RenderJob::moving`]). Otherwise the world itself
//! differs from instant to instant: the frame is rendered instant by instant (a row of a
//! rolling shutter, a slice of an exposure), each over the context of its instant, and each
//! pixel's samples are summed in the order the one pass sums them, so the two agree bit for
//! bit where both apply.

use std::ops::Range;

use anyhow::Result;
use glam::Vec3;
use rayon::prelude::*;

use crate::geometry::camera::Camera;
use crate::geometry::shutter::Shutter;
use crate::render::footprint::PixelRect;
use crate::render::frame::{Frame, Rows};
use crate::render::integrator::RenderContext;
use crate::render::render_job::{BAND_ROWS, RenderJob, RenderStats};

/// Rows whose contexts are held at once on the instant-by-instant path: each holds a copy of
/// the moving layer.
const ROWS_AT_ONCE: usize = 32;

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
    if needs_instants(context, &job) {
        render_by_instant(context_at, t, job, frame)
    } else {
        Ok(context.render_into(job, frame))
    }
}

/// [`render_in_time`]'s instant-by-instant path, whatever the view shows: the render that
/// [`RenderJob::moving`]'s one pass must equal where the world stands still.
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
    // Rows and samples that share an instant are rendered together.
    let rows: Vec<u32> = if shutter.is_rolling() {
        (region.y0..region.y1).collect()
    } else {
        vec![region.y0]
    };
    let rows_of = |first: u32| {
        if shutter.is_rolling() {
            first..first + 1
        } else {
            region.y0..region.y1
        }
    };
    let samples: Vec<Option<u32>> = if shutter.exposure_s > 0.0 {
        (0..spp).map(Some).collect()
    } else {
        vec![None]
    };
    let mut stats = RenderStats::default();
    let mut sums = vec![Vec3::ZERO; frame.color.len()];
    let mut scratch = Frame::new(camera.width, camera.height);
    for &sample in &samples {
        for chunk in rows.chunks(ROWS_AT_ONCE) {
            let mut at = Vec::with_capacity(chunk.len());
            for &row in chunk {
                let dt = shutter.instant(row, camera.height, sample.unwrap_or(0), spp);
                let pose = job.pose_at.map_or(camera.world_from_camera, |p| p(dt));
                let seen = Camera {
                    world_from_camera: pose,
                    shutter: Shutter::INSTANT,
                    ..camera
                };
                at.push((context_at(t + dt)?, seen, row));
            }
            let bands = scratch.bands_mut(if shutter.is_rolling() { 1 } else { BAND_ROWS });
            let overlaps = |b: &Rows, ys: &Range<u32>| b.y < ys.end && b.y + b.len() > ys.start;
            let mut bands: Vec<_> = bands
                .into_iter()
                .filter(|b| chunk.iter().any(|&r| overlaps(b, &rows_of(r))))
                .collect();
            // Each instant renders its rows into their bands, in parallel.
            let mut work = Vec::new();
            for (context, seen, row) in &at {
                let ys = rows_of(*row);
                let (mine, rest): (Vec<_>, Vec<_>) =
                    bands.into_iter().partition(|b| overlaps(b, &ys));
                bands = rest;
                work.push((context, seen, ys, mine));
            }
            let done: Vec<RenderStats> = work
                .into_par_iter()
                .map(|(context, seen, ys, mine)| {
                    let mut one = job.seen_by(seen);
                    one.sample = sample;
                    let rect = PixelRect {
                        y0: ys.start,
                        y1: ys.end,
                        ..region
                    };
                    context.render_bands(&one, rect, mine)
                })
                .collect();
            for s in done {
                stats.primary_rays += s.primary_rays;
                stats.shadow_rays += s.shadow_rays;
                stats.seconds += s.seconds;
            }
        }
        // The first sample's AOVs, every sample's colour summed in order.
        for y in region.y0..region.y1 {
            let i = frame.index(region.x0, y);
            let n = (region.x1 - region.x0) as usize;
            if sample.is_none_or(|s| s == 0) {
                frame.copy_pixels(i, &scratch, i, n);
            }
            for (sum, c) in sums[i..i + n].iter_mut().zip(&scratch.color[i..i + n]) {
                *sum += *c;
            }
        }
    }
    if samples.len() > 1 {
        for y in region.y0..region.y1 {
            let i = frame.index(region.x0, y);
            let n = (region.x1 - region.x0) as usize;
            for (c, sum) in frame.color[i..i + n].iter_mut().zip(&sums[i..i + n]) {
                *c = *sum / spp as f32;
            }
        }
    }
    Ok(stats)
}
