//! A wide bounding volume hierarchy laid out for SIMD traversal of single rays.
//!
//! Nodes of [`WIDTH`] = 8 children whose boxes are stored structure-of-arrays, so that one
//! ray is tested against four of them with a few SSE instructions (glam's `Vec4`, any
//! x86-64), and a packet of rays against each child in vector lanes (`render/bvh_packet.rs`);
//! leaves of primitive packets — four triangles tested together, or single ellipsoids
//! ([`crate::render::packets`]). The nodes are binned straight from the primitives' boxes
//! (`bvh_binned.rs`); the builder before, obvhs' binary BVH (PLOC, reinsertion;
//! [`crate::render::bvh_build`]) collapsed here, stays as its twin in tests.
//!
//! Traversal keeps the ray's `tmax` at the closest hit so far, visits children near to far,
//! and skips stacked subtrees that start beyond it. Box tests are conservative (the exit
//! distance is rounded up by a few ulps) so that rounding never drops a box whose primitive
//! the exact intersection test would hit: the brute-force twins in `tests/accel.rs` hold every
//! query to the same distance, bit for bit.

use anyhow::{Result, bail};
use glam::{Affine3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::bvh2::Bvh2;
use obvhs::splits::split_aabbs_preset;
use obvhs::triangle::Triangle;
use rayon::prelude::*;

use crate::render::bvh_build;
use crate::render::packets::{EllipsoidLeaf, TRI_LANES, Triangles4};
use crate::render::ray::TraceRay;
use crate::scene::world::World;

/// Children per node, a multiple of four (a `Vec4` per four). 8 against 4, measured in CPU
/// time per ray on one thread (docs/reference/benchmark.md): camera-ray packets 3 % cheaper on
/// das and 9 % on das grown 10×, single incoherent rays 4–8 %, sun-shadow packets 2–5 %
/// dearer; the nodes take 256 bytes (four cache lines) instead of 128.
pub(crate) const WIDTH: usize = 8;
const _: () = assert!(WIDTH.is_multiple_of(4));

/// Child reference: a leaf (else an inner node's index) ...
pub(crate) const LEAF: u32 = 1 << 31;
/// ... of ellipsoids (else of triangle packets) ...
pub(crate) const ELLIPSOIDS: u32 = 1 << 30;
/// ... with (packets − 1) in these bits, and the first packet's index below them.
pub(crate) const COUNT_SHIFT: u32 = 27;
pub(crate) const COUNT_MASK: u32 = 0b111;
pub(crate) const FIRST_MASK: u32 = (1 << COUNT_SHIFT) - 1;
/// Most packets in one leaf.
pub(crate) const MAX_LEAF_PACKETS: usize = COUNT_MASK as usize + 1;
/// The error of a hierarchy whose leaf references cannot hold its packets.
const TOO_MANY_PACKETS: &str = "the scene has more than 134217727 triangle packets or ellipsoids in one hierarchy, the most its leaf references hold: use fewer or coarser meshes";
const _: () = assert!(FIRST_MASK == 134_217_727);
/// An unused child slot (its box is empty, so it is never entered); unused slots follow the
/// used ones.
pub(crate) const EMPTY: u32 = u32::MAX;
/// Traversal stack entries; a hierarchy that could need more is refused at build time.
pub(crate) const STACK: usize = 1024;
const _: () = assert!(bvh_build::MAX_DEPTH * WIDTH <= STACK);
/// Box exits are scaled by this before comparison: 8 ulps of headroom for the rounding of
/// the slab distances against the exact primitive tests.
pub(crate) const EXIT_ROUND_UP: f32 = 1.0 + 8.0 * f32::EPSILON;
/// Boxes from which the root's subtrees are collapsed into wide nodes side by side.
const PARALLEL_BOXES: usize = 1 << 16;
pub use crate::render::packets::NO_PRIM;

/// Which rows of a node's bounds hold each axis's near and far planes for rays of one
/// octant: [min, max] on an axis they run along toward +, [max, min] toward −.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Planes {
    pub(crate) near: [usize; 3],
    pub(crate) far: [usize; 3],
}

impl Planes {
    /// The planes of octant `octant` (bit a set where the rays run toward − on axis a).
    #[inline(always)]
    pub(crate) fn of(octant: u32) -> Planes {
        let toward_minus = |axis: usize| (octant >> axis) & 1;
        Planes {
            near: [0, 1, 2].map(|a| 2 * a + toward_minus(a) as usize),
            far: [0, 1, 2].map(|a| 2 * a + 1 - toward_minus(a) as usize),
        }
    }
}

/// What the box test needs of a ray: computed once per traversal.
struct RayLanes {
    origin: [f32; 3],
    inv_dir: [f32; 3],
    /// The planes the ray meets first and last on each axis: those of its octant (bit a set
    /// where its reciprocal direction's axis-a component has its sign bit set).
    planes: Planes,
}

impl RayLanes {
    #[inline(always)]
    fn new(ray: &TraceRay) -> RayLanes {
        let inv_dir = [ray.inv_dir.x, ray.inv_dir.y, ray.inv_dir.z];
        let octant = (0..3).fold(0, |k, a| k | ((inv_dir[a].to_bits() >> 31) << a));
        RayLanes {
            origin: [ray.origin.x, ray.origin.y, ray.origin.z],
            inv_dir,
            planes: Planes::of(octant),
        }
    }
}

/// SSE's `minps`/`maxps`: the second operand where either is NaN.
#[inline(always)]
pub(crate) fn min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

#[inline(always)]
pub(crate) fn max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

