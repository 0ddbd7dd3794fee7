//! What each display pixel of the driver's view shows against the truth, in directions from
//! the eye: its misregistration, whether the frontal camera could see its truth point (or sky
//! direction) at all, and whether it lies in the display's border band.
//!
//! Whether the frontal camera sees a point is a ray from it towards the point, cut short of
//! it; the rays of neighbouring display pixels are traced together as packets.

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

use crate::analysis::physical::ARCMIN_PER_RAD;
#[cfg(test)]
use crate::render::accel::Hit;
use crate::render::accel::make_ray;
use crate::render::bvh_packet::{PACKET, PacketStack, RayPacket};
use crate::render::frame_over::FrameView;
use crate::render::integrator::RenderContext;
use crate::render::ray::TraceRay;
use crate::render::simd::Isa;
use crate::scene::Scene;
use crate::scene::world::view_bit;
use crate::system::display::{DisplayPlacement, MISSING_ID};

/// Why the frontal camera cannot see a display pixel's truth point.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Missing {
    OutOfView,
    Hidden,
}

/// One display pixel's measurements.
pub(crate) struct Measured {
    pub(crate) misregistration: f32,
    pub(crate) missing: Option<Missing>,
    pub(crate) class: PixelClass,
    /// In the border band of the left, right, top, bottom side.
    pub(crate) sides: [bool; 4],
}

/// What one display pixel shows, for the statistics.
#[derive(Clone, Copy, Default)]
pub(crate) struct PixelClass {
    pub(crate) blank: bool,
    /// Whether the truth / `seethru` shows sky here (the pixel has a misregistration).
    pub(crate) truth_sky: bool,
    pub(crate) shown_sky: bool,
    /// Neither a point nor a direction (a frame without sky directions).
    pub(crate) undefined: bool,
}

