//! A ray prepared for BVH traversal.

use glam::Vec3A;
use obvhs::ray::Ray;

/// A ray prepared for traversal, with its reciprocal direction.
#[derive(Clone, Copy, Debug)]
pub struct TraceRay {
    /// Origin, world frame, metres.
    pub origin: Vec3A,
    /// Unit direction, world frame.
    pub dir: Vec3A,
    /// Reciprocal direction (components of magnitude below 1e-20 are replaced by ±1e-20).
    pub inv_dir: Vec3A,
    /// Distance interval searched, metres; `tmax` shrinks to the closest hit found.
    pub tmin: f32,
    pub tmax: f32,
}

impl TraceRay {
    pub fn new(origin: Vec3A, dir: Vec3A, tmin: f32, tmax: f32) -> TraceRay {
        // A zero component would give 0 · ∞ = NaN in the slab test; a tiny one gives the
        // same answer (the slab is entered everywhere or nowhere) without NaN.
        let tiny = dir.abs().cmplt(Vec3A::splat(1e-20));
        let inv_dir = Vec3A::ONE / Vec3A::select(tiny, Vec3A::splat(1e-20).copysign(dir), dir);
        TraceRay {
            origin,
            dir,
            inv_dir,
            tmin,
            tmax,
        }
    }

    /// The ray as obvhs' type, for the world's own (brute-force) intersection tests.
    pub fn as_obvhs(&self) -> Ray {
        Ray::new(self.origin, self.dir, self.tmin, self.tmax)
    }
}

/// One component of [`TraceRay::inv_dir`] from that of the direction: [`TraceRay::new`]'s
/// rule for one lane of a packet filled axis by axis.
#[inline(always)]
pub fn reciprocal(d: f32) -> f32 {
    1.0 / if d.abs() < 1e-20 {
        1e-20f32.copysign(d)
    } else {
        d
    }
}

/// A closest-hit answer: which primitive of the world, at which distance (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub prim: usize,
    pub t: f32,
}
