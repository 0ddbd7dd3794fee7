//! Trace-only workloads for `seethru bench`: batches of rays traced without shading, the way
//! ray tracing kernels (Embree's `rtcIntersect1`/`rtcOccluded1` over arrays of rays) are
//! measured. Rays are made before the clock starts; tracing runs on the rayon pool.
//!
//! Camera rays come in 4×4 tiles of pixels, so that [`PACKET`] consecutive rays of a batch
//! are a tile: [`trace_closest`] and [`trace_any`] trace them as packets (Embree's
//! `rtcIntersect16` on 4×4 tiles), [`trace_closest_per_ray`] and [`trace_any_per_ray`] one by
//! one.

use glam::Vec3;
use rayon::prelude::*;

use crate::geometry::camera::Camera;
use crate::render::accel::{Accel, Hit, make_ray};
use crate::render::bvh::Stack;
use crate::render::bvh_packet::{PACKET, PacketStack, RayPacket};
use crate::render::camera_rays::CameraRays;
use crate::render::integrator::shadow_ray;
use crate::render::ray::TraceRay;
use crate::render::simd::Isa;
use crate::scene::world::World;
use crate::util::sampling::{hash_words, unit_float};

/// Rays traced per rayon task.
const CHUNK: usize = 4096;

/// Rays of one kind, all for one view ([`crate::scene::world::view_bit`]).
pub struct Batch {
    pub rays: Vec<BatchRay>,
    pub view: u8,
}

/// A ray of a batch, searched over [0, ∞): 24 bytes, as compact as Embree's inputs, so that
/// reading the batch costs no more memory traffic than theirs; the tracers prepare it
/// ([`TraceRay`], its reciprocal direction) as they go, as Embree does.
#[derive(Clone, Copy, Debug)]
pub struct BatchRay {
    /// Origin, world frame, metres.
    pub origin: Vec3,
    /// Unit direction, world frame.
    pub dir: Vec3,
}

impl BatchRay {
    #[inline]
    pub fn ray(&self) -> TraceRay {
        make_ray(self.origin, self.dir, 0.0, f32::INFINITY)
    }

    fn of(ray: &TraceRay) -> BatchRay {
        BatchRay {
            origin: ray.origin.into(),
            dir: ray.dir.into(),
        }
    }
}

/// Side of the square tiles of [`camera_batch`], pixels.
pub const TILE: u32 = 4;
const _: () = assert!((TILE * TILE) as usize == PACKET);

/// The pixels of a `width`×`height` image in 4×4 tiles: tiles row by row, and the pixels of
/// a tile row by row (the last tiles of a row and column are cut by the image's edge).
pub fn tile_order(width: u32, height: u32) -> impl Iterator<Item = (u32, u32)> {
    (0..height.div_ceil(TILE)).flat_map(move |ty| {
        (0..width.div_ceil(TILE)).flat_map(move |tx| {
            (ty * TILE..((ty + 1) * TILE).min(height))
                .flat_map(move |y| (tx * TILE..((tx + 1) * TILE).min(width)).map(move |x| (x, y)))
        })
    })
}

/// One ray through each pixel centre, in [`tile_order`].
pub fn camera_batch(camera: &Camera, view: u8) -> Batch {
    let camera_rays = CameraRays::new(camera);
    let rays = tile_order(camera.width, camera.height)
        .map(|(x, y)| {
            let dir = camera_rays.direction(x as f32 + 0.5, y as f32 + 0.5);
            BatchRay {
                origin: camera_rays.origin,
                dir,
            }
        })
        .collect();
    Batch { rays, view }
}

/// Closest hits of `batch` into `out` (same length), [`PACKET`] consecutive rays at a time
/// on `isa`'s packet kernels.
pub fn trace_closest(accel: &Accel, batch: &Batch, isa: Isa, out: &mut [Option<Hit>]) {
    by_packets(batch, out, |packet, stack, out| {
        accel.closest_packet(packet, batch.view, isa, stack);
        for (lane, out) in out.iter_mut().enumerate() {
            *out = packet.hit(lane);
        }
    });
}