/// Measures the display pixels `on_display` (indices of the driver's frames, in order) of
/// `truth`, `seethru` and `occluded`, frames of the driver's camera at `driver_eye`; `band`
/// is the border band's width in display pixels. One answer per display pixel, in order.
pub(crate) fn measure_display_pixels(
    ctx: &RenderContext,
    scene: &Scene,
    driver_eye: DVec3,
    [truth, seethru, occluded]: [FrameView<'_>; 3],
    on_display: &[usize],
    band: u32,
) -> Vec<Measured> {
    let obstacle = &scene.obstacle;
    let placement = DisplayPlacement::new(obstacle);
    let [dw, dh] = obstacle.display_resolution;
    let frontal = &scene.frontal;
    let in_frontal_image = |q: Option<DVec2>| {
        q.is_some_and(|q| {
            q.x >= 0.0 && q.y >= 0.0 && q.x < frontal.width as f64 && q.y < frontal.height as f64
        })
    };
    let frontal_origin = frontal.position();
    // One display pixel's measurements, and the ray towards the frontal camera that decides
    // whether its truth point is hidden from it (direction, reach), where one is needed.
    let per_pixel = |i: usize| -> (Measured, Option<(Vec3, f64)>) {
        let mut out = Measured {
            misregistration: f32::NAN,
            missing: None,
            class: PixelClass::default(),
            sides: [false; 4],
        };
        let mut hidden_query = None;
        // The display pixel coordinates of the point: a curved display's from its UVs.
        let uv = placement.pixel_coords(occluded.get(|f| &f.position, i));
        let (u, v) = (uv.x, uv.y);
        out.sides = [
            u < band as f64,
            u >= (dw - band) as f64,
            v < band as f64,
            v >= (dh - band) as f64,
        ];
        let t = truth.get(|f| &f.position, i);
        let true_dir = shown_direction(t, truth.get(|f| &f.normal, i), driver_eye);
        // Can the frontal camera see the truth's point, or its sky direction?
        if let Some(d) = true_dir {
            let (inside, to, distance) = if t.is_finite() {
                let to = t.as_dvec3() - frontal_origin;
                (
                    in_frontal_image(frontal.project_point(t.as_dvec3())),
                    to,
                    to.length(),
                )
            } else {
                (
                    in_frontal_image(frontal.project_direction(d)),
                    d,
                    f64::INFINITY,
                )
            };
            if !inside {
                out.missing = Some(Missing::OutOfView);
            } else {
                // A surface short of the point (any surface, towards a sky direction).
                let reach = if distance.is_finite() {
                    distance - 1e-3 * distance.max(1.0)
                } else {
                    f64::INFINITY
                };
                hidden_query = Some((to.normalize().as_vec3(), reach));
            }
        }
        if seethru.get(|f| &f.object_id, i) == MISSING_ID {
            out.class.blank = true;
            return (out, hidden_query);
        }
        let shown = seethru.get(|f| &f.position, i);
        let shown_dir = shown_direction(shown, seethru.get(|f| &f.normal, i), driver_eye);
        match (shown_dir, true_dir) {
            (Some(a), Some(b)) => {
                out.misregistration = (angle_between(a, b) * ARCMIN_PER_RAD) as f32;
                out.class.truth_sky = !t.is_finite();
                out.class.shown_sky = !shown.is_finite();
            }
            _ => out.class.undefined = true,
        }
        (out, hidden_query)
    };
    // Runs of PACKET display pixels in parallel, their rays to the frontal camera traced as
    // one packet: the same answers for any number of threads.
    let isa = Isa::best();
    on_display
        .par_chunks(PACKET)
        .map(|run| {
            PacketStack::with_thread_stack(|stack| {
                let mut queries = [(Vec3::X, 0.0); PACKET];
                let mut asked = 0u32;
                let mut out: Vec<Measured> = Vec::with_capacity(run.len());
                for (lane, &i) in run.iter().enumerate() {
                    let (m, query) = per_pixel(i);
                    if let Some(q) = query {
                        queries[lane] = q;
                        asked |= 1 << lane;
                    }
                    out.push(m);
                }
                let origin = frontal_origin.as_vec3();
                let hidden = nearer_than_packet(ctx, origin, &queries, asked, isa, stack);
                for (lane, m) in out.iter_mut().enumerate() {
                    if hidden >> lane & 1 != 0 {
                        m.missing = Some(Missing::Hidden);
                    }
                }
                out
            })
        })
        .flatten_iter()
        .collect()
}

/// The direction from `eye` that a pixel shows: towards its world point, or its sky
/// direction (carried in the normal, see [`Frame::normal`]); `None` where nothing is shown.
fn shown_direction(position: Vec3, normal: Vec3, eye: DVec3) -> Option<DVec3> {
    if position.is_finite() {
        Some(position.as_dvec3() - eye)
    } else if normal.is_finite() && normal != Vec3::ZERO {
        Some(-normal.as_dvec3())
    } else {
        None
    }
}

/// The angle between two directions, radians, accurate at small angles.
fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The ray from `origin` along unit `dir` of [`nearer_than`]: the traversal stops a little
/// beyond `reach` (every f32 below `reach` is at most `reach as f32`, below this bound).
fn reach_ray(origin: Vec3, dir: Vec3, reach: f64) -> TraceRay {
    let tmax = if reach.is_finite() {
        (reach as f32).max(0.0).next_up().next_up()
    } else {
        f32::INFINITY
    };
    make_ray(origin, dir, 0.0, tmax)
}

/// Whether the closest surface the frontal camera sees along the ray from `origin` (unit
/// `dir`) is nearer than `reach` m: exactly `ctx.trace(origin, dir, view_bit::FRONTAL)`'s
/// hit at `t < reach`, but the traversal stops a little beyond `reach` and nothing is shaded.
/// One ray at a time: the twin of [`nearer_than_packet`].
#[cfg(test)]
fn nearer_than(ctx: &RenderContext, origin: Vec3, dir: Vec3, reach: f64) -> bool {
    let ray = reach_ray(origin, dir, reach);
    let near = |hit: Option<Hit>| hit.is_some_and(|h| (h.t as f64) < reach);
    near(ctx.accel.closest(&ray, view_bit::FRONTAL))
        || ctx
            .moving
            .as_ref()
            .is_some_and(|m| near(m.accel.closest(&ray, view_bit::FRONTAL)))
}

/// [`nearer_than`] for the rays from `origin` of the lanes of `lanes` (bit i for lane i),
/// lane i along `queries[i].0` to `queries[i].1` m, traced as one packet on `isa`'s kernels:
/// bit i of the answer is lane i's. The rays of neighbouring display pixels from one camera
/// are coherent, and the packet kernels give the per-ray hits bit for bit.
fn nearer_than_packet(
    ctx: &RenderContext,
    origin: Vec3,
    queries: &[(Vec3, f64); PACKET],
    lanes: u32,
    isa: Isa,
    stack: &mut PacketStack,
) -> u32 {
    if lanes == 0 {
        return 0;
    }
    let mut packet = RayPacket::new();
    for (lane, &(dir, reach)) in queries.iter().enumerate() {
        if lanes >> lane & 1 != 0 {
            packet.set(lane, &reach_ray(origin, dir, reach));
        }
    }
    let rays = packet;
    // A lane never set, or left out of `rest` (already near), holds no hit.
    let near_in = |packet: &RayPacket| {
        (0..PACKET)
            .filter(|&lane| {
                packet
                    .hit(lane)
                    .is_some_and(|h| (h.t as f64) < queries[lane].1)
            })
            .fold(0u32, |bits, lane| bits | 1 << lane)
    };
    ctx.accel
        .closest_packet(&mut packet, view_bit::FRONTAL, isa, stack);
    let mut near = near_in(&packet);
    if let Some(m) = &ctx.moving {
        let mut rest = rays;
        rest.active &= !near;
        if rest.active != 0 {
            m.accel
                .closest_packet(&mut rest, view_bit::FRONTAL, isa, stack);
            near |= near_in(&rest);
        }
    }
    near
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The packet query against its per-ray twin, on das seen from the frontal camera, with
    /// a moving layer (the car and the ball, carried 3 m towards the camera and 1 m left) that
    /// alone decides some lanes: every reach from the camera's near field to infinity.
    #[test]
    fn the_packet_query_answers_as_the_per_ray_one() {
        use crate::render::moving::MovingParts;
        use std::sync::Arc;
        let scene = Scene::bundled("das.toml");
        let mut ctx = RenderContext::new(scene.clone()).unwrap();
        let movers = |i: usize| ["car", "ball"].contains(&scene.objects[i].name.as_str());
        let moved = glam::DAffine3::from_translation(DVec3::new(-1.0, 0.0, 3.0));
        let layer = MovingParts::new(&scene, &movers)
            .unwrap()
            .at(&|_| Some(moved))
            .unwrap();
        ctx.moving = Some(Arc::new(layer));
        let camera = &scene.frontal;
        let origin = camera.position().as_vec3();
        let mut stack = PacketStack::new();
        let (mut rays, mut near, mut by_moving) = (0, 0, 0);
        for (k, isa) in Isa::ALL.into_iter().filter(|i| i.available()).enumerate() {
            for y in (0..camera.height).step_by(9) {
                for x0 in (0..camera.width).step_by(4 * PACKET) {
                    let mut queries = [(Vec3::X, 0.0); PACKET];
                    let mut lanes = 0u32;
                    for (lane, query) in queries.iter_mut().enumerate() {
                        let x = x0 + 3 * lane as u32;
                        // Every third lane idle; reaches 0.5 m to 154 m and infinity.
                        if x >= camera.width || lane % 3 == 2 {
                            continue;
                        }
                        let pixel = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                        let (_, dir) = camera.world_ray(pixel);
                        let reach = match (x + y) % 8 {
                            0 => f64::INFINITY,
                            // Exactly the static surface's distance: it is not nearer.
                            7 => ctx
                                .accel
                                .closest(
                                    &reach_ray(origin, dir.as_vec3(), f64::INFINITY),
                                    view_bit::FRONTAL,
                                )
                                .map_or(1.0, |h| f64::from(h.t)),
                            r => 0.5 * 2.6f64.powi(r as i32),
                        };
                        *query = (dir.as_vec3(), reach);
                        lanes |= 1 << lane;
                    }
                    let got = nearer_than_packet(&ctx, origin, &queries, lanes, isa, &mut stack);
                    for (lane, &(dir, reach)) in queries.iter().enumerate() {
                        let asked = lanes >> lane & 1 != 0;
                        let want = asked && nearer_than(&ctx, origin, dir, reach);
                        assert_eq!(got >> lane & 1 != 0, want, "{isa:?} ({x0}+3·{lane}, {y})");
                        if k == 0 && asked {
                            rays += 1;
                            near += usize::from(want);
                            let alone = ctx
                                .accel
                                .closest(&reach_ray(origin, dir, reach), view_bit::FRONTAL);
                            let by_static = alone.is_some_and(|h| (h.t as f64) < reach);
                            by_moving += usize::from(want && !by_static);
                        }
                    }
                }
            }
        }
        // Both answers, and the moving layer's, in numbers.
        assert!(near > rays / 5 && near < rays * 4 / 5, "{near} of {rays}");
        assert!(by_moving > 20, "{by_moving}");
    }
}
