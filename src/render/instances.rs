//! The instance level of the two-level hierarchy: each instanced mesh
//! ([`crate::scene::instances`]) gets one wide hierarchy in its object frame, shared by all
//! its placements, and a binary hierarchy over the placements' world boxes finds which
//! placements a ray may hit.
//!
//! A placement is entered with the ray in its object frame (the same `t`: the direction is
//! transformed, not normalised), but its triangles are tested in the world frame, placed as
//! the flattened world places them ([`crate::scene::instances::placed`]), so a hit has the
//! distance and index the flattened world gives, bit for bit. Only the boxes are tested in
//! the object frame, so they are widened by a bound on the rounding between the two frames
//! ([`PAD_ULPS`]); `tests/instances.rs` holds every query to the flattened world's and to the
//! brute force.

use anyhow::Result;
use glam::{Affine3A, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;

use crate::render::bvh::{Bvh, EXIT_ROUND_UP, Stack};
use crate::render::bvh_build;
use crate::render::bvh_packet::{
    self, Hits, Mask, PACKET, PacketStack, RayPacket, Rays, and, any_set, bits_of, box_hits,
    lanes_of, nearest_entry,
};
use crate::render::ray::TraceRay;
use crate::scene::instances::box_corners;
use crate::scene::world::InstanceSet;
use crate::scene::world::World;

/// Slack of an instance's object-frame boxes, in units of f32's epsilon × the largest world
/// coordinate (over the scale): the rounding of the ray into the object frame and of the
/// placed vertices is a few such units.
const PAD_ULPS: f32 = 64.0;

/// One placement: its mesh's hierarchy, its transforms and its first primitive index.
#[derive(Clone, Copy)]
struct Placement {
    mesh: u32,
    world_from_object: Affine3A,
    object_from_world: Affine3A,
    base: u32,
}

impl Placement {
    /// (world from object, object from world, first primitive index): what a packet walk of
    /// its mesh needs.
    #[inline(always)]
    fn placed(&self) -> (&Affine3A, &Affine3A, u32) {
        (&self.world_from_object, &self.object_from_world, self.base)
    }
}

/// The placements of one visibility group and their meshes' hierarchies.
#[derive(Clone, Default)]
pub struct InstanceLevel {
    /// One per instanced mesh, in its object frame, boxes widened.
    meshes: Vec<Bvh>,
    placements: Vec<Placement>,
    /// Over the placements' world boxes; each leaf holds one placement's index.
    tlas: Option<Bvh2>,
}

impl InstanceLevel {
    /// The level of the sets `sets` (indices into `world.instanced`), all of one visibility
    /// group. `world_box` bounds every primitive of the world, placed ones too (the slack of
    /// the boxes grows with its reach; rays are assumed to start within it).
    pub fn build(world: &World, sets: &[usize], world_box: &Aabb) -> Result<InstanceLevel> {
        let mut level = InstanceLevel::default();
        if sets.is_empty() {
            return Ok(level);
        }
        let reach = world_box
            .min
            .abs()
            .max(world_box.max.abs())
            .max_element()
            .max(1.0);
        let mut boxes = Vec::new();
        for &s in sets {
            let set = &world.instanced[s];
            // A world length ℓ is at most ‖object_from_world‖ ℓ in the object frame (the
            // Frobenius norm bounds the largest stretch, whatever the shear).
            let stretch = set
                .world_from_object
                .iter()
                .map(|m| {
                    let inv = m.matrix3.inverse();
                    (inv.x_axis.length_squared()
                        + inv.y_axis.length_squared()
                        + inv.z_axis.length_squared())
                    .sqrt()
                })
                .fold(0.0f32, f32::max);
            let pad = PAD_ULPS * f32::EPSILON * reach * stretch;
            let mesh = mesh_hierarchy(set, pad)?;
            let Some(object_box) = mesh_box(set, pad) else {
                continue;
            };
            let index = level.meshes.len() as u32;
            level.meshes.push(mesh);
            let n = set.triangles.len() as u32;
            for (i, m) in set.world_from_object.iter().enumerate() {
                boxes.push(placed_box(m, &object_box));
                level.placements.push(Placement {
                    mesh: index,
                    world_from_object: *m,
                    object_from_world: m.inverse(),
                    base: set.first_prim + i as u32 * n,
                });
            }
        }
        let prims: Vec<u32> = (0..boxes.len() as u32).collect();
        let owners = prims.clone();
        level.tlas = (!boxes.is_empty()).then(|| bvh_build::build(&boxes, prims, &owners).0);
        Ok(level)
    }

    /// World box of every placement.
    pub fn bounds(&self) -> Aabb {
        self.tlas
            .as_ref()
            .map_or_else(Aabb::empty, |t| t.nodes[0].aabb)
    }

    /// Bytes held: the meshes' hierarchies, the placements and their hierarchy.
    pub fn bytes(&self) -> usize {
        self.meshes.iter().map(Bvh::bytes).sum::<usize>()
            + self.placements.len() * size_of::<Placement>()
            + self.tlas.as_ref().map_or(0, |t| {
                t.nodes.len() * size_of::<obvhs::bvh2::node::Bvh2Node>()
            })
    }

    /// Placements in the level.
    pub fn len(&self) -> usize {
        self.placements.len()
    }

    pub fn is_empty(&self) -> bool {
        self.placements.is_empty()
    }

    /// [`Bvh::closest`] over the placements.
    #[inline]
    pub fn closest(&self, ray: &mut TraceRay, best: &mut u32, stack: &mut Stack) {
        self.walk(ray, stack, |m, object_ray, ray, stack| {
            self.meshes[m.mesh as usize].closest_placed(
                object_ray,
                ray,
                best,
                stack,
                (&m.world_from_object, m.base),
            );
            false
        });
    }

    /// [`Bvh::any`] over the placements.
    #[inline]
    pub fn any(&self, ray: &TraceRay, stack: &mut Stack) -> bool {
        let mut blocked = false;
        self.walk(&mut ray.clone(), stack, |m, object_ray, ray, stack| {
            blocked = self.meshes[m.mesh as usize].any_placed(
                object_ray,
                ray,
                stack,
                (&m.world_from_object, m.base),
            );
            blocked
        });
        blocked
    }

    /// Visits the placements whose boxes `ray` enters in its [tmin, tmax], near first, with
    /// the ray in each one's object frame, until `visit` returns true; `visit` may shrink
    /// `ray.tmax`, which prunes what is left.
    #[inline(always)]
    fn walk(
        &self,
        ray: &mut TraceRay,
        stack: &mut Stack,
        mut visit: impl FnMut(&Placement, &TraceRay, &mut TraceRay, &mut Stack) -> bool,
    ) {
        let Some(tlas) = &self.tlas else {
            return;
        };
        let enters = |b: &Aabb, ray: &TraceRay| -> Option<f32> {
            let t0 = (b.min - ray.origin) * ray.inv_dir;
            let t1 = (b.max - ray.origin) * ray.inv_dir;
            let entry = t0.min(t1).max_element().max(ray.tmin);
            let exit = t0.max(t1).min_element().min(ray.tmax);
            (entry <= exit * EXIT_ROUND_UP).then_some(entry)
        };
        // Its own stack, taken from the thread's for the walk (the mesh walks use the rest).
        let mut todo = std::mem::take(&mut stack.placements);
        todo.clear();
        let mut current = enters(&tlas.nodes[0].aabb, ray).map(|_| 0u32);
        loop {
            let i = match current.take() {
                Some(i) => i,
                // The next stacked node that starts before the closest hit so far.
                None => match std::iter::from_fn(|| todo.pop())
                    .find(|&(_, entry)| entry <= ray.tmax * EXIT_ROUND_UP)
                {
                    Some((i, _)) => i,
                    None => break,
                },
            };
            let node = &tlas.nodes[i as usize];
            if node.is_leaf() {
                let m = &self.placements[node.first_index as usize];
                let object_ray = TraceRay::new(
                    m.object_from_world.transform_point3a(ray.origin),
                    m.object_from_world.transform_vector3a(ray.dir),
                    ray.tmin,
                    ray.tmax,
                );
                if visit(m, &object_ray, ray, stack) {
                    break;
                }
                continue;
            }
            let (a, b) = (node.first_index, node.first_index + 1);
            match [a, b].map(|c| enters(&tlas.nodes[c as usize].aabb, ray)) {
                [Some(ea), Some(eb)] => {
                    let (near, far) = if ea <= eb { (a, (b, eb)) } else { (b, (a, ea)) };
                    todo.push(far);
                    current = Some(near);
                }
                [Some(_), None] => current = Some(a),
                [None, Some(_)] => current = Some(b),
                [None, None] => {}
            }
        }
        stack.placements = todo;
    }
}

impl InstanceLevel {
    /// [`InstanceLevel::closest`] for every active ray of `packet`, `N` lanes at a time: the
    /// placements' boxes and each mesh's hierarchy walked by the lanes together, each leaf's
    /// triangles placed once for all of them. Each lane gets the hit the per-ray walk gives
    /// it, bit for bit (the same box and triangle tests, and [`closer`]'s choice, which does
    /// not depend on the order of the tests).
    ///
    /// [`closer`]: crate::render::packets::closer
    #[inline(always)]
    pub(crate) fn closest_packet<const N: usize>(
        &self,
        packet: &mut RayPacket,
        stack: &mut PacketStack,
    ) {
        for base in (0..PACKET).step_by(N) {
            let lanes = packet.lanes_from::<N>(base);
            if lanes == 0 {
                continue;
            }
            let rays = Rays::<N>::load(packet, base);
            let mut hits = Hits::<N>::load(packet, base);
            let mut tmax = hits.tmax;
            self.walk_packet(
                &rays,
                lanes_of(lanes),
                &mut tmax,
                stack,
                |m, on, tmax, _, stack| {
                    let mesh = &self.meshes[m.mesh as usize];
                    bvh_packet::closest_placed(mesh, m.placed(), &rays, &mut hits, on, stack);
                    *tmax = hits.tmax;
                },
            );
            hits.store(packet, base);
        }
    }

    /// [`InstanceLevel::any`] for every active ray of `packet`, `N` lanes at a time, as
    /// [`InstanceLevel::closest_packet`]: bit i is set where lane i's ray is blocked.
    #[inline(always)]
    pub(crate) fn any_packet<const N: usize>(
        &self,
        packet: &RayPacket,
        stack: &mut PacketStack,
    ) -> u32 {
        let mut blocked = 0;
        for base in (0..PACKET).step_by(N) {
            let lanes = packet.lanes_from::<N>(base);
            if lanes == 0 {
                continue;
            }
            let rays = Rays::<N>::load(packet, base);
            let mut tmax = Hits::<N>::load(packet, base).tmax;
            let mut hit = [false; N];
            self.walk_packet(
                &rays,
                lanes_of(lanes),
                &mut tmax,
                stack,
                |m, on, tmax, open, stack| {
                    let mesh = &self.meshes[m.mesh as usize];
                    let now = bvh_packet::any_placed(mesh, m.placed(), &rays, tmax, on, stack);
                    for i in 0..N {
                        hit[i] |= now[i];
                        open[i] &= !now[i];
                    }
                },
            );
            blocked |= bits_of(hit) << base;
        }
        blocked
    }

    /// [`InstanceLevel::walk`] for the lanes `on` of `rays` together: visits the placements
    /// whose boxes any open lane enters within its [tmin, `tmax`], nearest lane's entry first,
    /// with the lanes that enter each, until no lane is open. `visit` may shrink `tmax`, which
    /// prunes what is left, and close lanes (`open`).
    #[inline(always)]
    fn walk_packet<const N: usize>(
        &self,
        rays: &Rays<N>,
        on: Mask<N>,
        tmax: &mut [f32; N],
        stack: &mut PacketStack,
        mut visit: impl FnMut(&Placement, Mask<N>, &mut [f32; N], &mut Mask<N>, &mut PacketStack),
    ) {
        let Some(tlas) = &self.tlas else {
            return;
        };
        let mut open = on;
        // Its own stack, taken from the thread's for the walk (the mesh walks use the rest).
        let mut todo = std::mem::take(&mut stack.placements);
        todo.clear();
        let (m, e) = enters(&tlas.nodes[0].aabb, rays, tmax, open);
        if any_set(&m) {
            todo.push((0, bits_of(m), widen(e)));
        }
        while let Some((i, lanes, entry)) = todo.pop() {
            let lanes: Mask<N> = lanes_of(lanes);
            // Lanes closed, or whose closest hit so far is nearer than the subtree, skip it.
            let on: Mask<N> =
                std::array::from_fn(|l| lanes[l] & open[l] & (entry[l] <= tmax[l] * EXIT_ROUND_UP));
            if !any_set(&on) {
                continue;
            }
            let node = &tlas.nodes[i as usize];
            if node.is_leaf() {
                visit(
                    &self.placements[node.first_index as usize],
                    on,
                    tmax,
                    &mut open,
                    stack,
                );
                if !any_set(&open) {
                    break;
                }
                continue;
            }
            let (a, b) = (node.first_index, node.first_index + 1);
            let (ma, ea) = enters(&tlas.nodes[a as usize].aabb, rays, tmax, on);
            let (mb, eb) = enters(&tlas.nodes[b as usize].aabb, rays, tmax, on);
            // Far first on the stack, so that the near child is popped next.
            let far_first = if nearest_entry(&ma, &ea) <= nearest_entry(&mb, &eb) {
                [(b, mb, eb), (a, ma, ea)]
            } else {
                [(a, ma, ea), (b, mb, eb)]
            };
            for (c, m, e) in far_first {
                if any_set(&m) {
                    todo.push((c, bits_of(m), widen(e)));
                }
            }
        }
        stack.placements = todo;
    }
}

/// Which lanes of `lanes` enter the box `b` within their [tmin, `tmax`], and where. (A
/// function, not a closure in the walk: the closure was compiled apart, without the
/// kernels' target features, and took 7.6 % of `bench`'s time on the town.)
#[inline(always)]
fn enters<const N: usize>(
    b: &Aabb,
    rays: &Rays<N>,
    tmax: &[f32; N],
    lanes: Mask<N>,
) -> (Mask<N>, [f32; N]) {
    let mut entry = [0.0; N];
    let hit = box_hits(b.min.into(), b.max.into(), rays, tmax, &mut entry);
    (and(hit, lanes), entry)
}

/// `e` in the first `N` of [`PACKET`] lanes, 0 in the others.
#[inline(always)]
fn widen<const N: usize>(e: [f32; N]) -> [f32; PACKET] {
    let mut wide = [0.0; PACKET];
    wide[..N].copy_from_slice(&e);
    wide
}

/// World box of every placement of every instanced mesh of `world` (unwidened).
pub fn placed_bounds(world: &World) -> Aabb {
    let mut bounds = Aabb::empty();
    for set in &world.instanced {
        if let Some(b) = mesh_box(set, 0.0) {
            for m in &set.world_from_object {
                bounds = bounds.union(&placed_box(m, &b));
            }
        }
    }
    bounds
}

/// The mesh's hierarchy in its object frame, every box widened by `pad`.
fn mesh_hierarchy(set: &InstanceSet, pad: f32) -> Result<Bvh> {
    let mesh = World::of_triangles(set.triangles.clone(), set.attrs.clone());
    let prims: Vec<u32> = (0..set.triangles.len() as u32).collect();
    let (mut boxes, mut indices) = crate::render::bvh::primitive_boxes(&mesh, &prims);
    let mut bvh = crate::render::bvh_binned::build(&mesh, &mut boxes, &mut indices)?;
    bvh.pad(pad);
    Ok(bvh)
}

/// The mesh's box in its object frame, widened by `pad`; `None` without triangles.
fn mesh_box(set: &InstanceSet, pad: f32) -> Option<Aabb> {
    let mut b = Aabb::empty();
    for t in &set.triangles {
        b = b.union(&t.aabb());
    }
    (!set.triangles.is_empty())
        .then(|| Aabb::new(b.min - Vec3A::splat(pad), b.max + Vec3A::splat(pad)))
}

/// The world box of an object-frame box under `m`, widened by a few ulps of its coordinates.
fn placed_box(m: &Affine3A, b: &Aabb) -> Aabb {
    let mut out = Aabb::empty();
    for p in box_corners(b.min.into(), b.max.into()) {
        let q = m.transform_point3a(p.into());
        out = out.union(&Aabb::new(q, q));
    }
    let pad = out.min.abs().max(out.max.abs()) * (8.0 * f32::EPSILON);
    Aabb::new(out.min - pad, out.max + pad)
}
