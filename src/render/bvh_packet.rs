//! Packet traversal of the wide BVH: up to [`PACKET`] coherent rays (a tile's camera rays,
//! or the shadow rays toward the sun from a tile's hits) traced together.
//!
//! Each node's child boxes are tested against every ray of the packet at once, one ray per
//! SIMD lane, and a child is entered if any active ray enters it, with the mask of the rays
//! that do; a leaf's triangles are tested one at a time against all of them. The kernels are
//! plain loops over fixed-size arrays (`[f32; N]`), generic over the lane count `N`, that the
//! compiler vectorises: `render/simd.rs` compiles them for AVX-512 (16 lanes), AVX2
//! (8 lanes) and baseline x86-64 or any other target (4 lanes) and picks one at run time.
//!
//! Every lane computes what the per-ray traversal ([`crate::render::bvh::Bvh::closest`])
//! computes for its ray, operation for operation and without fused multiply-adds: the same
//! conservative box test, the same triangle test, and the same choice of the closest hit
//! ([`closer`]), which does not depend on the order of the tests. So a packet gives every ray
//! the hit the per-ray path gives it, bit for bit, on every ISA (`tests/accel.rs`).

use std::cell::RefCell;

use glam::Vec3A;

use crate::render::bvh::{
    Bvh, COUNT_MASK, COUNT_SHIFT, ELLIPSOIDS, EMPTY, EXIT_ROUND_UP, FIRST_MASK, LEAF, NO_PRIM,
    Node, STACK, WIDTH, max, min,
};
use crate::render::packets::{TRI_LANES, Triangles4, closer};
use crate::render::ray::{Hit, TraceRay, reciprocal};

/// Rays per packet: a 4×4 tile of pixels.
pub const PACKET: usize = 16;

/// Up to [`PACKET`] rays, structure of arrays, with the closest hit found so far per ray.
#[derive(Clone, Copy, Debug)]
pub struct RayPacket {
    /// Origin per axis and lane, world frame, metres.
    pub origin: [[f32; PACKET]; 3],
    /// Unit direction per axis and lane, world frame.
    pub dir: [[f32; PACKET]; 3],
    /// Reciprocal direction, as [`TraceRay::inv_dir`].
    pub inv_dir: [[f32; PACKET]; 3],
    /// Distance interval per lane, metres; `tmax` shrinks to the closest hit found.
    pub tmin: [f32; PACKET],
    pub tmax: [f32; PACKET],
    /// Primitive of the closest hit found per lane ([`NO_PRIM`]: none).
    pub prim: [u32; PACKET],
    /// Lanes that hold a ray (bit i for lane i).
    pub active: u32,
}

impl Default for RayPacket {
    fn default() -> Self {
        Self::new()
    }
}

impl RayPacket {
    /// A packet with no rays.
    pub fn new() -> RayPacket {
        RayPacket {
            origin: [[0.0; PACKET]; 3],
            dir: [[1.0; PACKET]; 3],
            inv_dir: [[1.0; PACKET]; 3],
            tmin: [0.0; PACKET],
            tmax: [0.0; PACKET],
            prim: [NO_PRIM; PACKET],
            active: 0,
        }
    }

    /// Puts `ray` in lane `lane` (and makes the lane active, with no hit found yet).
    #[inline]
    pub fn set(&mut self, lane: usize, ray: &TraceRay) {
        for axis in 0..3 {
            self.origin[axis][lane] = ray.origin[axis];
            self.dir[axis][lane] = ray.dir[axis];
            self.inv_dir[axis][lane] = ray.inv_dir[axis];
        }
        self.tmin[lane] = ray.tmin;
        self.tmax[lane] = ray.tmax;
        self.prim[lane] = NO_PRIM;
        self.active |= 1 << lane;
    }

    /// Lanes `0..n` hold the rays over [0, ∞) that `ray(lane)` gives (origin, unit
    /// direction; world frame), with no hit found yet, and the others none: what
    /// [`RayPacket::set`] of [`TraceRay::new`] gives lane by lane, filled axis by axis across
    /// the lanes instead (vector operations, where lane by lane costs a dozen scalar stores
    /// and a division per ray: 3 of the 29 ns per camera ray of `bench`'s packets).
    ///
    /// # Panics
    /// If `n` > [`PACKET`].
    #[inline(always)]
    pub fn set_from_zero(&mut self, n: usize, ray: impl Fn(usize) -> (glam::Vec3, glam::Vec3)) {
        assert!(n <= PACKET, "{n} rays in a packet of {PACKET}");
        for lane in 0..PACKET {
            let (o, d) = if lane < n {
                ray(lane)
            } else {
                (glam::Vec3::ZERO, glam::Vec3::ONE)
            };
            for axis in 0..3 {
                self.origin[axis][lane] = o[axis];
                self.dir[axis][lane] = d[axis];
            }
        }
        for axis in 0..3 {
            for lane in 0..PACKET {
                self.inv_dir[axis][lane] = reciprocal(self.dir[axis][lane]);
            }
        }
        self.tmin = [0.0; PACKET];
        self.tmax = [f32::INFINITY; PACKET];
        self.prim = [NO_PRIM; PACKET];
        self.active = ((1u64 << n) - 1) as u32;
    }

