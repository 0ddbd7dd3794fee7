//! What the pillar hides from the driver: its obstruction angle, as vehicle standards state
//! it (the angle of the driver's horizontal field of view it blocks, monocular and binocular,
//! degrees), with and without the display; and how much of the display the driver sees.
//!
//! The sight plane is the plane through the eye that contains the line of sight to the
//! display's centre and the horizontal direction across it (world +y is up): the horizontal
//! plane through the eye when the display's centre is at eye height. Rays are cast in it
//! every [`STEP_DEG`] over ±[`SPAN_DEG`] around that line of sight, in the `occluded` view: a
//! ray is blocked when the first thing it meets is the obstacle (without the display), or the
//! obstacle's body (with it: the display shows what is behind it). Binocular: the directions
//! that both eyes, `ipd` apart across the sight plane, have blocked (for a distant scene, what
//! neither eye sees).

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use serde_json::json;

use crate::geometry::camera::Camera;
use crate::render::bvh_packet::{PACKET, PacketStack};
use crate::render::integrator::RenderContext;
use crate::scene::world::view_bit;
use crate::system::surface_map::display_points;

/// Ray spacing of the sweep, degrees (the angles are quantised to it).
pub const STEP_DEG: f64 = 0.005;
/// Half the sweep, degrees, around the line of sight to the display's centre.
pub const SPAN_DEG: f64 = 30.0;

/// Blocked angles, degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obstruction {
    pub monocular_without_display: f64,
    pub monocular_with_display: f64,
    pub binocular_without_display: f64,
    pub binocular_with_display: f64,
}

/// Per ray of the sweep from `eye`: (blocked by the obstacle, blocked by its body).
fn sweep(ctx: &RenderContext, eye: DVec3, forward: DVec3, across: DVec3) -> Vec<(bool, bool)> {
    let n = (2.0 * SPAN_DEG / STEP_DEG).round() as usize;
    let angles: Vec<usize> = (0..=n).collect();
    angles
        .par_chunks(PACKET)
        .map(|run| {
            PacketStack::with_thread_stack(|stack| {
                let dirs: Vec<Option<Vec3>> = run
                    .iter()
                    .map(|&i| {
                        let phi = (-SPAN_DEG + i as f64 * STEP_DEG).to_radians();
                        Some((forward * phi.cos() + across * phi.sin()).as_vec3())
                    })
                    .collect();
                let hits = ctx.trace_fan(eye.as_vec3(), &dirs, view_bit::OCCLUDED, stack);
                hits[..run.len()]
                    .iter()
                    .map(|hit| match hit {
                        Some(hit) if hit.object == ctx.world.obstacle_id => {
                            (true, !ctx.world.is_display(hit.object, hit.part))
                        }
                        _ => (false, false),
                    })
                    .collect::<Vec<_>>()
            })
        })
        .flatten_iter()
        .collect()
}

/// The obstruction angles for the cyclopean eye `eye` (world) and eyes `ipd` metres apart.
pub fn obstruction(ctx: &RenderContext, eye: DVec3, ipd: f64) -> Obstruction {
    let centre = ctx
        .scene
        .obstacle
        .world_from_obstacle
        .transform_point3(DVec3::ZERO);
    let forward = (centre - eye).normalize();
    let across = forward.cross(DVec3::Y).normalize_or(DVec3::X);
    let mono = sweep(ctx, eye, forward, across);
    let left = sweep(ctx, eye - across * ipd / 2.0, forward, across);
    let right = sweep(ctx, eye + across * ipd / 2.0, forward, across);
    let angle = |count: usize| count as f64 * STEP_DEG;
    let both = |pick: fn(&(bool, bool)) -> bool| {
        angle(
            left.iter()
                .zip(&right)
                .filter(|(l, r)| pick(l) && pick(r))
                .count(),
        )
    };
    Obstruction {
        monocular_without_display: angle(mono.iter().filter(|b| b.0).count()),
        monocular_with_display: angle(mono.iter().filter(|b| b.1).count()),
        binocular_without_display: both(|b| b.0),
        binocular_with_display: both(|b| b.1),
    }
}

/// Display pixels whose centre the driver sees: inside the driver camera's view and the first
/// thing the eye's ray to it meets.
pub fn display_pixels_seen(ctx: &RenderContext, driver: &Camera) -> usize {
    let eye = driver.position();
    // The eye's ray to a point inside the driver's view, and the point's distance.
    let ray_to = |p: Option<DVec3>| {
        let p = p?;
        let px = driver.project_point(p)?;
        let inside =
            px.x >= 0.0 && px.y >= 0.0 && px.x < driver.width as f64 && px.y < driver.height as f64;
        let to = p - eye;
        let dist = to.length();
        inside.then(|| ((to / dist).as_vec3(), dist))
    };
    display_points(&ctx.scene.obstacle)
        .par_chunks(PACKET)
        .map(|points| {
            PacketStack::with_thread_stack(|stack| {
                let rays: Vec<Option<(Vec3, f64)>> = points.iter().map(|&p| ray_to(p)).collect();
                let dirs: Vec<Option<Vec3>> = rays.iter().map(|r| r.map(|(dir, _)| dir)).collect();
                let hits = ctx.trace_fan(eye.as_vec3(), &dirs, view_bit::OCCLUDED, stack);
                hits.iter()
                    .zip(&rays)
                    .filter(|(hit, ray)| match (hit, ray) {
                        (Some(hit), Some((_, dist))) => {
                            ctx.world.is_display(hit.object, hit.part)
                                && (f64::from(hit.t) - dist).abs() < 1e-3 * dist.max(1.0)
                        }
                        _ => false,
                    })
                    .count()
            })
        })
        .sum()
}

/// The share of the display below which a run warns that the driver sees only a sliver of it.
pub const SLIVER_SHARE: f64 = 0.1;

/// `run.json`'s `obstruction` and `display_seen` blocks.
pub fn obstruction_json(ctx: &RenderContext, driver: &Camera, ipd: f64) -> serde_json::Value {
    let o = obstruction(ctx, driver.position(), ipd);
    let [w, h] = ctx.scene.obstacle.display_resolution;
    let total = w as usize * h as usize;
    let seen = display_pixels_seen(ctx, driver);
    json!({
        "obstruction_deg": {
            "monocular_without_display": o.monocular_without_display,
            "monocular_with_display": o.monocular_with_display,
            "binocular_without_display": o.binocular_without_display,
            "binocular_with_display": o.binocular_with_display,
            "eye_separation_m": ipd,
            "step_deg": STEP_DEG,
            "definition": "angle of the sight plane (through the eye, the display's centre and the horizontal across it) whose rays first meet the obstacle (without display) or its body (with display); binocular: blocked for both eyes",
        },
        "display_seen": {
            "display_pixels": total,
            "seen_by_driver": seen,
            "share": seen as f64 / total as f64,
            "definition": "display pixel centres inside the driver's view and the first thing the eye's ray to them meets",
        },
    })
}
