//! Ray queries accelerated by a compressed wide BVH (obvhs `CwBvh`), with brute-force twins
//! that the tests hold the accelerated queries to.
//!
//! CWBVH was chosen over BVH2 by measurement (`seethru bench --bvh bvh2`, README §Benchmark):
//! its 8-wide nodes traverse faster on this CPU's SIMD for the same build presets.

use std::time::{Duration, Instant};

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::leaf_collapser::collapse;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::ploc::PlocBuilder;
use obvhs::ray::{Ray, RayHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::splits::split_aabbs_preset;
use obvhs::triangle::Triangle;

use crate::scene::world::World;

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
    /// Copy of the primitive's triangle (unused for ellipsoids): traversal reads leaves in
    /// BVH order, and the copy saves a cache miss into the world's own array.
    tri: RtTriangle,
    /// Index of the primitive in the [`World`].
    prim: u32,
    is_triangle: bool,
    /// Views that show the primitive ([`crate::scene::world::view_bit`]).
    views: u8,
    casts_shadow: bool,
}

impl Leaf {
    #[inline(always)]
    fn intersect(&self, world: &World, ray: &Ray) -> f32 {
        if self.is_triangle {
            self.tri.intersect(ray)
        } else {
            world.intersect(self.prim as usize, ray)
        }
    }
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

/// Boxes to build the hierarchy over, and the primitive each belongs to. Large triangles (the
/// ground, the street, long kerbs) get several tight boxes instead of one that overlaps
/// everything (obvhs' spatial pre-splits); a primitive may then appear in several leaves.
fn split_primitive_boxes(world: &World) -> (Vec<Aabb>, Vec<u32>) {
    let tris: Vec<Triangle> = world
        .triangles
        .iter()
        .map(|t| Triangle {
            v0: t.v0,
            v1: t.v0 - t.e1,
            v2: t.v0 + t.e2,
        })
        .collect();
    let mut aabbs: Vec<Aabb> = tris.iter().map(Triangle::aabb).collect();
    let mut indices: Vec<u32> = (0..tris.len() as u32).collect();
    if !tris.is_empty() {
        let areas: Vec<f32> = aabbs.iter().map(Aabb::half_area).collect();
        let average = areas.iter().sum::<f32>() / areas.len() as f32;
        let largest = areas.iter().copied().fold(0.0, f32::max);
        split_aabbs_preset(&mut aabbs, &mut indices, &tris, average, largest);
    }
    // Ellipsoids are never split: their boxes are already tight enough.
    for prim in tris.len()..world.primitive_count() {
        aabbs.push(world.aabb(prim));
        indices.push(prim as u32);
    }
    (aabbs, indices)
}

pub fn make_ray(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Ray {
    Ray::new(Vec3A::from(origin), Vec3A::from(dir), tmin, tmax)
}

impl Accel {
    pub fn build(world: &World, kind: BvhKind) -> Accel {
        let start = Instant::now();
        let params = BvhBuildParams::medium_build();
        let (aabbs, indices) = split_primitive_boxes(world);
        let mut bvh2 = PlocBuilder::with_capacity(aabbs.len()).build(
            params.ploc_search_distance,
            &aabbs,
            indices,
            params.sort_precision,
            params.search_depth_threshold,
        );
        bvh2.uses_spatial_splits = true;
        let mut optimizer = ReinsertionOptimizer::default();
        optimizer.run(&mut bvh2, params.reinsertion_batch_ratio, None);
        let hierarchy = match kind {
            BvhKind::Cwbvh => Hierarchy::Cwbvh(bvh2_to_cwbvh(
                &bvh2,
                params.max_prims_per_leaf.clamp(1, 3),
                true,
                false,
            )),
            BvhKind::Bvh2 => {
                collapse(
                    &mut bvh2,
                    params.max_prims_per_leaf,
                    params.collapse_traversal_cost,
                );
                let ratio = params.reinsertion_batch_ratio
                    * params.post_collapse_reinsertion_batch_ratio_multiplier;
                optimizer.run(&mut bvh2, ratio, None);
                Hierarchy::Bvh2(bvh2)
            }
        };
        let order = match &hierarchy {
            Hierarchy::Cwbvh(b) => &b.primitive_indices,
            Hierarchy::Bvh2(b) => &b.primitive_indices,
        };
        let leaves = order
            .iter()
            .map(|&p| {
                let (views, casts_shadow) = world.visibility(p as usize);
                let is_triangle = (p as usize) < world.triangles.len();
                let tri = if is_triangle {
                    world.triangles[p as usize]
                } else {
                    RtTriangle::default()
                };
                Leaf {
                    tri,
                    prim: p,
                    is_triangle,
                    views,
                    casts_shadow,
                }
            })
            .collect();
        Accel {
            hierarchy,
            leaves,
            build_time: start.elapsed(),
        }
    }

    /// Closest primitive visible in `view` that `ray` hits in [tmin, tmax].
    pub fn closest(&self, world: &World, ray: Ray, view: u8) -> Option<Hit> {
        let mut hit = RayHit::none();
        let test = |r: &Ray, id: usize| {
            let leaf = &self.leaves[id];
            if leaf.views & view == 0 {
                f32::INFINITY
            } else {
                leaf.intersect(world, r)
            }
        };
        let found = match &self.hierarchy {
            Hierarchy::Cwbvh(b) => b.ray_traverse(ray, &mut hit, test),
            Hierarchy::Bvh2(b) => b.ray_traverse(ray, &mut hit, test),
        };
        found.then(|| Hit {
            prim: self.leaves[hit.primitive_id as usize].prim as usize,
            t: hit.t,
        })
    }

    /// Whether any shadow-casting primitive visible in `view` blocks `ray` in [tmin, tmax].
    pub fn occluded(&self, world: &World, ray: Ray, view: u8) -> bool {
        let test = |r: &Ray, id: usize| {
            let leaf = &self.leaves[id];
            if leaf.views & view == 0 || !leaf.casts_shadow {
                f32::INFINITY
            } else {
                leaf.intersect(world, r)
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
