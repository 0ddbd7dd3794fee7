//! The grid lookup of a curved display's hit points (`CurvedSurface::uv_at_point`) against
//! its brute-force twin (a scan over every triangle): the same UV for many random rays' hits
//! on a cylinder and on a bumpy mesh, and for points off the surface.

use glam::{DVec2, DVec3};
use seethru::scene::display_surface::{CurvedSurface, UvTri};

/// A small deterministic generator (no entropy), uniform in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A height field of n×n quads over 0.3 m × 0.5 m with random bumps of up to 2 cm.
fn bumps(n: usize, rng: &mut Lcg) -> CurvedSurface {
    let h: Vec<f64> = (0..(n + 1) * (n + 1)).map(|_| 0.02 * rng.next()).collect();
    let at = |i: usize, j: usize| {
        let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
        (
            DVec3::new((u - 0.5) * 0.3, (0.5 - v) * 0.5, h[j * (n + 1) + i]),
            DVec2::new(u, v),
        )
    };
    let mut tris = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            for [x, y, z] in [[a, d, c], [a, c, b]] {
                tris.push(UvTri {
                    p: [x.0, y.0, z.0],
                    uv: [x.1, y.1, z.1],
                });
            }
        }
    }
    CurvedSurface::new("bumps".into(), tris).unwrap()
}

/// Nearest ray–triangle hit over every triangle (Möller–Trumbore).
fn hit(s: &CurvedSurface, o: DVec3, d: DVec3) -> Option<DVec3> {
    let mut best: Option<f64> = None;
    for t in &s.tris {
        let (e1, e2) = (t.p[1] - t.p[0], t.p[2] - t.p[0]);
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        if det.abs() < 1e-15 {
            continue;
        }
        let tv = o - t.p[0];
        let u = tv.dot(pv) / det;
        let qv = tv.cross(e1);
        let v = d.dot(qv) / det;
        let dist = e2.dot(qv) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 0.0 && best.is_none_or(|b| dist < b) {
            best = Some(dist);
        }
    }
    best.map(|t| o + d * t)
}

fn check(s: &CurvedSurface, rng: &mut Lcg, rays: usize) -> usize {
    let (lo, hi) = s.bounds();
    let mut hits = 0;
    for _ in 0..rays {
        let target = lo + (hi - lo) * DVec3::new(rng.next(), rng.next(), rng.next());
        let origin = DVec3::new(rng.next() - 0.5, rng.next() - 0.5, 1.0);
        let Some(p) = hit(s, origin, (target - origin).normalize()) else {
            continue;
        };
        hits += 1;
        // The renderer hands the point over in f32.
        let p = p.as_vec3().as_dvec3();
        // The grid answers every hit itself (no fallback to the scan), with the scan's UV.
        let brute = s.uv_at_point_brute(p);
        assert!(brute.is_some(), "a hit on the surface has a UV: {p}");
        assert_eq!(s.uv_at_point_by_grid(p), brute, "hit {p}");
        assert_eq!(s.uv_at_point(p), brute, "hit {p}");
        // Off the surface by up to 5 cm along z, and beyond the bounds.
        let off = p + DVec3::new(0.0, 0.0, 0.1 * (rng.next() - 0.5));
        assert_eq!(s.uv_at_point(off), s.uv_at_point_brute(off), "off {off}");
    }
    hits
}

#[test]
fn the_grid_finds_the_brute_forces_uv_on_a_cylinder() {
    let mut rng = Lcg(1);
    // The cabin's display, and a wide one of many facets.
    for (w, h, r, n) in [(0.1, 0.6, 0.07, 24), (0.5, 0.3, 0.2, 300)] {
        let s = CurvedSurface::cylinder(w, h, r, n).unwrap();
        let hits = check(&s, &mut rng, 4000);
        assert!(hits > 1000, "only {hits} rays hit the cylinder");
    }
}

#[test]
fn the_grid_finds_the_brute_forces_uv_on_a_bumpy_mesh() {
    let mut rng = Lcg(2);
    let s = bumps(40, &mut rng);
    assert_eq!(s.tris.len(), 3200);
    let hits = check(&s, &mut rng, 3000);
    assert!(hits > 1000, "only {hits} rays hit the mesh");
}