/// [`WIDTH`] child boxes, structure of arrays, and the child references.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Node {
    /// Per child: [min x, max x, min y, max y, min z, max z], world frame, metres.
    pub(crate) bounds: [[f32; WIDTH]; 6],
    pub(crate) children: [u32; WIDTH],
}

impl Node {
    /// Unused slots have NaN boxes, which no ray enters.
    pub(crate) const EMPTY: Node = Node {
        bounds: [[f32::NAN; WIDTH]; 6],
        children: [EMPTY; WIDTH],
    };

    /// Sets child `slot`'s box to `aabb` padded by a few ulps of its coordinates: clipped
    /// (spatially split) boxes can be a rounding short of their triangle, which matters to a
    /// ray that runs exactly along a box face.
    pub(crate) fn set_child_box(&mut self, slot: usize, aabb: &Aabb) {
        let pad = aabb.min.abs().max(aabb.max.abs()) * (4.0 * f32::EPSILON);
        for axis in 0..3 {
            self.bounds[2 * axis][slot] = aabb.min[axis] - pad[axis];
            self.bounds[2 * axis + 1][slot] = aabb.max[axis] + pad[axis];
        }
    }

    /// Which children the ray enters in [tmin, tmax] (bit i for child i), and where: four
    /// children at a time in a `Vec4` (SSE on any x86-64).
    ///
    /// Each axis's near plane is the ray's `near` row, its far plane the `far` row: the
    /// reciprocal direction is finite and not 0 ([`crate::render::ray::reciprocal`]), so
    /// (lo − o)·inv ≤ (hi − o)·inv where inv > 0 and ≥ where inv < 0 (subtraction and
    /// multiplication round monotonically), and the near plane's distance is the min of the
    /// two, the far one's the max, bit for bit but for a zero's sign, which compares equal:
    /// the packets' test (`bvh_packet.rs`'s `child_hits`) and the slab test's min and max
    /// answer alike.
    #[inline(always)]
    fn intersect(&self, lanes: &RayLanes, tmin: f32, tmax: f32) -> (u32, [f32; WIDTH]) {
        let b = &self.bounds;
        let [ox, oy, oz] = lanes.origin.map(Vec4::splat);
        let [ix, iy, iz] = lanes.inv_dir.map(Vec4::splat);
        let (near, far) = (&lanes.planes.near, &lanes.planes.far);
        let mut entries = [0.0; WIDTH];
        let mut mask = 0;
        for k in (0..WIDTH).step_by(4) {
            let at = |row: usize| Vec4::from_slice(&b[row][k..k + 4]);
            let (x0, x1) = ((at(near[0]) - ox) * ix, (at(far[0]) - ox) * ix);
            let (y0, y1) = ((at(near[1]) - oy) * iy, (at(far[1]) - oy) * iy);
            let (z0, z1) = ((at(near[2]) - oz) * iz, (at(far[2]) - oz) * iz);
            // An empty slot's NaN box makes both distances NaN, and SSE's max and min
            // return their second operand where either is NaN (as [`min`], [`max`]): its
            // entry is NaN, and NaN ≤ anything is false.
            let entry = Vec4::splat(tmin).max(z0).max(y0).max(x0);
            let exit = Vec4::splat(tmax).min(z1).min(y1).min(x1);
            mask |= entry.cmple(exit * EXIT_ROUND_UP).bitmask() << k;
            entry.write_to_slice(&mut entries[k..k + 4]);
        }
        (mask, entries)
    }
}

/// A traversal stack of (entry distance, child reference) keys, allocated once per thread
/// and reused: zeroing a fresh array for every ray cost more than the traversal.
pub struct Stack {
    entries: Vec<u64>,
    len: usize,
    /// The instance level's own stack of (node, entry distance), beside this one (its walk
    /// runs mesh walks on `entries` at its leaves).
    pub(crate) placements: Vec<(u32, f32)>,
}

impl Stack {
    pub fn new() -> Stack {
        Stack {
            entries: vec![0; STACK],
            len: 0,
            placements: Vec::with_capacity(64),
        }
    }

    /// Runs `f` with this thread's stack, allocated once per thread (a fresh one where the
    /// thread's is in use further up its call stack), as the packet stack's
    /// `with_thread_stack`.
    pub fn with_thread_stack<R>(f: impl FnOnce(&mut Stack) -> R) -> R {
        thread_local! {
            static STACK: std::cell::RefCell<Stack> = std::cell::RefCell::new(Stack::new());
        }
        STACK.with(|cell| match cell.try_borrow_mut() {
            Ok(mut stack) => f(&mut stack),
            Err(_) => f(&mut Stack::new()),
        })
    }