/// Whether each ray of `batch` is blocked, into `out` (same length), as [`trace_closest`].
pub fn trace_any(accel: &Accel, batch: &Batch, isa: Isa, out: &mut [bool]) {
    by_packets(batch, out, |packet, stack, out| {
        let blocked = accel.occluded_packet(packet, batch.view, isa, stack);
        for (lane, out) in out.iter_mut().enumerate() {
            *out = blocked >> lane & 1 != 0;
        }
    });
}

/// Calls `trace` on each run of [`PACKET`] consecutive rays of `batch`, packed, with the
/// matching run of `out`; chunks of [`CHUNK`] rays go to the worker threads.
fn by_packets<T: Send>(
    batch: &Batch,
    out: &mut [T],
    trace: impl Fn(&mut RayPacket, &mut PacketStack, &mut [T]) + Sync,
) {
    batch
        .rays
        .par_chunks(CHUNK)
        .zip(out.par_chunks_mut(CHUNK))
        .for_each(|(rays, out)| {
            PacketStack::with_thread_stack(|stack| {
                for (rays, out) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
                    let mut packet = RayPacket::new();
                    packet.set_from_zero(rays.len(), |lane| (rays[lane].origin, rays[lane].dir));
                    trace(&mut packet, stack, out);
                }
            })
        });
}

/// Closest hits of `batch` into `out` (same length), one ray at a time.
pub fn trace_closest_per_ray(accel: &Accel, batch: &Batch, out: &mut [Option<Hit>]) {
    batch
        .rays
        .par_chunks(CHUNK)
        .zip(out.par_chunks_mut(CHUNK))
        .for_each(|(rays, out)| {
            Stack::with_thread_stack(|stack| {
                for (ray, out) in rays.iter().zip(out) {
                    *out = accel.closest_with(&ray.ray(), batch.view, stack);
                }
            })
        });
}

/// Whether each ray of `batch` is blocked, into `out` (same length), one ray at a time.
pub fn trace_any_per_ray(accel: &Accel, batch: &Batch, out: &mut [bool]) {
    batch
        .rays
        .par_chunks(CHUNK)
        .zip(out.par_chunks_mut(CHUNK))
        .for_each(|(rays, out)| {
            Stack::with_thread_stack(|stack| {
                for (ray, out) in rays.iter().zip(out) {
                    *out = accel.occluded_with(&ray.ray(), batch.view, stack);
                }
            })
        });
}

/// The surface points that `hits` of `batch` found: position and normal facing the ray.
fn hit_points<'a>(
    world: &'a World,
    batch: &'a Batch,
    hits: &'a [Option<Hit>],
) -> impl Iterator<Item = (usize, Vec3, Vec3)> + 'a {
    batch
        .rays
        .iter()
        .zip(hits)
        .enumerate()
        .filter_map(|(i, (ray, hit))| {
            let hit = (*hit)?;
            let s = world.surface(hit.prim, ray.origin, ray.dir, hit.t);
            Some((i, s.position, s.normal))
        })
}

/// A shadow ray towards the sun (`sun`, unit) from every hit whose surface faces it, as the
/// integrator casts them.
pub fn shadow_batch(world: &World, batch: &Batch, hits: &[Option<Hit>], sun: Vec3) -> Batch {
    let rays = hit_points(world, batch, hits)
        .filter(|(_, _, n)| n.dot(sun) > 0.0)
        .map(|(_, p, n)| BatchRay::of(&shadow_ray(p, n, sun)))
        .collect();
    Batch {
        rays,
        view: batch.view,
    }
}

/// Incoherent rays: one cosine-distributed direction about the normal at every hit (the rays
/// of diffuse indirect light), from hashed, reproducible random numbers.
pub fn cosine_batch(world: &World, batch: &Batch, hits: &[Option<Hit>]) -> Batch {
    let rays = hit_points(world, batch, hits)
        .map(|(i, p, n)| {
            let (u1, u2) = (
                unit_float(hash_words(&[i as u32, 1])),
                unit_float(hash_words(&[i as u32, 2])),
            );
            // Malley's method: a uniform point on the disc, lifted to the hemisphere.
            let (r, phi) = (u1.sqrt(), std::f32::consts::TAU * u2);
            let (t, b) = n.any_orthonormal_pair();
            let dir =
                (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).sqrt()).normalize();
            BatchRay::of(&shadow_ray(p, n, dir))
        })
        .collect();
    Batch {
        rays,
        view: batch.view,
    }
}