    /// Empties the packet (its lanes keep their old rays, inactive).
    #[inline]
    pub fn clear(&mut self) {
        self.active = 0;
    }

    /// The ray of lane `lane`, with `tmax` as it now stands.
    pub fn ray(&self, lane: usize) -> TraceRay {
        let v = |a: &[[f32; PACKET]; 3]| Vec3A::new(a[0][lane], a[1][lane], a[2][lane]);
        TraceRay {
            origin: v(&self.origin),
            dir: v(&self.dir),
            inv_dir: v(&self.inv_dir),
            tmin: self.tmin[lane],
            tmax: self.tmax[lane],
        }
    }

    /// The closest hit found in lane `lane`.
    #[inline]
    pub fn hit(&self, lane: usize) -> Option<Hit> {
        (self.prim[lane] != NO_PRIM).then(|| Hit {
            prim: self.prim[lane] as usize,
            t: self.tmax[lane],
        })
    }
}

/// The traversal stack of packet queries (child reference, lanes, each lane's entry distance),
/// allocated once per thread and reused.
pub struct PacketStack {
    nodes: Vec<u32>,
    masks: Vec<[bool; PACKET]>,
    entries: Vec<[f32; PACKET]>,
}

impl Default for PacketStack {
    fn default() -> Self {
        Self::new()
    }
}

impl PacketStack {
    pub fn new() -> PacketStack {
        PacketStack {
            nodes: Vec::with_capacity(STACK),
            masks: Vec::with_capacity(STACK),
            entries: Vec::with_capacity(STACK),
        }
    }

    #[inline(always)]
    fn clear(&mut self) {
        self.nodes.clear();
        self.masks.clear();
        self.entries.clear();
    }

    /// Runs `f` with this thread's stack, allocated once per thread (a fresh one where the
    /// thread's is in use further up its call stack). A stack per rayon split (`map_init`)
    /// cost about a seventh of `bench`'s shadow batch on two threads: its 86 kB were fresh pages,
    /// faulted in, at every split.
    pub fn with_thread_stack<R>(f: impl FnOnce(&mut PacketStack) -> R) -> R {
        thread_local! {
            static STACK: RefCell<PacketStack> = RefCell::new(PacketStack::new());
        }
        STACK.with(|cell| match cell.try_borrow_mut() {
            Ok(mut stack) => f(&mut stack),
            Err(_) => f(&mut PacketStack::new()),
        })
    }
}

/// `N` lanes of a packet, loaded for a kernel.
struct Lanes<const N: usize> {
    o: [[f32; N]; 3],
    d: [[f32; N]; 3],
    inv: [[f32; N]; 3],
    tmin: [f32; N],
    tmax: [f32; N],
    prim: [u32; N],
}

#[inline(always)]
fn part<const N: usize, T: Copy + Default>(a: &[T; PACKET], base: usize) -> [T; N] {
    let mut out = [T::default(); N];
    out.copy_from_slice(&a[base..base + N]);
    out
}

impl<const N: usize> Lanes<N> {
    #[inline(always)]
    fn load(p: &RayPacket, base: usize) -> Lanes<N> {
        Lanes {
            o: [0, 1, 2].map(|a| part(&p.origin[a], base)),
            d: [0, 1, 2].map(|a| part(&p.dir[a], base)),
            inv: [0, 1, 2].map(|a| part(&p.inv_dir[a], base)),
            tmin: part(&p.tmin, base),
            tmax: part(&p.tmax, base),
            prim: part(&p.prim, base),
        }
    }

    #[inline(always)]
    fn store(&self, p: &mut RayPacket, base: usize) {
        p.tmax[base..base + N].copy_from_slice(&self.tmax);
        p.prim[base..base + N].copy_from_slice(&self.prim);
    }
}

/// Lanes of a kernel: `true` where the lane's ray takes part. Kept as one `bool` per lane, not
/// as bits: the compiler turns these loops into vector compares and blends, where building
/// an integer of bits cost a dozen instructions per box test.
type Mask<const N: usize> = [bool; N];