    #[inline(always)]
    fn push(&mut self, key: u64) {
        self.entries[self.len] = key;
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<u64> {
        self.len = self.len.checked_sub(1)?;
        Some(self.entries[self.len])
    }
}

impl Default for Stack {
    fn default() -> Self {
        Self::new()
    }
}

/// Sort key of a child: its entry distance (non-negative floats order as their bits) above
/// its reference.
#[inline(always)]
fn key(entry: f32, child: u32) -> u64 {
    (u64::from(entry.to_bits()) << 32) | u64::from(child)
}

/// Sorts `keys[..n]` in increasing order (insertion sort: a few keys).
#[inline(always)]
fn sort_keys(keys: &mut [u64; WIDTH], n: usize) {
    for a in 1..n {
        let k = keys[a];
        let mut b = a;
        while b > 0 && keys[b - 1] > k {
            keys[b] = keys[b - 1];
            b -= 1;
        }
        keys[b] = k;
    }
}

#[inline(always)]
fn key_entry(key: u64) -> f32 {
    f32::from_bits((key >> 32) as u32)
}

/// Boxes to build a hierarchy over `prims`, and the primitive each belongs to. Large
/// triangles (the ground, the street, long kerbs) get several tight boxes instead of one that
/// overlaps everything (obvhs' spatial pre-splits); a primitive may then be in several leaves.
/// Ellipsoids keep one box: it is tight enough.
pub fn primitive_boxes(world: &World, prims: &[u32]) -> (Vec<Aabb>, Vec<u32>) {
    // One pass in order (rayon's partition gathers lists of vectors: 11 ms for a million).
    let (mut indices, mut ellipsoids) = (Vec::with_capacity(prims.len()), Vec::new());
    for &p in prims {
        if (p as usize) < world.triangles.len() {
            indices.push(p);
        } else {
            ellipsoids.push(p);
        }
    }
    let triangle = |p: u32| {
        let t = &world.triangles[p as usize];
        Triangle {
            v0: t.v0,
            v1: t.v0 - t.e1,
            v2: t.v0 + t.e2,
        }
    };
    let mut aabbs: Vec<Aabb> = indices.par_iter().map(|&p| triangle(p).aabb()).collect();
    if !aabbs.is_empty() {
        // Summed per chunk of fixed size, then the chunks in order: the same rounding on any
        // thread count.
        let (sum, largest) = aabbs
            .par_chunks(SPLIT_CHUNK)
            .map(|chunk| {
                chunk
                    .iter()
                    .map(Aabb::half_area)
                    .fold((0.0f32, 0.0f32), |(sum, largest), area| {
                        (sum + area, largest.max(area))
                    })
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold((0.0f32, 0.0f32), |(sum, largest), (s, l)| {
                (sum + s, largest.max(l))
            });
        let average = sum / aabbs.len() as f32;
        // The preset splits only boxes of over three times the average area, each on its own
        // (whether a box is split, and into what, depends on it and its triangle alone): run
        // on the boxes over the average alone, in chunks side by side, it splits the same
        // boxes the same way, without a copy of every triangle. Each chunk's new boxes are
        // appended after the previous chunk's, the same order on any thread count.
        let large: Vec<usize> = (0..aabbs.len())
            .into_par_iter()
            .filter(|&i| aabbs[i].half_area() > average)
            .collect();
        let split: Vec<(Vec<Aabb>, Vec<u32>)> = large
            .par_chunks(SPLIT_CHUNK)
            .map(|chunk| {
                let mut boxes: Vec<Aabb> = chunk.iter().map(|&i| aabbs[i]).collect();
                let mut local: Vec<u32> = (0..chunk.len() as u32).collect();
                let triangles: Vec<Triangle> =
                    chunk.iter().map(|&i| triangle(indices[i])).collect();
                split_aabbs_preset(&mut boxes, &mut local, &triangles, average, largest);
                (boxes, local)
            })
            .collect();
        // Room for the new boxes first: a vector grown past its capacity is copied whole.
        let added: usize = large
            .chunks(SPLIT_CHUNK)
            .zip(&split)
            .map(|(chunk, (boxes, _))| boxes.len() - chunk.len())
            .sum();
        aabbs.reserve_exact(added + ellipsoids.len());
        indices.reserve_exact(added + ellipsoids.len());
        for (chunk, (boxes, local)) in large.chunks(SPLIT_CHUNK).zip(split) {
            for (k, aabb) in boxes.iter().enumerate() {
                if k < chunk.len() {
                    aabbs[chunk[k]] = *aabb;
                } else {
                    aabbs.push(*aabb);
                    indices.push(indices[chunk[local[k] as usize]]);
                }
            }
        }
    }
    aabbs.extend(ellipsoids.iter().map(|&p| world.aabb(p as usize)));
    indices.extend(ellipsoids);
    (aabbs, indices)
}

/// Boxes per chunk of [`primitive_boxes`]' sums and splits, side by side.
const SPLIT_CHUNK: usize = 1 << 14;

/// First packet and packet count of a triangle leaf reference.
#[inline(always)]
pub(crate) fn packets_of(leaf: u32) -> (usize, usize) {
    debug_assert!(leaf & ELLIPSOIDS == 0);
    (
        (leaf & FIRST_MASK) as usize,
        ((leaf >> COUNT_SHIFT) & COUNT_MASK) as usize + 1,
    )
}

/// A wide BVH over the triangles and ellipsoids of a world.
#[derive(Clone)]
pub struct Bvh {
    /// Which builder made the binary hierarchy (None: no primitives).
    pub builder: Option<bvh_build::Builder>,
    pub(crate) nodes: Vec<Node>,
    pub(crate) triangles: Vec<Triangles4>,
    pub(crate) ellipsoids: Vec<EllipsoidLeaf>,
}

impl Bvh {
    pub(crate) fn empty() -> Bvh {
        Bvh {
            builder: None,
            nodes: Vec::new(),
            triangles: Vec::new(),
            ellipsoids: Vec::new(),
        }
    }

    /// Builds the hierarchy over primitives of `world` with boxes `boxes`, referred to by
    /// `prims` (a primitive may have several boxes: spatial splits), by the builder before
    /// the binned one: PLOC's binary tree (a top-down one where PLOC degenerates) collapsed.
    pub fn build_ploc(world: &World, boxes: &[Aabb], prims: Vec<u32>) -> Result<Self> {
        if boxes.is_empty() {
            return Ok(Bvh::empty());
        }
        let mut draft = Draft::with_room(0);
        let owners: Vec<u32> = prims.iter().map(|&p| world.object_of(p as usize)).collect();
        let (bvh2, made) = bvh_build::build(boxes, prims, &owners);
        let summaries = summarise(&bvh2, world.triangles.len() as u32);
        let mut builder = Builder {
            bvh2: &bvh2,
            summaries: &summaries,
            world,
            out: &mut draft,
        };
        // The root is always an inner node, so that traversal starts uniformly.
        let root = builder.out.reserve();
        builder.fill(root, &[0], 1)?;
        let mut bvh = Draft::concatenate(&[&draft], &[], world)?;
        bvh.builder = Some(made);
        Ok(bvh)
    }

    /// Carries the hierarchy over to `world`, which holds the same primitives at the same
    /// indices, moved: the leaves take the moved primitives and every child box is recomputed
    /// bottom-up from their boxes (same topology). A primitive that the build split into
    /// several tight boxes now has its whole box in each of its leaves: looser, still
    /// conservative, so every query answers as a fresh build over `world` would, bit for bit
    /// (the tests hold it to both). Returns the world box of all primitives (unpadded) and the
    /// summed half-areas of the child boxes ([`Bvh::area`]).
    pub fn refit(&mut self, world: &World) -> (Aabb, f32) {
        for packet in &mut self.triangles {
            *packet = Triangles4::new(&world.triangles, &packet.prim);
        }
        let offset = world.ellipsoid_base();
        for leaf in &mut self.ellipsoids {
            leaf.ellipsoid = world.ellipsoids[leaf.prim as usize - offset];
        }
        // An inner child is reserved after its parent (`Builder::fill`): in reverse index
        // order every child's box is known before its parent's.
        let mut node_boxes = vec![Aabb::empty(); self.nodes.len()];
        for i in (0..self.nodes.len()).rev() {
            let mut node_box = Aabb::empty();
            for slot in 0..WIDTH {
                let child = self.nodes[i].children[slot];
                if child == EMPTY {
                    continue;
                }
                let aabb = if child & LEAF != 0 {
                    self.leaf_box(child, world)
                } else {
                    debug_assert!(child as usize > i);
                    node_boxes[child as usize]
                };
                self.nodes[i].set_child_box(slot, &aabb);
                node_box = node_box.union(&aabb);
            }
            node_boxes[i] = node_box;
        }
        let root = node_boxes.first().copied().unwrap_or_else(Aabb::empty);
        (root, self.area())
    }

    /// World box of the primitives of leaf reference `leaf`.
    fn leaf_box(&self, leaf: u32, world: &World) -> Aabb {
        let first = (leaf & FIRST_MASK) as usize;
        let count = ((leaf >> COUNT_SHIFT) & COUNT_MASK) as usize + 1;
        let mut aabb = Aabb::empty();
        if leaf & ELLIPSOIDS == 0 {
            for packet in &self.triangles[first..first + count] {
                for &p in &packet.prim {
                    aabb = aabb.union(&world.aabb(p as usize));
                }
            }
        } else {
            for e in &self.ellipsoids[first..first + count] {
                aabb = aabb.union(&world.aabb(e.prim as usize));
            }
        }
        aabb
    }

    /// Summed half-areas of every used child box, m²: the surface-area cost a traversal pays
    /// per unit of ray density, which loosened (refitted) boxes raise.
    pub fn area(&self) -> f32 {
        let mut area = 0.0;
        for node in &self.nodes {
            for slot in 0..WIDTH {
                if node.children[slot] != EMPTY {
                    let b = &node.bounds;
                    let d = [0, 1, 2].map(|a| b[2 * a + 1][slot] - b[2 * a][slot]);
                    area += d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
                }
            }
        }
        area
    }

    /// Tests the primitives of leaf `leaf` for the closest hit; shrinks `ray.tmax` and sets
    /// `best` (see [`closer`]).
    #[inline(always)]
    fn leaf_closest(&self, leaf: u32, ray: &mut TraceRay, best: &mut u32) {
        let first = (leaf & FIRST_MASK) as usize;
        let count = ((leaf >> COUNT_SHIFT) & COUNT_MASK) as usize + 1;
        if leaf & ELLIPSOIDS == 0 {
            for packet in &self.triangles[first..first + count] {
                packet.closest(ray, best);
            }
        } else {
            for ellipsoid in &self.ellipsoids[first..first + count] {
                ellipsoid.closest(ray, best);
            }
        }
    }

    #[inline(always)]
    fn leaf_any(&self, leaf: u32, ray: &TraceRay) -> bool {
        let first = (leaf & FIRST_MASK) as usize;
        let count = ((leaf >> COUNT_SHIFT) & COUNT_MASK) as usize + 1;
        if leaf & ELLIPSOIDS == 0 {
            self.triangles[first..first + count]
                .iter()
                .any(|p| p.any(ray))
        } else {
            self.ellipsoids[first..first + count]
                .iter()
                .any(|p| p.any(ray))
        }
    }

    /// Closest primitive hit in [tmin, tmax): shrinks `ray.tmax` to its distance and sets
    /// `best` to it, where it is closer than `best` at `ray.tmax` ([`closer`]; `best` is
    /// [`NO_PRIM`] where nothing was found yet).
    #[inline]
    pub fn closest(&self, ray: &mut TraceRay, best: &mut u32, stack: &mut Stack) {
        let lanes = RayLanes::new(ray);
        self.walk_closest(&lanes, ray, stack, |bvh, leaf, ray| {
            bvh.leaf_closest(leaf, ray, best)
        });
    }

    /// [`Bvh::closest`] of a hierarchy built in an object frame, placed by `m`: its boxes
    /// are tested with `object_ray` (`ray` in the object frame: the same `t`), its triangles
    /// are placed by `m` ([`crate::scene::instances::placed`]) and tested with `ray`, as the
    /// flattened world's would be, under primitive indices `base` + their own.
    #[inline]
    pub fn closest_placed(
        &self,
        object_ray: &TraceRay,
        ray: &mut TraceRay,
        best: &mut u32,
        stack: &mut Stack,
        (m, base): (&Affine3A, u32),
    ) {
        let lanes = RayLanes::new(object_ray);
        self.walk_closest(&lanes, ray, stack, |bvh, leaf, ray| {
            let (first, count) = packets_of(leaf);
            for packet in &bvh.triangles[first..first + count] {
                packet.placed(m, base).closest(ray, best);
            }
        });
    }

    /// The near-to-far walk of [`Bvh::closest`]: boxes tested with `lanes` in `ray`'s
    /// interval, each leaf handed to `leaf`, which shrinks `ray.tmax`.
    #[inline(always)]
    fn walk_closest(
        &self,
        lanes: &RayLanes,
        ray: &mut TraceRay,
        stack: &mut Stack,
        mut leaf: impl FnMut(&Bvh, u32, &mut TraceRay),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        stack.len = 0;
        let mut current = 0u32;
        'visit: loop {
            // Down the tree, near child first, until a leaf or nothing is hit.
            while current & LEAF == 0 {
                let node = &self.nodes[current as usize];
                let (mut mask, entry) = node.intersect(lanes, ray.tmin, ray.tmax);
                if mask == 0 {
                    break;
                }
                let a = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    current = node.children[a];
                    continue;
                }
                let b = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let (ka, kb) = (
                    key(entry[a], node.children[a]),
                    key(entry[b], node.children[b]),
                );
                if mask == 0 {
                    stack.push(ka.max(kb));
                    current = ka.min(kb) as u32;
                    continue;
                }
                // Three or more: sort near to far, push all but the nearest.
                let mut keys = [u64::MAX; WIDTH];
                keys[0] = ka;
                keys[1] = kb;
                let mut n = 2;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    keys[n] = key(entry[i], node.children[i]);
                    n += 1;
                }
                sort_keys(&mut keys, n);
                for &k in keys[1..n].iter().rev() {
                    stack.push(k);
                }
                current = keys[0] as u32;
            }
            if current & LEAF != 0 {
                leaf(self, current, ray);
            }
            // The next stacked subtree that starts before the closest hit so far.
            while let Some(k) = stack.pop() {
                if key_entry(k) <= ray.tmax * EXIT_ROUND_UP {
                    current = k as u32;
                    continue 'visit;
                }
            }
            return;
        }
    }

