//! Ray queries of a world: closest hit and shadow (any hit) per view, accelerated by wide
//! BVHs ([`crate::render::bvh`]), with brute-force twins that the tests hold them to.
//!
//! Primitives are grouped by visibility — which views show them, whether they cast shadows —
//! and each group gets its own hierarchy (over triangle packets and ellipsoids), and an
//! instance level for its instanced meshes ([`crate::render::instances`]).
//! A query traverses only the groups its view shows, so no leaf test asks "is this visible
//! here?": in das the big shared group holds everything but the obstacle (driver views only,
//! no shadow) and the head (hidden from the driver), which are tiny groups of their own.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use anyhow::Result;
use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use rayon::prelude::*;

use std::cell::RefCell;

use crate::render::bvh::{Bvh, NO_PRIM, Stack, primitive_boxes};
use crate::render::bvh_binned;
use crate::render::bvh_packet::{PacketStack, RayPacket};
use crate::render::instances::{InstanceLevel, placed_bounds};
use crate::render::ray::TraceRay;
use crate::render::simd::{self, Isa};
use crate::scene::world::World;

pub use crate::render::ray::Hit;

/// The primitives of one visibility class and their hierarchy.
#[derive(Clone)]
struct Group {
    /// Views that show the group ([`crate::scene::world::view_bit`]).
    views: u8,
    casts_shadow: bool,
    /// World box of the group's primitives.
    bounds: Aabb,
    /// Boxes the hierarchy was built over.
    boxes: usize,
    bvh: Bvh,
    /// The group's instanced meshes and their placements.
    instances: InstanceLevel,
}

/// Where the images of two views of one camera can differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Difference {
    /// Nowhere: the views show the same primitives.
    None,
    /// Only where rays can meet this world box: the primitives one view shows and the other
    /// does not, none of which casts a shadow.
    Within(Aabb),
    /// Anywhere: a primitive only one view shows casts shadows.
    Everywhere,
}

impl Difference {
    /// Where either of two differences can differ (of two sets of primitives traced together).
    pub fn union(self, other: Difference) -> Difference {
        match (self, other) {
            (Difference::Everywhere, _) | (_, Difference::Everywhere) => Difference::Everywhere,
            (Difference::None, d) | (d, Difference::None) => d,
            (Difference::Within(a), Difference::Within(b)) => Difference::Within(a.union(&b)),
        }
    }
}

thread_local! {
    /// The traversal stack of the queries that bring none.
    static STACK: RefCell<Stack> = RefCell::new(Stack::new());
}

/// Which builder makes the hierarchies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildChoice {
    /// Binned SAH straight into wide nodes (`bvh_binned.rs`): the default.
    Binned,
    /// PLOC's binary tree (a top-down one where PLOC degenerates) collapsed into wide nodes:
    /// the builder before, kept as the binned one's twin in tests (on das its trees trace
    /// 2–10 % slower and take 20 % more memory, and it builds 2.5–3 times slower).
    Ploc,
}

impl BuildChoice {
    /// The hierarchy over `boxes` of primitives `prims` of `world` (reordered as it likes).
    fn build(self, world: &World, mut boxes: Vec<Aabb>, mut prims: Vec<u32>) -> Result<Bvh> {
        match self {
            BuildChoice::Binned => bvh_binned::build(world, &mut boxes, &mut prims),
            BuildChoice::Ploc => Bvh::build_ploc(world, &boxes, prims),
        }
    }
}

#[derive(Clone)]
pub struct Accel {
    /// Largest group first, so that the others are searched with a short `tmax`.
    groups: Vec<Group>,
    /// Wall time of the hierarchy build (or refit).
    pub build_time: Duration,
}