/// Bit i set where `c[i]` (once per packet, at the end).
#[inline(always)]
fn bits_of<const N: usize>(c: Mask<N>) -> u32 {
    let mut m = 0u32;
    for (i, &b) in c.iter().enumerate() {
        m |= u32::from(b) << i;
    }
    m
}

/// `c[i]` where bit i of `mask` is set.
#[inline(always)]
fn lanes_of<const N: usize>(mask: u32) -> Mask<N> {
    std::array::from_fn(|i| (mask >> i) & 1 != 0)
}

#[inline(always)]
fn and<const N: usize>(a: Mask<N>, b: Mask<N>) -> Mask<N> {
    std::array::from_fn(|i| a[i] & b[i])
}

/// Whether any lane is set (a reduction, without early exit, so that it vectorises).
#[inline(always)]
fn any_set<const N: usize>(c: &Mask<N>) -> bool {
    c.iter().fold(false, |a, &b| a | b)
}

/// Which lanes enter child `c` of `node` within their [tmin, tmax], and where: the box test
/// of `bvh.rs`'s `Node::intersect`, per lane.
#[inline(always)]
fn child_hits<const N: usize>(
    node: &Node,
    c: usize,
    l: &Lanes<N>,
    entry: &mut [f32; N],
) -> Mask<N> {
    let b = &node.bounds;
    let (bx0, bx1, by0, by1, bz0, bz1) = (b[0][c], b[1][c], b[2][c], b[3][c], b[4][c], b[5][c]);
    let mut hit = [false; N];
    for i in 0..N {
        let (x0, x1) = (
            (bx0 - l.o[0][i]) * l.inv[0][i],
            (bx1 - l.o[0][i]) * l.inv[0][i],
        );
        let (y0, y1) = (
            (by0 - l.o[1][i]) * l.inv[1][i],
            (by1 - l.o[1][i]) * l.inv[1][i],
        );
        let (z0, z1) = (
            (bz0 - l.o[2][i]) * l.inv[2][i],
            (bz1 - l.o[2][i]) * l.inv[2][i],
        );
        let e = max(max(max(l.tmin[i], min(z0, z1)), min(y0, y1)), min(x0, x1));
        let x = min(min(min(l.tmax[i], max(z0, z1)), max(y0, y1)), max(x0, x1));
        entry[i] = e;
        hit[i] = e <= x * EXIT_ROUND_UP;
    }
    hit
}

/// The triangle test of [`Triangles4`] (obvhs' `RtTriangle::intersect`) for lane `j` of
/// `packet` against every ray: each lane's distance, and whether it is a hit in [tmin, tmax].
#[inline(always)]
fn triangle_hits<const N: usize>(
    packet: &Triangles4,
    j: usize,
    l: &Lanes<N>,
    t_out: &mut [f32; N],
) -> Mask<N> {
    let [v0x, v0y, v0z] = packet.v0.map(|v| v[j]);
    let [e1x, e1y, e1z] = packet.e1.map(|v| v[j]);
    let [e2x, e2y, e2z] = packet.e2.map(|v| v[j]);
    let [ngx, ngy, ngz] = crate::scene::instances::normal([e1x, e1y, e1z], [e2x, e2y, e2z]);
    let mut valid = [false; N];
    for i in 0..N {
        let (dx, dy, dz) = (l.d[0][i], l.d[1][i], l.d[2][i]);
        let (cx, cy, cz) = (v0x - l.o[0][i], v0y - l.o[1][i], v0z - l.o[2][i]);
        let rx = dy * cz - dz * cy;
        let ry = dz * cx - dx * cz;
        let rz = dx * cy - dy * cx;
        let inv_det = 1.0 / (ngx * dx + ngy * dy + ngz * dz);
        let u = (rx * e2x + ry * e2y + rz * e2z) * inv_det;
        let v = (rx * e1x + ry * e1y + rz * e1z) * inv_det;
        let w = 1.0 - u - v;
        let t = (ngx * cx + ngy * cy + ngz * cz) * inv_det;
        // A -0.0 barycentric is a miss, like a negative one (the sign bit, as obvhs).
        let outside = (u.to_bits() | v.to_bits() | w.to_bits()) >> 31 != 0;
        t_out[i] = t;
        valid[i] = inv_det != 0.0 && t >= l.tmin[i] && t <= l.tmax[i] && !outside;
    }
    valid
}