    /// Whether any primitive is hit in [tmin, tmax].
    #[inline]
    pub fn any(&self, ray: &TraceRay, stack: &mut Stack) -> bool {
        let lanes = RayLanes::new(ray);
        self.walk_any(&lanes, ray, stack, |bvh, leaf| bvh.leaf_any(leaf, ray))
    }

    /// [`Bvh::any`] of a hierarchy placed by `m`, as [`Bvh::closest_placed`].
    #[inline]
    pub fn any_placed(
        &self,
        object_ray: &TraceRay,
        ray: &TraceRay,
        stack: &mut Stack,
        (m, base): (&Affine3A, u32),
    ) -> bool {
        let lanes = RayLanes::new(object_ray);
        self.walk_any(&lanes, ray, stack, |bvh, leaf| {
            let (first, count) = packets_of(leaf);
            bvh.triangles[first..first + count]
                .iter()
                .any(|p| p.placed(m, base).any(ray))
        })
    }

    /// The walk of [`Bvh::any`]: until `leaf` finds a hit.
    #[inline(always)]
    fn walk_any(
        &self,
        lanes: &RayLanes,
        ray: &TraceRay,
        stack: &mut Stack,
        leaf: impl Fn(&Bvh, u32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        stack.len = 0;
        let mut current = 0u32;
        loop {
            if current & LEAF == 0 {
                let node = &self.nodes[current as usize];
                let (mut mask, _) = node.intersect(lanes, ray.tmin, ray.tmax);
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    stack.push(u64::from(node.children[i]));
                }
            } else if leaf(self, current) {
                return true;
            }
            match stack.pop() {
                Some(k) => current = k as u32,
                None => return false,
            }
        }
    }

