//! Ray queries accelerated by a compressed wide BVH (obvhs `CwBvh`), with brute-force twins
//! that the tests hold the accelerated queries to.
//!
//! CWBVH was chosen over BVH2 by measurement (`seethru bench --bvh bvh2`, README §Benchmark):
//! its 8-wide nodes traverse faster on this CPU's SIMD for the same build presets.

use std::time::{Duration, Instant};

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::bvh2::Bvh2;
use obvhs::ray::{Ray, RayHit};

use crate::world::World;

/// Which obvhs hierarchy to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BvhKind {
    /// Binary BVH (PLOC + reinsertion).
    Bvh2,
    /// 8-wide compressed BVH (the default; faster to traverse).
    Cwbvh,
}

enum Hierarchy {
    Bvh2(Bvh2),
    Cwbvh(CwBvh),
}

/// A primitive in BVH order: the leaf data a traversal touches, kept together for locality.
#[derive(Clone, Copy)]
struct Leaf {
    /// Index of the primitive in the [`World`].
    prim: u32,
    /// Views that show the primitive ([`crate::world::view_bit`]).
    views: u8,
    casts_shadow: bool,
}

/// A closest-hit answer: which primitive, at which distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub prim: usize,
    pub t: f32,
}

pub struct Accel {
    hierarchy: Hierarchy,
    leaves: Vec<Leaf>,
    /// Wall time of the hierarchy build.
    pub build_time: Duration,
}

struct PrimBox(Aabb);

impl obvhs::Boundable for PrimBox {
    fn aabb(&self) -> Aabb {
        self.0
    }
}

pub fn make_ray(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Ray {
    Ray::new(Vec3A::from(origin), Vec3A::from(dir), tmin, tmax)
}

impl Accel {
    pub fn build(world: &World, kind: BvhKind) -> Accel {
        let start = Instant::now();
        let boxes: Vec<PrimBox> = (0..world.primitive_count()).map(|p| PrimBox(world.aabb(p))).collect();
        let params = BvhBuildParams::medium_build();
        let mut core = Duration::default();
        let (hierarchy, order) = match kind {
            BvhKind::Cwbvh => {
                let bvh = build_cwbvh(&boxes, params, &mut core);
                let order = bvh.primitive_indices.clone();
                (Hierarchy::Cwbvh(bvh), order)
            }
            BvhKind::Bvh2 => {
                let bvh = build_bvh2(&boxes, params, &mut core);
                let order = bvh.primitive_indices.clone();
                (Hierarchy::Bvh2(bvh), order)
            }
        };
        let leaves = order
            .iter()
            .map(|&p| {
                let (views, casts_shadow) = world.visibility(p as usize);
                Leaf { prim: p, views, casts_shadow }
            })
            .collect();
        Accel { hierarchy, leaves, build_time: start.elapsed() }
    }

    /// Closest primitive visible in `view` that `ray` hits in [tmin, tmax].
    pub fn closest(&self, world: &World, ray: Ray, view: u8) -> Option<Hit> {
        let mut hit = RayHit::none();
        let test = |r: &Ray, id: usize| {
            let leaf = &self.leaves[id];
            if leaf.views & view == 0 { f32::INFINITY } else { world.intersect(leaf.prim as usize, r) }
        };
        let found = match &self.hierarchy {
            Hierarchy::Cwbvh(b) => b.ray_traverse(ray, &mut hit, test),
            Hierarchy::Bvh2(b) => b.ray_traverse(ray, &mut hit, test),
        };
        found.then(|| Hit { prim: self.leaves[hit.primitive_id as usize].prim as usize, t: hit.t })
    }

    /// Whether any shadow-casting primitive visible in `view` blocks `ray` in [tmin, tmax].
    pub fn occluded(&self, world: &World, ray: Ray, view: u8) -> bool {
        let test = |r: &Ray, id: usize| {
            let leaf = &self.leaves[id];
            if leaf.views & view == 0 || !leaf.casts_shadow {
                f32::INFINITY
            } else {
                world.intersect(leaf.prim as usize, r)
            }
        };
        let miss = match &self.hierarchy {
            Hierarchy::Cwbvh(b) => b.ray_traverse_miss(ray, test),
            Hierarchy::Bvh2(b) => b.ray_traverse_miss(ray, test),
        };
        !miss
    }
}

/// Brute-force twin of [`Accel::closest`]: every primitive, in order.
pub fn closest_brute_force(world: &World, ray: Ray, view: u8) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for prim in 0..world.primitive_count() {
        if world.visibility(prim).0 & view == 0 {
            continue;
        }
        let t = world.intersect(prim, &ray);
        if t < best.map_or(ray.tmax, |b| b.t) {
            best = Some(Hit { prim, t });
        }
    }
    best
}

/// Brute-force twin of [`Accel::occluded`].
pub fn occluded_brute_force(world: &World, ray: Ray, view: u8) -> bool {
    (0..world.primitive_count()).any(|prim| {
        let (views, casts) = world.visibility(prim);
        views & view != 0 && casts && world.intersect(prim, &ray).is_finite()
    })
}