/// Lanes of a triangle packet in use: its unused lanes repeat lane 0's primitive, which no
/// other lane holds.
#[inline(always)]
fn used_lanes(packet: &Triangles4) -> usize {
    (1..TRI_LANES)
        .find(|&j| packet.prim[j] == packet.prim[0])
        .unwrap_or(TRI_LANES)
}

/// Tests the rays of `on` against leaf `leaf`'s primitives for their closest hits.
#[inline(always)]
fn leaf_closest<const N: usize>(bvh: &Bvh, leaf: u32, l: &mut Lanes<N>, on: Mask<N>) {
    let first = (leaf & FIRST_MASK) as usize;
    let count = ((leaf >> COUNT_SHIFT) & COUNT_MASK) as usize + 1;
    if leaf & ELLIPSOIDS == 0 {
        for packet in &bvh.triangles[first..first + count] {
            for j in 0..used_lanes(packet) {
                let prim = packet.prim[j];
                let mut t = [0.0; N];
                let valid = triangle_hits(packet, j, l, &mut t);
                for i in 0..N {
                    let take = on[i] && valid[i] && closer(t[i], prim, l.tmax[i], l.prim[i]);
                    l.tmax[i] = if take { t[i] } else { l.tmax[i] };
                    l.prim[i] = if take { prim } else { l.prim[i] };
                }
            }
        }
    } else {
        for e in &bvh.ellipsoids[first..first + count] {
            for i in (0..N).filter(|&i| on[i]) {
                let (o, d) = (lane_vec(&l.o, i), lane_vec(&l.d, i));
                let t = e.ellipsoid.intersect(o, d, l.tmin[i], l.tmax[i]);
                if t.is_finite() && closer(t, e.prim, l.tmax[i], l.prim[i]) {
                    l.tmax[i] = t;
                    l.prim[i] = e.prim;
                }
            }
        }
    }
}

/// Adds to `blocked` the rays of `on` that hit a primitive of leaf `leaf` in their
/// [tmin, tmax].
#[inline(always)]
fn leaf_any<const N: usize>(
    bvh: &Bvh,
    leaf: u32,
    l: &Lanes<N>,
    on: Mask<N>,
    blocked: &mut Mask<N>,
) {
    let first = (leaf & FIRST_MASK) as usize;
    let count = ((leaf >> COUNT_SHIFT) & COUNT_MASK) as usize + 1;
    if leaf & ELLIPSOIDS == 0 {
        for packet in &bvh.triangles[first..first + count] {
            for j in 0..used_lanes(packet) {
                let mut t = [0.0; N];
                let hit = triangle_hits(packet, j, l, &mut t);
                for i in 0..N {
                    blocked[i] |= hit[i] & on[i];
                }
            }
        }
    } else {
        for e in &bvh.ellipsoids[first..first + count] {
            for i in 0..N {
                if !on[i] || blocked[i] {
                    continue;
                }
                let (o, d) = (lane_vec(&l.o, i), lane_vec(&l.d, i));
                if e.ellipsoid
                    .intersect(o, d, l.tmin[i], l.tmax[i])
                    .is_finite()
                {
                    blocked[i] = true;
                }
            }
        }
    }
}

#[inline(always)]
fn lane_vec<const N: usize>(a: &[[f32; N]; 3], i: usize) -> Vec3A {
    Vec3A::new(a[0][i], a[1][i], a[2][i])
}