    /// Widens every child box by `pad` (metres of the frame the hierarchy was built in) on
    /// each side: the slack an instance's boxes need for the rounding between its object
    /// frame and the world's (the instance level, `render/instances.rs`).
    pub(crate) fn pad(&mut self, pad: f32) {
        for node in &mut self.nodes {
            for slot in 0..WIDTH {
                if node.children[slot] != EMPTY {
                    for axis in 0..3 {
                        node.bounds[2 * axis][slot] -= pad;
                        node.bounds[2 * axis + 1][slot] += pad;
                    }
                }
            }
        }
    }

    /// Bytes held by the hierarchy.
    pub fn bytes(&self) -> usize {
        self.nodes.len() * size_of::<Node>()
            + self.triangles.len() * size_of::<Triangles4>()
            + self.ellipsoids.len() * size_of::<EllipsoidLeaf>()
    }
}

/// A hierarchy being built: its nodes, its ellipsoid leaves, and its triangle leaves' packets
/// as their primitives: 16 bytes each while its parts are built, packed into [`Triangles4`]
/// of 160 bytes once, as the drafts are concatenated into a [`Bvh`] (instead of written in
/// each part, then copied).
pub(crate) struct Draft {
    pub(crate) nodes: Vec<Node>,
    /// Each packet's triangles; unused lanes repeat the first.
    packets: Vec<[u32; TRI_LANES]>,
    ellipsoids: Vec<EllipsoidLeaf>,
}