pub fn make_ray(origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> TraceRay {
    TraceRay::new(Vec3A::from(origin), Vec3A::from(dir), tmin, tmax)
}

impl Accel {
    pub fn build(world: &World) -> Result<Accel> {
        Accel::build_with(world, BuildChoice::Binned)
    }

    /// [`Accel::build`] with the builder `choice` for the world's own primitives (instanced
    /// meshes are binned).
    pub fn build_with(world: &World, choice: BuildChoice) -> Result<Accel> {
        let start = Instant::now();
        // Primitives of each visibility class, in world order; the instanced ones by set.
        // Classified in chunks side by side, each chunk's runs merged in order (the same
        // classes on any thread count): 11.5 million triangles took 70-90 ms one by one.
        let mut classes: BTreeMap<(u8, bool), (Vec<u32>, Vec<usize>)> = BTreeMap::new();
        let triangles = world.triangles.len();
        let chunks: Vec<Vec<ClassRun>> = (0..triangles.div_ceil(CLASS_CHUNK))
            .into_par_iter()
            .map(|c| {
                let end = ((c + 1) * CLASS_CHUNK).min(triangles);
                class_runs(world, c * CLASS_CHUNK..end)
            })
            .collect();
        let ellipsoids = class_runs(world, world.ellipsoid_base()..world.primitive_count());
        for (key, prims) in chunks.into_iter().flatten().chain(ellipsoids) {
            classes.entry(key).or_default().0.extend(prims);
        }
        for (s, set) in world.instanced.iter().enumerate() {
            if !set.is_empty() {
                let class = classes
                    .entry(world.visibility(set.first_prim as usize))
                    .or_default();
                class.1.push(s);
            }
        }
        let mut built = Vec::new();
        let mut world_box = placed_bounds(world);
        for ((views, casts_shadow), (prims, sets)) in classes {
            let (boxes, indices) = primitive_boxes(world, &prims);
            let mut bounds = Aabb::empty();
            for b in &boxes {
                bounds = bounds.union(b);
            }
            world_box = world_box.union(&bounds);
            built.push((
                views,
                casts_shadow,
                bounds,
                boxes.len(),
                choice.build(world, boxes, indices)?,
                sets,
            ));
        }
        let mut groups = Vec::new();
        for (views, casts_shadow, bounds, boxes, bvh, sets) in built {
            let instances = InstanceLevel::build(world, &sets, &world_box)?;
            groups.push(Group {
                views,
                casts_shadow,
                bounds: bounds.union(&instances.bounds()),
                boxes,
                bvh,
                instances,
            });
        }
        groups.sort_by_key(|g| std::cmp::Reverse(g.bvh.bytes() + g.instances.bytes()));
        Ok(Accel {
            groups,
            build_time: start.elapsed(),
        })
    }

    /// These hierarchies carried over to `world`, the world they were built on with its
    /// primitives moved (same primitives, indices and visibility): [`Bvh::refit`] per group.
    /// Every query answers as [`Accel::build`] of `world` would, bit for bit; the boxes are
    /// looser where primitives moved apart or were split at build ([`Accel::area`]).
    pub fn refit(&self, world: &World) -> Accel {
        let start = Instant::now();
        let mut refitted = self.clone();
        for group in &mut refitted.groups {
            group.bounds = group.bvh.refit(world).0;
        }
        refitted.build_time = start.elapsed();
        refitted
    }

    /// Summed half-areas of the hierarchies' child boxes, m² ([`Bvh::area`]).
    pub fn area(&self) -> f32 {
        self.groups.iter().map(|g| g.bvh.area()).sum()
    }

    /// Closest primitive visible in `view` that `ray` hits in [tmin, tmax).
    #[inline]
    pub fn closest(&self, ray: &TraceRay, view: u8) -> Option<Hit> {
        STACK.with_borrow_mut(|stack| self.closest_with(ray, view, stack))
    }

    /// [`Accel::closest`] with a traversal stack of the caller's.
    #[inline]
    pub fn closest_with(&self, ray: &TraceRay, view: u8, stack: &mut Stack) -> Option<Hit> {
        let mut ray = *ray;
        let mut best = NO_PRIM;
        for group in self.groups.iter().filter(|g| g.views & view != 0) {
            group.bvh.closest(&mut ray, &mut best, stack);
            if !group.instances.is_empty() {
                group.instances.closest(&mut ray, &mut best, stack);
            }
        }
        (best != NO_PRIM).then_some(Hit {
            prim: best as usize,
            t: ray.tmax,
        })
    }

    /// [`Accel::closest_with`] for every active ray of `packet` at once, on `isa`'s kernels:
    /// each lane's `prim` and `tmax` become its closest hit ([`RayPacket::hit`]), the one
    /// the per-ray query gives, bit for bit.
    #[inline]
    pub fn closest_packet(
        &self,
        packet: &mut RayPacket,
        view: u8,
        isa: Isa,
        stack: &mut PacketStack,
    ) {
        for group in self.groups.iter().filter(|g| g.views & view != 0) {
            simd::closest(isa, &group.bvh, packet, stack);
            if !group.instances.is_empty() {
                simd::closest_instances(isa, &group.instances, packet, stack);
            }
        }
    }

    /// [`Accel::occluded_with`] for every active ray of `packet`: bit i is set where lane
    /// i's ray is blocked.
    #[inline]
    pub fn occluded_packet(
        &self,
        packet: &RayPacket,
        view: u8,
        isa: Isa,
        stack: &mut PacketStack,
    ) -> u32 {
        let mut rest = *packet;
        let mut blocked = 0;
        for g in self
            .groups
            .iter()
            .filter(|g| g.views & view != 0 && g.casts_shadow)
        {
            blocked |= simd::any(isa, &g.bvh, &rest, stack);
            if !g.instances.is_empty() {
                rest.active = packet.active & !blocked;
                blocked |= simd::any_instances(isa, &g.instances, &rest, stack);
            }
            rest.active = packet.active & !blocked;
            if rest.active == 0 {
                break;
            }
        }
        blocked
    }

    /// Whether any shadow-casting primitive visible in `view` blocks `ray` in [tmin, tmax].
    #[inline]
    pub fn occluded(&self, ray: &TraceRay, view: u8) -> bool {
        STACK.with_borrow_mut(|stack| self.occluded_with(ray, view, stack))
    }

    /// [`Accel::occluded`] with a traversal stack of the caller's.
    #[inline]
    pub fn occluded_with(&self, ray: &TraceRay, view: u8, stack: &mut Stack) -> bool {
        self.groups
            .iter()
            .filter(|g| g.views & view != 0 && g.casts_shadow)
            .any(|g| {
                g.bvh.any(ray, stack) || (!g.instances.is_empty() && g.instances.any(ray, stack))
            })
    }

    /// Whether view `view` shows any primitive of the hierarchy (as a surface, or as the
    /// shadow it casts on the view's surfaces).
    pub fn shows(&self, view: u8) -> bool {
        self.groups.iter().any(|g| g.views & view != 0)
    }

    /// Where images of views `a` and `b` (from one camera) can differ.
    pub fn difference(&self, a: u8, b: u8) -> Difference {
        let mut bounds = Aabb::empty();
        for group in &self.groups {
            if (group.views & a != 0) != (group.views & b != 0) {
                if group.casts_shadow {
                    return Difference::Everywhere;
                }
                bounds = bounds.union(&group.bounds);
            }
        }
        if bounds.min.cmple(bounds.max).all() {
            Difference::Within(bounds)
        } else {
            Difference::None
        }
    }

    /// Which builder made each group's hierarchy, with the boxes it holds, largest first.
    pub fn builders(&self) -> Vec<(crate::render::bvh_build::Builder, usize)> {
        self.groups
            .iter()
            .filter_map(|g| Some((g.bvh.builder?, g.boxes)))
            .collect()
    }

    /// Bytes held by the hierarchies.
    pub fn bytes(&self) -> usize {
        self.groups
            .iter()
            .map(|g| g.bvh.bytes() + g.instances.bytes())
            .sum()
    }
}

/// Brute-force twin of [`Accel::closest`]: every primitive, in order.
pub fn closest_brute_force(world: &World, ray: &TraceRay, view: u8) -> Option<Hit> {
    let ray = ray.as_obvhs();
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
pub fn occluded_brute_force(world: &World, ray: &TraceRay, view: u8) -> bool {
    let ray = ray.as_obvhs();
    (0..world.primitive_count()).any(|prim| {
        let (views, casts) = world.visibility(prim);
        views & view != 0 && casts && world.intersect(prim, &ray).is_finite()
    })
}

/// A visibility class (views, casts a shadow) and primitives of it.
type ClassRun = ((u8, bool), Vec<u32>);

/// Primitives classified side by side per chunk of this many.
const CLASS_CHUNK: usize = 1 << 16;

/// The primitives `prims` of `world` as runs of one visibility class, in order.
fn class_runs(world: &World, prims: std::ops::Range<usize>) -> Vec<ClassRun> {
    let mut runs: Vec<ClassRun> = Vec::new();
    for prim in prims {
        let key = world.visibility(prim);
        match runs.last_mut() {
            Some((k, run)) if *k == key => run.push(prim as u32),
            _ => runs.push((key, vec![prim as u32])),
        }
    }
    runs
}