/// Closest hits of the rays of `on` in `l`, as [`Bvh::closest`] per ray.
#[inline(always)]
fn closest_lanes<const N: usize>(
    bvh: &Bvh,
    l: &mut Lanes<N>,
    on: Mask<N>,
    stack: &mut PacketStack,
) {
    stack.clear();
    let mut entry = [0.0; PACKET];
    entry[..N].copy_from_slice(&l.tmin);
    let mut mask = [false; PACKET];
    mask[..N].copy_from_slice(&on);
    stack.nodes.push(0);
    stack.masks.push(mask);
    stack.entries.push(entry);
    while let Some(current) = stack.nodes.pop() {
        let mask: Mask<N> = part(&stack.masks.pop().unwrap_or([false; PACKET]), 0);
        let entry: [f32; N] = part(&stack.entries.pop().unwrap_or([0.0; PACKET]), 0);
        // Lanes whose closest hit so far is nearer than the subtree are done with it.
        let on: Mask<N> =
            std::array::from_fn(|i| mask[i] & (entry[i] <= l.tmax[i] * EXIT_ROUND_UP));
        if !any_set(&on) {
            continue;
        }
        if current & LEAF != 0 {
            leaf_closest(bvh, current, l, on);
            continue;
        }
        let node = &bvh.nodes[current as usize];
        // The children any lane enters, sorted far to near by their nearest lane's entry.
        let mut keys = [u64::MAX; WIDTH];
        let mut masks = [[false; PACKET]; WIDTH];
        let mut entries = [[0.0f32; PACKET]; WIDTH];
        let mut n = 0;
        for c in 0..WIDTH {
            if node.children[c] == EMPTY {
                break;
            }
            let mut e = [0.0; N];
            let m = and(child_hits(node, c, l, &mut e), on);
            if !any_set(&m) {
                continue;
            }
            // Entries are at least tmin ≥ 0: non-negative floats order as their bits.
            let nearest = (0..N).fold(u32::MAX, |a, i| {
                a.min(if m[i] {
                    e[i].to_bits() & 0x7fff_ffff
                } else {
                    u32::MAX
                })
            });
            keys[n] = (u64::from(nearest) << 32) | c as u64;
            masks[c][..N].copy_from_slice(&m);
            entries[c][..N].copy_from_slice(&e);
            n += 1;
        }
        // Far to near (insertion sort: a few keys).
        for a in 1..n {
            let mut b = a;
            while b > 0 && keys[b - 1] < keys[b] {
                keys.swap(b - 1, b);
                b -= 1;
            }
        }
        for &k in &keys[..n] {
            let c = (k & 0xff) as usize;
            stack.nodes.push(node.children[c]);
            stack.masks.push(masks[c]);
            stack.entries.push(entries[c]);
        }
    }
}

/// Which rays of `on` in `l` are blocked, as [`Bvh::any`] per ray.
#[inline(always)]
fn any_lanes<const N: usize>(
    bvh: &Bvh,
    l: &Lanes<N>,
    on: Mask<N>,
    stack: &mut PacketStack,
) -> Mask<N> {
    stack.clear();
    let mut mask = [false; PACKET];
    mask[..N].copy_from_slice(&on);
    stack.nodes.push(0);
    stack.masks.push(mask);
    let mut blocked = [false; N];
    let mut scratch = [0.0; N];
    while let Some(current) = stack.nodes.pop() {
        let m: Mask<N> = part(&stack.masks.pop().unwrap_or([false; PACKET]), 0);
        let m: Mask<N> = std::array::from_fn(|i| m[i] & !blocked[i]);
        if !any_set(&m) {
            continue;
        }
        if current & LEAF != 0 {
            leaf_any(bvh, current, l, m, &mut blocked);
            let open: Mask<N> = std::array::from_fn(|i| on[i] & !blocked[i]);
            if !any_set(&open) {
                return blocked;
            }
            continue;
        }
        let node = &bvh.nodes[current as usize];
        for c in 0..WIDTH {
            if node.children[c] == EMPTY {
                break;
            }
            let cm = and(child_hits(node, c, l, &mut scratch), m);
            if any_set(&cm) {
                let mut wide = [false; PACKET];
                wide[..N].copy_from_slice(&cm);
                stack.nodes.push(node.children[c]);
                stack.masks.push(wide);
            }
        }
    }
    blocked
}

/// The closest hits of `packet`'s active rays in `bvh`, `N` lanes at a time: shrinks each
/// lane's `tmax` and sets its `prim` where `bvh` holds a [`closer`] hit.
#[inline(always)]
pub(crate) fn closest<const N: usize>(bvh: &Bvh, packet: &mut RayPacket, stack: &mut PacketStack) {
    if bvh.nodes.is_empty() {
        return;
    }
    for base in (0..PACKET).step_by(N) {
        let mask = (packet.active >> base) & (u32::MAX >> (32 - N));
        if mask != 0 {
            let mut l = Lanes::<N>::load(packet, base);
            closest_lanes(bvh, &mut l, lanes_of(mask), stack);
            l.store(packet, base);
        }
    }
}

/// Which of `packet`'s active rays (bit i for lane i) a primitive of `bvh` blocks in their
/// [tmin, tmax], `N` lanes at a time.
#[inline(always)]
pub(crate) fn any<const N: usize>(bvh: &Bvh, packet: &RayPacket, stack: &mut PacketStack) -> u32 {
    if bvh.nodes.is_empty() {
        return 0;
    }
    let mut blocked = 0;
    for base in (0..PACKET).step_by(N) {
        let mask = (packet.active >> base) & (u32::MAX >> (32 - N));
        if mask != 0 {
            let l = Lanes::<N>::load(packet, base);
            blocked |= bits_of(any_lanes(bvh, &l, lanes_of(mask), stack)) << base;
        }
    }
    blocked
}