impl Draft {
    /// An empty draft with room for the hierarchy of about `boxes` boxes.
    pub(crate) fn with_room(boxes: usize) -> Draft {
        Draft {
            nodes: Vec::with_capacity(boxes / 8),
            packets: Vec::with_capacity(boxes / 3),
            ellipsoids: Vec::new(),
        }
    }

    /// A new inner node (empty), its index.
    pub(crate) fn reserve(&mut self) -> usize {
        self.nodes.push(Node::EMPTY);
        self.nodes.len() - 1
    }

    /// Appends a hierarchy made apart (its root first), its references moved by this one's
    /// node, packet and ellipsoid counts; returns the reference of its root.
    pub(crate) fn append(&mut self, part: Draft) -> Result<u32> {
        let (nodes, triangles, ellipsoids) = (
            self.nodes.len() as u32,
            self.packets.len(),
            self.ellipsoids.len(),
        );
        if triangles + part.packets.len() > FIRST_MASK as usize
            || ellipsoids + part.ellipsoids.len() > FIRST_MASK as usize
        {
            bail!(TOO_MANY_PACKETS);
        }
        let counts = [nodes as usize, triangles, ellipsoids];
        self.nodes.extend(part.nodes.into_iter().map(|mut node| {
            node.children = node.children.map(|child| relocated(child, counts));
            node
        }));
        self.packets.extend(part.packets);
        self.ellipsoids.extend(part.ellipsoids);
        Ok(nodes)
    }

    /// The hierarchy of drafts made apart (each its root first), concatenated: each one's
    /// references moved by the node, packet and ellipsoid counts of those before it, its
    /// packets packed from `world`'s triangles; each link [part, node, slot, linked part]
    /// then refers that child slot to the linked part's root.
    pub(crate) fn concatenate(
        parts: &[&Draft],
        links: &[[usize; 4]],
        world: &World,
    ) -> Result<Bvh> {
        let starts = |len: fn(&Draft) -> usize| -> (Vec<usize>, usize) {
            let mut total = 0;
            let starts = parts
                .iter()
                .map(|part| {
                    total += len(part);
                    total - len(part)
                })
                .collect();
            (starts, total)
        };
        let (nodes, node_count) = starts(|b| b.nodes.len());
        let (triangles, triangle_count) = starts(|b| b.packets.len());
        let (ellipsoids, ellipsoid_count) = starts(|b| b.ellipsoids.len());
        if triangle_count > FIRST_MASK as usize || ellipsoid_count > FIRST_MASK as usize {
            bail!(TOO_MANY_PACKETS);
        }
        let out_nodes = concatenated(
            parts,
            |b| &b.nodes,
            (&nodes, node_count),
            |i, node| {
                let counts = [nodes[i], triangles[i], ellipsoids[i]];
                Node {
                    children: node.children.map(|child| relocated(child, counts)),
                    ..*node
                }
            },
        );
        let mut out = Bvh {
            builder: None,
            nodes: out_nodes,
            triangles: concatenated(
                parts,
                |b| &b.packets,
                (&triangles, triangle_count),
                |_, prims| Triangles4::new(&world.triangles, prims),
            ),
            ellipsoids: concatenated(
                parts,
                |b| &b.ellipsoids,
                (&ellipsoids, ellipsoid_count),
                |_, e| *e,
            ),
        };
        for &[part, node, slot, linked] in links {
            out.nodes[nodes[part] + node].children[slot] = nodes[linked] as u32;
        }
        Ok(out)
    }

    /// Puts primitives `prims` of `world` (all triangles, or all ellipsoids) in a leaf and
    /// returns its reference.
    pub(crate) fn push_leaf(
        &mut self,
        world: &World,
        prims: &mut Vec<u32>,
        triangles: bool,
    ) -> Result<u32> {
        // Spatial splits can put one primitive in several boxes of the same subtree.
        prims.sort_unstable();
        prims.dedup();
        let (first, count, kind) = if triangles {
            let first = self.packets.len();
            self.packets.extend(prims.chunks(TRI_LANES).map(|chunk| {
                // Unused lanes repeat the first, as `Triangles4::new` fills them.
                let mut packet = [chunk[0]; TRI_LANES];
                packet[..chunk.len()].copy_from_slice(chunk);
                packet
            }));
            (first, prims.len().div_ceil(TRI_LANES), 0)
        } else {
            let first = self.ellipsoids.len();
            let offset = world.ellipsoid_base();
            self.ellipsoids.extend(prims.iter().map(|&p| EllipsoidLeaf {
                ellipsoid: world.ellipsoids[p as usize - offset],
                prim: p,
            }));
            (first, prims.len(), ELLIPSOIDS)
        };
        if count > MAX_LEAF_PACKETS || first + count > FIRST_MASK as usize {
            bail!(TOO_MANY_PACKETS);
        }
        Ok(LEAF | kind | ((count as u32 - 1) << COUNT_SHIFT) | first as u32)
    }
}

/// Child reference `child` of a hierarchy placed after `counts` = [nodes, triangle packets,
/// ellipsoid leaves] of another.
fn relocated(child: u32, [nodes, triangles, ellipsoids]: [usize; 3]) -> u32 {
    if child == EMPTY {
        child
    } else if child & LEAF == 0 {
        child + nodes as u32
    } else if child & ELLIPSOIDS != 0 {
        child + ellipsoids as u32
    } else {
        child + triangles as u32
    }
}

