//! Leaf packets of the wide BVH: four triangles tested against one ray in SIMD lanes, and
//! single ellipsoids.
//!
//! The triangle test is obvhs' `RtTriangle::intersect` (Möller–Trumbore in the layout of
//! madmann91's bvh), computed lane by lane with the same operations in the same order, so that
//! it returns the same distance bit for bit: the brute-force twin in `tests/accel.rs` checks it.
//!
//! Which hit is the closest does not depend on the order the primitives are tested in
//! ([`closer`]): the per-ray and the packet traversals (`render/bvh_packet.rs`) visit
//! them in different orders and give the same primitive.

use glam::{Affine3A, Vec4};
use obvhs::rt_triangle::RtTriangle;

use crate::scene::instances::{normal, placed};

use crate::render::ray::TraceRay;

/// No primitive found (yet): the closest-hit queries keep the primitive of the closest hit
/// so far, this where there is none.
pub const NO_PRIM: u32 = u32::MAX;
use crate::scene::world::Ellipsoid;

/// Whether a hit of primitive `prim` at distance `t` (in the ray's [tmin, tmax]) replaces the
/// closest so far, `best` at `tmax` ([`NO_PRIM`]: none yet, `tmax` the ray's own): nearer,
/// or as near and of a lower index. So the answer is the brute force's — the first primitive
/// in world order among the nearest — whatever order the traversal tests them in; at a
/// shared edge hit by a ray, both triangles can give the same distance.
#[inline(always)]
pub fn closer(t: f32, prim: u32, tmax: f32, best: u32) -> bool {
    (t < tmax) | ((t == tmax) & (best != NO_PRIM) & (prim < best))
}

/// Triangles per packet.
pub const TRI_LANES: usize = 4;

/// Four triangles, structure of arrays: per axis and lane the base vertex and the two edges
/// of [`RtTriangle`] (its normal is computed where needed: [`normal`], which keeps a packet
/// at 160 bytes, not 208, for 0–4 % of the rays' speed); and each lane's
/// primitive index.
#[derive(Clone, Copy, Debug)]
pub struct Triangles4 {
    pub(crate) v0: [Vec4; 3],
    pub(crate) e1: [Vec4; 3],
    pub(crate) e2: [Vec4; 3],
    /// Primitive index of each lane; unused lanes repeat lane 0's.
    pub(crate) prim: [u32; TRI_LANES],
}

impl Triangles4 {
    /// Packs 1 to 4 triangles; unused lanes repeat the first one (a repeated hit never wins).
    pub fn new(triangles: &[RtTriangle], prims: &[u32]) -> Triangles4 {
        assert!(!prims.is_empty() && prims.len() <= TRI_LANES);
        let mut packet = Triangles4 {
            v0: [Vec4::ZERO; 3],
            e1: [Vec4::ZERO; 3],
            e2: [Vec4::ZERO; 3],
            prim: [0; TRI_LANES],
        };
        for lane in 0..TRI_LANES {
            let prim = prims[if lane < prims.len() { lane } else { 0 }];
            let t = &triangles[prim as usize];
            for axis in 0..3 {
                packet.v0[axis][lane] = t.v0[axis];
                packet.e1[axis][lane] = t.e1[axis];
                packet.e2[axis][lane] = t.e2[axis];
            }
            packet.prim[lane] = prim;
        }
        packet
    }

    /// Each lane's hit distance, and which lanes hit in [tmin, tmax] (bit i for lane i).
    #[inline(always)]
    fn hits(&self, ray: &TraceRay) -> (Vec4, u32) {
        let [ox, oy, oz] = [ray.origin.x, ray.origin.y, ray.origin.z].map(Vec4::splat);
        let [dx, dy, dz] = [ray.dir.x, ray.dir.y, ray.dir.z].map(Vec4::splat);
        let [v0x, v0y, v0z] = self.v0;
        let [e1x, e1y, e1z] = self.e1;
        let [e2x, e2y, e2z] = self.e2;
        let [ngx, ngy, ngz] = normal(self.e1, self.e2);
        let (cx, cy, cz) = (v0x - ox, v0y - oy, v0z - oz);
        // r = d × c
        let rx = dy * cz - dz * cy;
        let ry = dz * cx - dx * cz;
        let rz = dx * cy - dy * cx;
        let inv_det = Vec4::ONE / (ngx * dx + ngy * dy + ngz * dz);
        let u = (rx * e2x + ry * e2y + rz * e2z) * inv_det;
        let v = (rx * e1x + ry * e1y + rz * e1z) * inv_det;
        let w = Vec4::ONE - u - v;
        let t = (ngx * cx + ngy * cy + ngz * cz) * inv_det;
        // As obvhs: a -0.0 barycentric is a miss, like a negative one.
        let outside = u.is_negative_bitmask() | v.is_negative_bitmask() | w.is_negative_bitmask();
        let valid = (inv_det.cmpne(Vec4::ZERO)
            & t.cmpge(Vec4::splat(ray.tmin))
            & t.cmple(Vec4::splat(ray.tmax)))
        .bitmask()
            & !outside;
        (t, valid)
    }
}

impl Triangles4 {
    /// The four triangles placed by `m` ([`placed`]: as the flattened world's), under
    /// primitive indices `base` + their own.
    #[inline(always)]
    pub fn placed(&self, m: &Affine3A, base: u32) -> Triangles4 {
        let [v0, e1, e2, _] = placed(m, self.v0, self.e1, self.e2);
        Triangles4 {
            v0,
            e1,
            e2,
            prim: self.prim.map(|p| base + p),
        }
    }

    /// Where a lane's triangle is hit [`closer`] than `best` at `ray.tmax`, shrinks
    /// `ray.tmax` to that hit and sets `best` to its primitive index.
    #[inline(always)]
    pub fn closest(&self, ray: &mut TraceRay, best: &mut u32) {
        let (t, mut valid) = self.hits(ray);
        while valid != 0 {
            let lane = valid.trailing_zeros() as usize;
            valid &= valid - 1;
            if closer(t[lane], self.prim[lane], ray.tmax, *best) {
                ray.tmax = t[lane];
                *best = self.prim[lane];
            }
        }
    }

    /// Whether any lane's triangle is hit in [tmin, tmax].
    #[inline(always)]
    pub fn any(&self, ray: &TraceRay) -> bool {
        self.hits(ray).1 != 0
    }
}

/// One ellipsoid and its primitive index.
#[derive(Clone, Copy, Debug)]
pub struct EllipsoidLeaf {
    pub ellipsoid: Ellipsoid,
    pub prim: u32,
}

impl EllipsoidLeaf {
    /// As [`Triangles4::closest`].
    #[inline]
    pub fn closest(&self, ray: &mut TraceRay, best: &mut u32) {
        let t = self
            .ellipsoid
            .intersect(ray.origin, ray.dir, ray.tmin, ray.tmax);
        // A miss is infinite: never closer than a finite tmax, and refused at an infinite one
        // (`closer` takes a tie only where a hit was found).
        if t.is_finite() && closer(t, self.prim, ray.tmax, *best) {
            ray.tmax = t;
            *best = self.prim;
        }
    }

    #[inline]
    pub fn any(&self, ray: &TraceRay) -> bool {
        self.ellipsoid
            .intersect(ray.origin, ray.dir, ray.tmin, ray.tmax)
            .is_finite()
    }
}
