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
//! conservative box test (each axis's near and far planes chosen by the direction's sign,
//! which answers as the slab test's min and max, bit for bit: [`child_hits`]; a packet is
//! walked once per octant among its rays), the same triangle test, and the same choice of
//! the closest hit
//! ([`closer`]), which does not depend on the order of the tests. So a packet gives every ray
//! the hit the per-ray path gives it, bit for bit, on every ISA (`tests/accel.rs`).

use std::cell::RefCell;

use glam::{Affine3A, Vec3A};

use crate::render::bvh::{
    Bvh, COUNT_MASK, COUNT_SHIFT, ELLIPSOIDS, EMPTY, EXIT_ROUND_UP, FIRST_MASK, LEAF, NO_PRIM,
    Node, Planes, STACK, WIDTH, max, min, packets_of,
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

    /// The active lanes among `base..base + N`, as bits from bit 0 (the lanes a kernel of `N`
    /// lanes takes at `base`).
    #[inline(always)]
    pub(crate) fn lanes_from<const N: usize>(&self, base: usize) -> u32 {
        (self.active >> base) & (u32::MAX >> (32 - N))
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
    /// The instance level's own stack of (node, lanes as bits, each lane's entry distance),
    /// beside this one (its walk runs mesh walks on the others at its leaves).
    pub(crate) placements: Vec<(u32, u32, [f32; PACKET])>,
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
            placements: Vec::with_capacity(64),
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

/// `N` rays of a packet, loaded for a kernel, in the frame their boxes (or triangles) are
/// tested in.
pub(crate) struct Rays<const N: usize> {
    o: [[f32; N]; 3],
    d: [[f32; N]; 3],
    inv: [[f32; N]; 3],
    tmin: [f32; N],
}

/// The closest hit found so far of each of `N` rays: distance (metres) and primitive.
pub(crate) struct Hits<const N: usize> {
    pub(crate) tmax: [f32; N],
    prim: [u32; N],
}

#[inline(always)]
fn part<const N: usize, T: Copy + Default>(a: &[T; PACKET], base: usize) -> [T; N] {
    let mut out = [T::default(); N];
    out.copy_from_slice(&a[base..base + N]);
    out
}

impl<const N: usize> Rays<N> {
    /// Lanes `base..base + N` of `p`.
    #[inline(always)]
    pub(crate) fn load(p: &RayPacket, base: usize) -> Rays<N> {
        Rays {
            o: [0, 1, 2].map(|a| part(&p.origin[a], base)),
            d: [0, 1, 2].map(|a| part(&p.dir[a], base)),
            inv: [0, 1, 2].map(|a| part(&p.inv_dir[a], base)),
            tmin: part(&p.tmin, base),
        }
    }

    /// These rays in the frame `frame_from_world` maps to, each as
    /// `TraceRay::new(frame_from_world.transform_point3a(o), ….transform_vector3a(d), …)`
    /// gives it, bit for bit (glam's order of operations, without fused multiply-adds): the
    /// same `t` in both frames.
    #[inline(always)]
    pub(crate) fn transformed(&self, frame_from_world: &Affine3A) -> Rays<N> {
        let c = [
            frame_from_world.matrix3.x_axis,
            frame_from_world.matrix3.y_axis,
            frame_from_world.matrix3.z_axis,
        ];
        let t = frame_from_world.translation;
        let linear = |v: &[[f32; N]; 3], row: usize, i: usize| {
            c[0][row] * v[0][i] + c[1][row] * v[1][i] + c[2][row] * v[2][i]
        };
        // Plain loops: `array::map` was compiled apart, without the kernels' target
        // features, and called at every placement a packet visits.
        let (mut o, mut d, mut inv) = ([[0.0; N]; 3], [[0.0; N]; 3], [[0.0; N]; 3]);
        for row in 0..3 {
            for i in 0..N {
                o[row][i] = linear(&self.o, row, i) + t[row];
                d[row][i] = linear(&self.d, row, i);
                inv[row][i] = reciprocal(d[row][i]);
            }
        }
        Rays {
            o,
            d,
            inv,
            tmin: self.tmin,
        }
    }
}

impl<const N: usize> Hits<N> {
    /// Lanes `base..base + N` of `p`.
    #[inline(always)]
    pub(crate) fn load(p: &RayPacket, base: usize) -> Hits<N> {
        Hits {
            tmax: part(&p.tmax, base),
            prim: part(&p.prim, base),
        }
    }

    #[inline(always)]
    pub(crate) fn store(&self, p: &mut RayPacket, base: usize) {
        p.tmax[base..base + N].copy_from_slice(&self.tmax);
        p.prim[base..base + N].copy_from_slice(&self.prim);
    }
}

/// Lanes of a kernel: `true` where the lane's ray takes part. Kept as one `bool` per lane, not
/// as bits: the compiler turns these loops into vector compares and blends, where building
/// an integer of bits cost a dozen instructions per box test.
pub(crate) type Mask<const N: usize> = [bool; N];

/// Bit i set where `c[i]` (once per packet, at the end).
#[inline(always)]
pub(crate) fn bits_of<const N: usize>(c: Mask<N>) -> u32 {
    let mut m = 0u32;
    for (i, &b) in c.iter().enumerate() {
        m |= u32::from(b) << i;
    }
    m
}

/// `c[i]` where bit i of `mask` is set.
#[inline(always)]
pub(crate) fn lanes_of<const N: usize>(mask: u32) -> Mask<N> {
    std::array::from_fn(|i| (mask >> i) & 1 != 0)
}

#[inline(always)]
pub(crate) fn and<const N: usize>(a: Mask<N>, b: Mask<N>) -> Mask<N> {
    std::array::from_fn(|i| a[i] & b[i])
}

/// Whether any lane is set (a reduction, without early exit, so that it vectorises).
#[inline(always)]
pub(crate) fn any_set<const N: usize>(c: &Mask<N>) -> bool {
    c.iter().fold(false, |a, &b| a | b)
}

/// Which lanes of `r` enter the box [`lo`, `hi`] within their [tmin, `tmax`], and where: the
/// box test of `bvh.rs`'s `Node::intersect`, per lane.
#[inline(always)]
pub(crate) fn box_hits<const N: usize>(
    lo: [f32; 3],
    hi: [f32; 3],
    r: &Rays<N>,
    tmax: &[f32; N],
    entry: &mut [f32; N],
) -> Mask<N> {
    let mut hit = [false; N];
    for i in 0..N {
        let (x0, x1) = (
            (lo[0] - r.o[0][i]) * r.inv[0][i],
            (hi[0] - r.o[0][i]) * r.inv[0][i],
        );
        let (y0, y1) = (
            (lo[1] - r.o[1][i]) * r.inv[1][i],
            (hi[1] - r.o[1][i]) * r.inv[1][i],
        );
        let (z0, z1) = (
            (lo[2] - r.o[2][i]) * r.inv[2][i],
            (hi[2] - r.o[2][i]) * r.inv[2][i],
        );
        let e = max(max(max(r.tmin[i], min(z0, z1)), min(y0, y1)), min(x0, x1));
        let x = min(min(min(tmax[i], max(z0, z1)), max(y0, y1)), max(x0, x1));
        entry[i] = e;
        hit[i] = e <= x * EXIT_ROUND_UP;
    }
    hit
}

/// Each lane's octant: bit a set where its reciprocal direction's axis-a component has its
/// sign bit set. A reciprocal is never 0 ([`reciprocal`] keeps it within ±1e20), so its
/// sign is its direction's (a NaN direction, which no triangle test hits, gets either).
#[inline(always)]
fn octants<const N: usize>(r: &Rays<N>) -> [u32; N] {
    let mut octant = [0; N];
    for (a, inv) in r.inv.iter().enumerate() {
        for i in 0..N {
            octant[i] |= (inv[i].to_bits() >> 31) << a;
        }
    }
    octant
}

/// The next octant group of the lanes of `rest`: the lanes of the octant of its first lane
/// (a shadow packet toward the sun, and a tile of camera rays off the image's centre lines,
/// are one group; a tile across those lines two or four), and that octant's [`Planes`];
/// takes them out of `rest`. (A loop over it, not a function that takes the walk as a
/// closure: the closure was compiled without the kernel's target features, 2.5× slower.)
#[inline(always)]
fn next_octant<const N: usize>(octant: &[u32; N], rest: &mut Mask<N>) -> Option<(Mask<N>, Planes)> {
    let mut first = N;
    for i in (0..N).rev() {
        if rest[i] {
            first = i;
        }
    }
    if first == N {
        return None;
    }
    let mut group = [false; N];
    for i in 0..N {
        group[i] = rest[i] & (octant[i] == octant[first]);
        rest[i] &= !group[i];
    }
    Some((group, Planes::of(octant[first])))
}

/// [`box_hits`] of child `c` of `node` for rays of the octant of `planes`, bit for bit in
/// every comparison, among the lanes of `on` (taken in the same loop: and-ed apart, the
/// 8-lane kernels moved the lanes byte by byte).
///
/// Within an octant the reciprocal's sign is known, and it is finite and not 0, so
/// (lo − o)·inv ≤ (hi − o)·inv where inv > 0 and ≥ where inv < 0 (subtraction and
/// multiplication round monotonically) and no NaN arises from finite bounds: the near
/// plane's distance is [`box_hits`]'s min and the far plane's its max. A tie may differ in
/// the sign of a zero, which compares equal and leaves the entry's sort key alone. Knowing
/// the planes saves six of the twenty-six vector operations of a child's test.
#[inline(always)]
fn child_hits<const N: usize>(
    node: &Node,
    c: usize,
    planes: &Planes,
    r: &Rays<N>,
    (tmax, on): (&[f32; N], &Mask<N>),
    entry: &mut [f32; N],
) -> Mask<N> {
    let b = &node.bounds;
    let near = planes.near.map(|row| b[row][c]);
    let far = planes.far.map(|row| b[row][c]);
    let mut hit = [false; N];
    for i in 0..N {
        let x0 = (near[0] - r.o[0][i]) * r.inv[0][i];
        let x1 = (far[0] - r.o[0][i]) * r.inv[0][i];
        let y0 = (near[1] - r.o[1][i]) * r.inv[1][i];
        let y1 = (far[1] - r.o[1][i]) * r.inv[1][i];
        let z0 = (near[2] - r.o[2][i]) * r.inv[2][i];
        let z1 = (far[2] - r.o[2][i]) * r.inv[2][i];
        let e = max(max(max(r.tmin[i], z0), y0), x0);
        let x = min(min(min(tmax[i], z1), y1), x1);
        entry[i] = e;
        hit[i] = on[i] & (e <= x * EXIT_ROUND_UP);
    }
    hit
}

/// The triangle test of [`Triangles4`] (obvhs' `RtTriangle::intersect`) for lane `j` of
/// `packet` against every ray: each lane's distance, and whether it is a hit in [tmin, tmax].
#[inline(always)]
fn triangle_hits<const N: usize>(
    packet: &Triangles4,
    j: usize,
    r: &Rays<N>,
    tmax: &[f32; N],
    t_out: &mut [f32; N],
) -> Mask<N> {
    let [v0x, v0y, v0z] = packet.v0.map(|v| v[j]);
    let [e1x, e1y, e1z] = packet.e1.map(|v| v[j]);
    let [e2x, e2y, e2z] = packet.e2.map(|v| v[j]);
    let [ngx, ngy, ngz] = crate::scene::instances::normal([e1x, e1y, e1z], [e2x, e2y, e2z]);
    let mut valid = [false; N];
    for i in 0..N {
        let (dx, dy, dz) = (r.d[0][i], r.d[1][i], r.d[2][i]);
        let (cx, cy, cz) = (v0x - r.o[0][i], v0y - r.o[1][i], v0z - r.o[2][i]);
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
        // `&`, not `&&`: short-circuits kept the 8-lane (AVX2) kernels' triangle tests
        // scalar, one lane at a time.
        valid[i] = (inv_det != 0.0) & (t >= r.tmin[i]) & (t <= tmax[i]) & !outside;
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

/// Tests the rays of `on` against `packet`'s triangles for their closest hits.
#[inline(always)]
fn triangles_closest<const N: usize>(
    packet: &Triangles4,
    r: &Rays<N>,
    h: &mut Hits<N>,
    on: Mask<N>,
) {
    // The lanes in use one by one, not as a loop: see `triangles_any`.
    const _: () = assert!(TRI_LANES == 4);
    let used = used_lanes(packet);
    triangle_closest(packet, 0, r, h, on);
    if used > 1 {
        triangle_closest(packet, 1, r, h, on);
    }
    if used > 2 {
        triangle_closest(packet, 2, r, h, on);
    }
    if used > 3 {
        triangle_closest(packet, 3, r, h, on);
    }
}

/// Tests the rays of `on` against triangle `j` of `packet` for their closest hits.
#[inline(always)]
fn triangle_closest<const N: usize>(
    packet: &Triangles4,
    j: usize,
    r: &Rays<N>,
    h: &mut Hits<N>,
    on: Mask<N>,
) {
    let prim = packet.prim[j];
    let mut t = [0.0; N];
    let valid = triangle_hits(packet, j, r, &h.tmax, &mut t);
    for i in 0..N {
        let take = on[i] & valid[i] & closer(t[i], prim, h.tmax[i], h.prim[i]);
        h.tmax[i] = if take { t[i] } else { h.tmax[i] };
        h.prim[i] = if take { prim } else { h.prim[i] };
    }
}

/// Adds to `blocked` the rays of `on` that hit a triangle of `packet` in [tmin, `tmax`].
#[inline(always)]
fn triangles_any<const N: usize>(
    packet: &Triangles4,
    r: &Rays<N>,
    tmax: &[f32; N],
    on: Mask<N>,
    blocked: &mut Mask<N>,
) {
    // Every lane, used or not (an unused lane repeats lane 0's triangle, which gives the same
    // answer), written out one by one: straight code, whatever the code around it. As a loop
    // bounded by the lanes in use, it was unrolled fourfold, eightfold or not at all as that
    // code changed, and das's shadow rays ran up to 13 % slower; as a loop of four, the
    // compiler sometimes folded the four bodies back into one behind a jump table, and the
    // blocked lanes were moved byte by byte around it (10-15 % slower).
    const _: () = assert!(TRI_LANES == 4);
    triangle_any(packet, 0, r, tmax, on, blocked);
    triangle_any(packet, 1, r, tmax, on, blocked);
    triangle_any(packet, 2, r, tmax, on, blocked);
    triangle_any(packet, 3, r, tmax, on, blocked);
}

/// Adds to `blocked` the rays of `on` that hit triangle `j` of `packet` in [tmin, `tmax`].
#[inline(always)]
fn triangle_any<const N: usize>(
    packet: &Triangles4,
    j: usize,
    r: &Rays<N>,
    tmax: &[f32; N],
    on: Mask<N>,
    blocked: &mut Mask<N>,
) {
    let mut t = [0.0; N];
    let hit = triangle_hits(packet, j, r, tmax, &mut t);
    for i in 0..N {
        blocked[i] |= hit[i] & on[i];
    }
}

/// Tests the rays of `on` against leaf `leaf`'s primitives for their closest hits.
#[inline(always)]
fn leaf_closest<const N: usize>(bvh: &Bvh, leaf: u32, r: &Rays<N>, h: &mut Hits<N>, on: Mask<N>) {
    let first = (leaf & FIRST_MASK) as usize;
    let count = ((leaf >> COUNT_SHIFT) & COUNT_MASK) as usize + 1;
    if leaf & ELLIPSOIDS == 0 {
        for packet in &bvh.triangles[first..first + count] {
            triangles_closest(packet, r, h, on);
        }
    } else {
        for e in &bvh.ellipsoids[first..first + count] {
            for i in (0..N).filter(|&i| on[i]) {
                let (o, d) = (lane_vec(&r.o, i), lane_vec(&r.d, i));
                let t = e.ellipsoid.intersect(o, d, r.tmin[i], h.tmax[i]);
                if t.is_finite() && closer(t, e.prim, h.tmax[i], h.prim[i]) {
                    h.tmax[i] = t;
                    h.prim[i] = e.prim;
                }
            }
        }
    }
}

/// Adds to `blocked` the rays of `on` that hit a primitive of leaf `leaf` in their
/// [tmin, `tmax`].
#[inline(always)]
fn leaf_any<const N: usize>(
    bvh: &Bvh,
    leaf: u32,
    r: &Rays<N>,
    tmax: &[f32; N],
    on: Mask<N>,
    blocked: &mut Mask<N>,
) {
    let first = (leaf & FIRST_MASK) as usize;
    let count = ((leaf >> COUNT_SHIFT) & COUNT_MASK) as usize + 1;
    if leaf & ELLIPSOIDS == 0 {
        for packet in &bvh.triangles[first..first + count] {
            triangles_any(packet, r, tmax, on, blocked);
        }
    } else {
        for e in &bvh.ellipsoids[first..first + count] {
            for i in 0..N {
                if !on[i] || blocked[i] {
                    continue;
                }
                let (o, d) = (lane_vec(&r.o, i), lane_vec(&r.d, i));
                if e.ellipsoid.intersect(o, d, r.tmin[i], tmax[i]).is_finite() {
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

/// The near-to-far walk of the rays of `on` (`r`) through `bvh` for their closest hits,
/// which shrink their `tmax` in `h`: its boxes tested with `boxes` (the rays in the
/// hierarchy's frame), its leaves' primitives with `r`, placed by `placed` = (world from
/// object, primitive index base) where it is given. (The leaf test is chosen by a value, not
/// passed as a closure: with a closure, the compiler unrolled `any_walk`'s leaf loop eightfold
/// and das's shadow rays ran 5 % slower.)
#[inline(always)]
fn closest_walk<const N: usize>(
    bvh: &Bvh,
    (boxes, planes, r): (&Rays<N>, &Planes, &Rays<N>),
    placed: Option<(&Affine3A, u32)>,
    h: &mut Hits<N>,
    on: Mask<N>,
    stack: &mut PacketStack,
) {
    stack.clear();
    let mut entry = [0.0; PACKET];
    entry[..N].copy_from_slice(&boxes.tmin);
    let mut mask = [false; PACKET];
    mask[..N].copy_from_slice(&on);
    stack.nodes.push(0);
    stack.masks.push(mask);
    stack.entries.push(entry);
    // A node's entered children, sort keys, lanes and entries: filled afresh at every node
    // before they are read, and set up once per walk (zeroing them at every node was 640
    // bytes of stores).
    let mut keys = [u64::MAX; WIDTH];
    let mut masks = [[false; PACKET]; WIDTH];
    let mut entries = [[0.0f32; PACKET]; WIDTH];
    while let Some(current) = stack.nodes.pop() {
        let mask: Mask<N> = part(&stack.masks.pop().unwrap_or([false; PACKET]), 0);
        let entry: [f32; N] = part(&stack.entries.pop().unwrap_or([0.0; PACKET]), 0);
        // Lanes whose closest hit so far is nearer than the subtree are done with it.
        let on: Mask<N> =
            std::array::from_fn(|i| mask[i] & (entry[i] <= h.tmax[i] * EXIT_ROUND_UP));
        if !any_set(&on) {
            continue;
        }
        if current & LEAF != 0 {
            match placed {
                None => leaf_closest(bvh, current, r, h, on),
                Some((world_from_object, base)) => {
                    let (first, count) = packets_of(current);
                    for packet in &bvh.triangles[first..first + count] {
                        triangles_closest(&packet.placed(world_from_object, base), r, h, on);
                    }
                }
            }
            continue;
        }
        let node = &bvh.nodes[current as usize];
        // The children any lane enters, sorted far to near by their nearest lane's entry.
        let mut n = 0;
        for c in 0..WIDTH {
            if node.children[c] == EMPTY {
                break;
            }
            let mut e = [0.0; N];
            let m = child_hits(node, c, planes, boxes, (&h.tmax, &on), &mut e);
            if !any_set(&m) {
                continue;
            }
            keys[n] = (u64::from(nearest_entry(&m, &e)) << 32) | c as u64;
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

/// The bits of the nearest entry of the lanes of `m` (entries are at least tmin ≥ 0, and
/// non-negative floats order as their bits), `u32::MAX` where no lane is set.
#[inline(always)]
pub(crate) fn nearest_entry<const N: usize>(m: &Mask<N>, e: &[f32; N]) -> u32 {
    // The lanes' keys first, all ones where a lane is off, then their minimum: a vector
    // select and reduction. As one fold with a branch per lane, it compiled to sixteen
    // scalar tests and extractions for every child a packet enters.
    let keys: [u32; N] =
        std::array::from_fn(|i| (e[i].to_bits() & 0x7fff_ffff) | u32::from(!m[i]).wrapping_neg());
    keys.iter().fold(u32::MAX, |a, &k| a.min(k))
}

/// Which rays of `on` (`r`) are blocked in `bvh` within each lane's [tmin, `tmax`], boxes and
/// leaves tested as in [`closest_walk`].
#[inline(always)]
fn any_walk<const N: usize>(
    bvh: &Bvh,
    (boxes, planes, r): (&Rays<N>, &Planes, &Rays<N>),
    placed: Option<(&Affine3A, u32)>,
    tmax: &[f32; N],
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
            match placed {
                None => leaf_any(bvh, current, r, tmax, m, &mut blocked),
                Some((world_from_object, base)) => {
                    let (first, count) = packets_of(current);
                    for packet in &bvh.triangles[first..first + count] {
                        let placed = packet.placed(world_from_object, base);
                        triangles_any(&placed, r, tmax, m, &mut blocked);
                    }
                }
            }
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
            let cm = child_hits(node, c, planes, boxes, (tmax, &m), &mut scratch);
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

/// [`closest_walk`] once per octant among the rays of `on` ([`next_octant`]).
#[inline(always)]
fn closest_walk_of<const N: usize>(
    bvh: &Bvh,
    (boxes, r): (&Rays<N>, &Rays<N>),
    placed: Option<(&Affine3A, u32)>,
    h: &mut Hits<N>,
    on: Mask<N>,
    stack: &mut PacketStack,
) {
    let octant = octants(boxes);
    let mut rest = on;
    while let Some((group, planes)) = next_octant(&octant, &mut rest) {
        closest_walk(bvh, (boxes, &planes, r), placed, h, group, stack);
    }
}

/// [`any_walk`] once per octant among the rays of `on` ([`next_octant`]).
#[inline(always)]
fn any_walk_of<const N: usize>(
    bvh: &Bvh,
    (boxes, r): (&Rays<N>, &Rays<N>),
    placed: Option<(&Affine3A, u32)>,
    tmax: &[f32; N],
    on: Mask<N>,
    stack: &mut PacketStack,
) -> Mask<N> {
    let mut blocked = [false; N];
    let octant = octants(boxes);
    let mut rest = on;
    while let Some((group, planes)) = next_octant(&octant, &mut rest) {
        let hit = any_walk(bvh, (boxes, &planes, r), placed, tmax, group, stack);
        blocked = std::array::from_fn(|i| blocked[i] | hit[i]);
    }
    blocked
}

/// The closest hits of the rays of `on` (`r`, world frame) among the triangles of `bvh`, a
/// hierarchy built in an object frame and placed by `world_from_object` under primitive
/// indices `base` + its own: [`crate::render::bvh::Bvh::closest_placed`] per lane. Its boxes
/// are tested with the rays moved by `object_from_world`, its triangles placed and tested
/// with `r`.
#[inline(always)]
pub(crate) fn closest_placed<const N: usize>(
    bvh: &Bvh,
    (world_from_object, object_from_world, base): (&Affine3A, &Affine3A, u32),
    r: &Rays<N>,
    h: &mut Hits<N>,
    on: Mask<N>,
    stack: &mut PacketStack,
) {
    if bvh.nodes.is_empty() {
        return;
    }
    let object = r.transformed(object_from_world);
    let placed = Some((world_from_object, base));
    closest_walk_of(bvh, (&object, r), placed, h, on, stack);
}

/// Which rays of `on` a triangle of `bvh` placed as in [`closest_placed`] blocks in their
/// [tmin, `tmax`].
#[inline(always)]
pub(crate) fn any_placed<const N: usize>(
    bvh: &Bvh,
    (world_from_object, object_from_world, base): (&Affine3A, &Affine3A, u32),
    r: &Rays<N>,
    tmax: &[f32; N],
    on: Mask<N>,
    stack: &mut PacketStack,
) -> Mask<N> {
    if bvh.nodes.is_empty() {
        return [false; N];
    }
    let object = r.transformed(object_from_world);
    any_walk_of(
        bvh,
        (&object, r),
        Some((world_from_object, base)),
        tmax,
        on,
        stack,
    )
}

/// The closest hits of `packet`'s active rays in `bvh`, `N` lanes at a time: shrinks each
/// lane's `tmax` and sets its `prim` where `bvh` holds a [`closer`] hit.
#[inline(always)]
pub(crate) fn closest<const N: usize>(bvh: &Bvh, packet: &mut RayPacket, stack: &mut PacketStack) {
    if bvh.nodes.is_empty() {
        return;
    }
    for base in (0..PACKET).step_by(N) {
        let mask = packet.lanes_from::<N>(base);
        if mask != 0 {
            let r = Rays::<N>::load(packet, base);
            let mut h = Hits::<N>::load(packet, base);
            closest_walk_of(bvh, (&r, &r), None, &mut h, lanes_of(mask), stack);
            h.store(packet, base);
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
        let mask = packet.lanes_from::<N>(base);
        if mask != 0 {
            let r = Rays::<N>::load(packet, base);
            let tmax: &[f32; N] = packet.tmax[base..base + N].try_into().expect("N lanes");
            let hit = any_walk_of(bvh, (&r, &r), None, tmax, lanes_of(mask), stack);
            blocked |= bits_of(hit) << base;
        }
    }
    blocked
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A child's test with its octant's near and far planes against [`box_hits`]' min and
    /// max, lane by lane: the same lanes enter, at the same entry (as values: a zero's sign
    /// may differ), for drawn boxes (some flat, some behind the rays or beside them) and rays
    /// of every octant, axis-parallel ones among them, each lane tested in its own octant.
    #[test]
    fn a_child_tested_with_its_octants_planes_answers_as_with_min_and_max() {
        let mut draws = crate::render::bvh::drawn::Draws::new(0x2545_f491_4f6c_dd1d);
        let mut entered = 0;
        for case in 0..400 {
            let node = draws.node(WIDTH, case % 7 == 0);
            let mut packet = RayPacket::new();
            for lane in 0..PACKET {
                packet.set(lane, &draws.ray(lane));
            }
            let r = Rays::<PACKET>::load(&packet, 0);
            let octant = octants(&r);
            for c in 0..WIDTH {
                let (mut want_entry, mut entry) = ([0.0; PACKET], [0.0; PACKET]);
                let want = box_hits(
                    [0, 2, 4].map(|row| node.bounds[row][c]),
                    [1, 3, 5].map(|row| node.bounds[row][c]),
                    &r,
                    &packet.tmax,
                    &mut want_entry,
                );
                for lane in 0..PACKET {
                    let planes = Planes::of(octant[lane]);
                    let got = child_hits(
                        &node,
                        c,
                        &planes,
                        &r,
                        (&packet.tmax, &[true; PACKET]),
                        &mut entry,
                    );
                    assert_eq!(got[lane], want[lane], "case {case}, child {c}, lane {lane}");
                    assert_eq!(
                        entry[lane], want_entry[lane],
                        "case {case}, child {c}, lane {lane}"
                    );
                    entered += usize::from(got[lane]);
                }
            }
        }
        // Enough lanes enter, and enough miss, for the test to tell.
        assert!(
            (5_000..40_000).contains(&entered),
            "{entered} of 51 200 entered"
        );
    }

    /// The octant groups of a mask partition its lanes, each group one octant, in order of
    /// their first lanes; a mask of no lanes has none.
    #[test]
    fn octant_groups_partition_the_lanes_by_octant() {
        let octant: [u32; PACKET] = std::array::from_fn(|i| [3, 3, 5, 0, 3, 7, 5, 0][i % 8]);
        for mask in [0u32, 1, 0x00ff, 0xffff, 0x8001, 0x5a5a, 0x0ff0] {
            let mut rest: Mask<PACKET> = lanes_of(mask);
            let mut seen = 0u32;
            let mut last_first = None;
            while let Some((group, planes)) = next_octant(&octant, &mut rest) {
                let bits = bits_of(group);
                assert_ne!(bits, 0);
                assert_eq!(bits & seen, 0, "groups overlap");
                let first = bits.trailing_zeros() as usize;
                assert!(last_first < Some(first), "groups out of order");
                last_first = Some(first);
                let k = octant[first];
                let want = (0..PACKET).filter(|&i| mask >> i & 1 != 0 && octant[i] == k);
                assert_eq!(bits, want.fold(0, |m, i| m | 1 << i));
                assert_eq!(planes, Planes::of(k));
                seen |= bits;
            }
            assert_eq!(seen, mask);
        }
        // The planes: toward + the min row is near, toward − the max row.
        assert_eq!(
            Planes::of(0),
            Planes {
                near: [0, 2, 4],
                far: [1, 3, 5]
            }
        );
        assert_eq!(
            Planes::of(0b101),
            Planes {
                near: [1, 2, 5],
                far: [0, 3, 4]
            }
        );
    }

    /// The nearest entry against its definition, lane by lane: the smallest entry among the
    /// lanes set (as a float; -0.0 as 0.0), `u32::MAX` where none is, for every mask of a
    /// few hundred drawn ones, entries of every order of magnitude, and ties.
    #[test]
    fn the_nearest_entry_is_the_smallest_among_the_lanes_set() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut draw = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            (state >> 33) as u32
        };
        for case in 0..500 {
            let mask = if case == 0 { 0 } else { draw() & 0xffff };
            let m: Mask<PACKET> = lanes_of(mask);
            let e: [f32; PACKET] = std::array::from_fn(|_| match draw() % 8 {
                0 => 0.0,
                1 => -0.0,
                2 => 3.5, // ties across lanes
                _ => (draw() % 1_000_000) as f32 * 10f32.powi((draw() % 9) as i32 - 4),
            });
            let want = (0..PACKET)
                .filter(|&i| m[i])
                .map(|i| e[i].abs())
                .fold(None, |a: Option<f32>, x| Some(a.map_or(x, |a| a.min(x))))
                .map_or(u32::MAX, f32::to_bits);
            assert_eq!(
                nearest_entry(&m, &e),
                want,
                "mask {mask:#06x}, entries {e:?}"
            );
        }
    }
}