/// The arrays `field` of `parts` one after the other, each element mapped by `map` (given
/// its part's index), made side by side; `(starts, total)`: where each part's elements start,
/// and their count.
fn concatenated<T: Send + Sync, U: Send>(
    parts: &[&Draft],
    field: impl Fn(&Draft) -> &Vec<T> + Sync,
    (starts, total): (&[usize], usize),
    map: impl Fn(usize, &T) -> U + Sync,
) -> Vec<U> {
    (0..total)
        .into_par_iter()
        .with_min_len(1 << 12)
        .map(|k| {
            // The last part that starts at or before k: the one holding it (an empty part
            // starts where the next does).
            let i = starts.partition_point(|&s| s <= k) - 1;
            map(i, &field(parts[i])[k - starts[i]])
        })
        .collect()
}

/// What the builder needs to know of a BVH2 subtree.
#[derive(Clone, Copy, Default)]
struct Summary {
    /// Primitive references under the node (a split primitive counts once per box).
    count: u32,
    /// Whether they are all triangles, or all ellipsoids.
    triangles: bool,
    ellipsoids: bool,
}

/// Summaries of every BVH2 node; primitives below `triangle_count` are triangles.
fn summarise(bvh2: &Bvh2, triangle_count: u32) -> Vec<Summary> {
    let mut summaries = vec![Summary::default(); bvh2.nodes.len()];
    // Preorder, then children before parents.
    let mut order: Vec<usize> = Vec::with_capacity(bvh2.nodes.len());
    let mut todo = vec![0usize];
    while let Some(i) = todo.pop() {
        order.push(i);
        let node = &bvh2.nodes[i];
        if !node.is_leaf() {
            todo.push(node.first_index as usize);
            todo.push(node.first_index as usize + 1);
        }
    }
    for &i in order.iter().rev() {
        let node = &bvh2.nodes[i];
        summaries[i] = if node.is_leaf() {
            // A PLOC leaf holds one box, and `first_index` is that box's primitive.
            let triangle = node.first_index < triangle_count;
            Summary {
                count: node.prim_count,
                triangles: triangle,
                ellipsoids: !triangle,
            }
        } else {
            let (a, b) = (
                summaries[node.first_index as usize],
                summaries[node.first_index as usize + 1],
            );
            Summary {
                count: a.count + b.count,
                triangles: a.triangles && b.triangles,
                ellipsoids: a.ellipsoids && b.ellipsoids,
            }
        };
    }
    summaries
}

struct Builder<'a> {
    bvh2: &'a Bvh2,
    summaries: &'a [Summary],
    world: &'a World,
    out: &'a mut Draft,
}

impl Builder<'_> {
    fn area(&self, node: usize) -> f32 {
        self.bvh2.nodes[node].aabb().half_area()
    }

    /// Whether the subtree under a BVH2 node becomes one leaf: one packet of one kind.
    fn is_leaf(&self, node: usize) -> bool {
        let s = self.summaries[node];
        self.bvh2.nodes[node].is_leaf()
            || (s.triangles && s.count as usize <= TRI_LANES)
            || (s.ellipsoids && s.count == 1)
    }

    /// Fills wide node `at` with the subtrees of BVH2 nodes `start`, opened largest first
    /// until there are `WIDTH`.
    fn fill(&mut self, at: usize, start: &[usize], depth: usize) -> Result<()> {
        // A closest-hit query stacks at most WIDTH − 1 entries per level, an any-hit WIDTH.
        // The binary hierarchy is at most `bvh_build::MAX_DEPTH` deep, and each wide level
        // descends at least one binary level: this cannot fail.
        if depth * WIDTH > STACK {
            bail!(
                "internal error: the scene's hierarchy is deeper than {} levels",
                STACK / WIDTH
            );
        }
        let mut children: Vec<usize> = start.to_vec();
        while children.len() < WIDTH {
            let open = children
                .iter()
                .enumerate()
                .filter(|&(_, &c)| !self.is_leaf(c))
                .max_by(|a, b| self.area(*a.1).total_cmp(&self.area(*b.1)));
            let Some((i, &c)) = open else { break };
            let first = self.bvh2.nodes[c].first_index as usize;
            children[i] = first;
            children.insert(i + 1, first + 1);
        }
        let mut node = Node::EMPTY;
        let mut inner = Vec::new();
        for (slot, &c) in children.iter().enumerate() {
            node.set_child_box(slot, self.bvh2.nodes[c].aabb());
            if self.is_leaf(c) {
                node.children[slot] = self.leaf(c)?;
            } else {
                inner.push((slot, c));
            }
        }
        let boxes: u32 = start.iter().map(|&c| self.summaries[c].count).sum();
        if depth == 1 && boxes as usize >= PARALLEL_BOXES {
            // A big hierarchy: the root's subtrees are made side by side, each into its own
            // arrays, then appended in slot order. The layout differs from the one-thread
            // order below, not the answers: a query's hit never depends on the order it
            // visits the leaves in (`closer`), and the layout is the same on any thread count.
            let (bvh2, summaries, world) = (self.bvh2, self.summaries, self.world);
            let parts: Vec<Result<Draft>> = inner
                .par_iter()
                .map(|&(_, c)| {
                    let mut part = Draft::with_room(0);
                    let mut builder = Builder {
                        bvh2,
                        summaries,
                        world,
                        out: &mut part,
                    };
                    let root = builder.out.reserve();
                    let first = bvh2.nodes[c].first_index as usize;
                    builder.fill(root, &[first, first + 1], depth + 1)?;
                    Ok(part)
                })
                .collect();
            for ((slot, _), part) in inner.iter().zip(parts) {
                node.children[*slot] = self.out.append(part?)?;
            }
            self.out.nodes[at] = node;
            return Ok(());
        }
        let mut reserved = Vec::with_capacity(inner.len());
        for &(slot, c) in &inner {
            let index = self.out.reserve();
            node.children[slot] = index as u32;
            reserved.push((index, c));
        }
        self.out.nodes[at] = node;
        for (index, c) in reserved {
            let first = self.bvh2.nodes[c].first_index as usize;
            self.fill(index, &[first, first + 1], depth + 1)?;
        }
        Ok(())
    }

    /// Packs the primitives under BVH2 node `node` into a leaf and returns its reference.
    fn leaf(&mut self, node: usize) -> Result<u32> {
        let mut prims = Vec::new();
        let mut todo = vec![node];
        while let Some(i) = todo.pop() {
            let n = &self.bvh2.nodes[i];
            if n.is_leaf() {
                prims.extend(n.first_index..n.first_index + n.prim_count);
            } else {
                todo.push(n.first_index as usize);
                todo.push(n.first_index as usize + 1);
            }
        }
        self.out
            .push_leaf(self.world, &mut prims, self.summaries[node].triangles)
    }
}

/// Drawn nodes and rays for the checks of the box tests against the slab test's min and max
/// (here and in `bvh_packet.rs`).
#[cfg(test)]
pub(crate) mod drawn {
    use super::{Node, TraceRay, WIDTH};

    /// A seeded stream of floats in [−1, 1).
    pub(crate) struct Draws(u64);

    impl Draws {
        pub(crate) fn new(seed: u64) -> Draws {
            Draws(seed)
        }

        pub(crate) fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        }

        /// A node whose first `used` children have drawn boxes within ±8 m (flat ones, every
        /// axis's two planes equal, where `flat`), the rest empty.
        pub(crate) fn node(&mut self, used: usize, flat: bool) -> Node {
            let mut node = Node::EMPTY;
            for c in 0..used.min(WIDTH) {
                for axis in 0..3 {
                    let (a, b) = (8.0 * self.next(), 8.0 * self.next());
                    let b = if flat { a } else { b };
                    node.bounds[2 * axis][c] = a.min(b);
                    node.bounds[2 * axis + 1][c] = a.max(b);
                }
                node.children[c] = c as u32;
            }
            node
        }

        /// Ray `k` of a drawn set: from within ±4 m, every octant, every fifth with one
        /// direction component ±0 (axis-parallel in that axis), every third with tmax 2 m.
        pub(crate) fn ray(&mut self, k: usize) -> TraceRay {
            let mut d = glam::Vec3::new(self.next(), self.next(), self.next());
            if k.is_multiple_of(5) {
                d[k % 3] = if k.is_multiple_of(2) { 0.0 } else { -0.0 };
            }
            let o = glam::Vec3::new(4.0 * self.next(), 4.0 * self.next(), 4.0 * self.next());
            let tmax = if k.is_multiple_of(3) {
                2.0
            } else {
                f32::INFINITY
            };
            let d = d.normalize_or(glam::Vec3::X);
            TraceRay::new(o.into(), d.into(), 0.0, tmax)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::drawn::Draws;
    use super::*;

    /// The slab test of child `c` as the min and max of its two planes' distances per axis,
    /// in the order the per-ray test took them before it knew its near and far rows: whether
    /// `ray` enters the child, and where.
    fn slab_min_max(node: &Node, c: usize, ray: &TraceRay) -> (bool, f32) {
        let b = &node.bounds;
        let d = |axis: usize, row: usize| (b[row][c] - ray.origin[axis]) * ray.inv_dir[axis];
        let (x0, x1, y0, y1, z0, z1) = (d(0, 0), d(0, 1), d(1, 2), d(1, 3), d(2, 4), d(2, 5));
        let e = max(max(max(ray.tmin, min(z0, z1)), min(y0, y1)), min(x0, x1));
        let x = min(min(min(ray.tmax, max(z0, z1)), max(y0, y1)), max(x0, x1));
        (e <= x * EXIT_ROUND_UP, e)
    }

    /// The per-ray test of a node's eight children, with the ray's near and far rows,
    /// against the slab test's min and max ([`slab_min_max`]): the same children
    /// entered at the same entries, for drawn boxes (some flat) and rays of every octant,
    /// axis-parallel ones among them, and an empty slot never entered.
    #[test]
    fn a_node_tested_with_the_rays_near_and_far_rows_answers_as_with_min_and_max() {
        let mut draws = Draws::new(0x9e37_79b9_7f4a_7c15);
        let mut entered = 0;
        for case in 0..300 {
            let node = draws.node(WIDTH - 1, case % 7 == 0);
            for k in 0..16 {
                let ray = draws.ray(k);
                let (mask, entries) = node.intersect(&RayLanes::new(&ray), ray.tmin, ray.tmax);
                assert_eq!(mask >> (WIDTH - 1), 0, "the empty slot was entered");
                for (c, &got_entry) in entries.iter().enumerate().take(WIDTH - 1) {
                    let (want, want_entry) = slab_min_max(&node, c, &ray);
                    let got = mask >> c & 1 != 0;
                    assert_eq!(got, want, "case {case}, ray {k}, child {c}");
                    assert_eq!(got_entry, want_entry, "case {case}, ray {k}, child {c}");
                    entered += usize::from(got);
                }
            }
        }
        assert!(
            (3_000..25_000).contains(&entered),
            "{entered} of 33 600 entered"
        );
    }
}
