//! Tessellation of the analytic object kinds into triangles, in object space.
//!
//! UVs follow the glTF convention: u to the right, v down, (0, 0) the image's top-left texel.
//! Every triangle carries a part id so that measurements can tell faces apart.

use glam::{Vec2, Vec3};

/// A triangle in some frame, with texture coordinates and the ids that travel into AOVs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tri {
    pub p: [Vec3; 3],
    pub uv: [Vec2; 3],
    /// Part of the object: a box face, a cylinder cap, a mesh group.
    pub part: u32,
    /// Material of the mesh file this triangle came from, if any (index into that file's list).
    pub file_material: Option<u32>,
}

/// Part ids of a box, one per face.
pub mod box_face {
    pub const POS_X: u32 = 0;
    pub const NEG_X: u32 = 1;
    pub const POS_Y: u32 = 2;
    pub const NEG_Y: u32 = 3;
    pub const POS_Z: u32 = 4;
    pub const NEG_Z: u32 = 5;
}

fn quad(out: &mut Vec<Tri>, corners: [Vec3; 4], uvs: [Vec2; 4], part: u32) {
    // Corners go counter-clockwise seen from the front.
    let [a, b, c, d] = corners;
    let [ua, ub, uc, ud] = uvs;
    out.push(Tri {
        p: [a, b, c],
        uv: [ua, ub, uc],
        part,
        file_material: None,
    });
    out.push(Tri {
        p: [a, c, d],
        uv: [ua, uc, ud],
        part,
        file_material: None,
    });
}

const FULL_UV: [Vec2; 4] = [
    Vec2::new(0.0, 1.0),
    Vec2::new(1.0, 1.0),
    Vec2::new(1.0, 0.0),
    Vec2::new(0.0, 0.0),
];

/// Rectangle in the xy plane facing +z, centred at the origin.
pub fn quad_xy(size: [f32; 2], part: u32) -> Vec<Tri> {
    let (x, y) = (size[0] / 2.0, size[1] / 2.0);
    let mut out = Vec::new();
    quad(
        &mut out,
        [
            Vec3::new(-x, -y, 0.0),
            Vec3::new(x, -y, 0.0),
            Vec3::new(x, y, 0.0),
            Vec3::new(-x, y, 0.0),
        ],
        FULL_UV,
        part,
    );
    out
}

/// Rectangle in the xz plane facing +y, centred at the origin; v runs along −z (away from a
/// viewer looking down −z), so a texture reads upright on a street ahead.
pub fn plane_xz(size: [f32; 2]) -> Vec<Tri> {
    let (x, z) = (size[0] / 2.0, size[1] / 2.0);
    let mut out = Vec::new();
    quad(
        &mut out,
        [
            Vec3::new(-x, 0.0, z),
            Vec3::new(x, 0.0, z),
            Vec3::new(x, 0.0, -z),
            Vec3::new(-x, 0.0, -z),
        ],
        FULL_UV,
        0,
    );
    out
}

/// Axis-aligned box centred at the origin; part ids from [`box_face`].
pub fn cuboid(size: [f32; 3]) -> Vec<Tri> {
    let h = Vec3::from_array(size) / 2.0;
    let mut out = Vec::new();
    // Each face: normal axis and the two in-plane axes (right, up) seen from outside.
    let faces = [
        (Vec3::X, -Vec3::Z, Vec3::Y, box_face::POS_X),
        (-Vec3::X, Vec3::Z, Vec3::Y, box_face::NEG_X),
        (Vec3::Y, Vec3::X, -Vec3::Z, box_face::POS_Y),
        (-Vec3::Y, Vec3::X, Vec3::Z, box_face::NEG_Y),
        (Vec3::Z, Vec3::X, Vec3::Y, box_face::POS_Z),
        (-Vec3::Z, -Vec3::X, Vec3::Y, box_face::NEG_Z),
    ];
    for &(n, r, u, part) in &faces {
        let (n, r, u) = (n * h, r * h, u * h);
        quad(
            &mut out,
            [n - r - u, n + r - u, n + r + u, n - r + u],
            FULL_UV,
            part,
        );
    }
    out
}

/// Part ids of cylinders and cones.
pub mod round_part {
    pub const SIDE: u32 = 0;
    pub const TOP: u32 = 1;
    pub const BOTTOM: u32 = 2;
}

/// Cylinder (`top_radius == radius`) or cone (`top_radius == 0`) along +y from y = 0 to `height`.
pub fn frustum(radius: f32, top_radius: f32, height: f32, segments: usize) -> Vec<Tri> {
    let mut out = Vec::new();
    let ring = |i: usize, r: f32, y: f32| {
        let a = std::f32::consts::TAU * (i % segments) as f32 / segments as f32;
        Vec3::new(r * a.cos(), y, -r * a.sin())
    };
    let top = Vec3::new(0.0, height, 0.0);
    for i in 0..segments {
        let (u0, u1) = (i as f32 / segments as f32, (i + 1) as f32 / segments as f32);
        let (b0, b1) = (ring(i, radius, 0.0), ring(i + 1, radius, 0.0));
        if top_radius > 0.0 {
            let (t0, t1) = (ring(i, top_radius, height), ring(i + 1, top_radius, height));
            quad(
                &mut out,
                [b0, b1, t1, t0],
                [
                    Vec2::new(u0, 1.0),
                    Vec2::new(u1, 1.0),
                    Vec2::new(u1, 0.0),
                    Vec2::new(u0, 0.0),
                ],
                round_part::SIDE,
            );
            out.push(Tri {
                p: [top, t0, t1],
                uv: [Vec2::splat(0.5); 3],
                part: round_part::TOP,
                file_material: None,
            });
        } else {
            out.push(Tri {
                p: [b0, b1, top],
                uv: [
                    Vec2::new(u0, 1.0),
                    Vec2::new(u1, 1.0),
                    Vec2::new((u0 + u1) / 2.0, 0.0),
                ],
                part: round_part::SIDE,
                file_material: None,
            });
        }
        let base_part = if top_radius > 0.0 {
            round_part::BOTTOM
        } else {
            round_part::TOP
        };
        out.push(Tri {
            p: [Vec3::ZERO, b1, b0],
            uv: [Vec2::splat(0.5); 3],
            part: base_part,
            file_material: None,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(tris: &[Tri]) -> f32 {
        tris.iter()
            .map(|t| (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length() / 2.0)
            .sum()
    }

    /// Outward-facing winding: the normal of every face points away from the centroid.
    fn outward(tris: &[Tri], centre: Vec3) -> bool {
        tris.iter().all(|t| {
            let n = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
            let c = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
            n.dot(c - centre) > 0.0
        })
    }

    #[test]
    fn box_has_the_analytic_area_and_faces_outward() {
        let tris = cuboid([1.0, 2.0, 3.0]);
        assert_eq!(tris.len(), 12);
        assert!((area(&tris) - 2.0 * (2.0 + 3.0 + 6.0)).abs() < 1e-5);
        assert!(outward(&tris, Vec3::ZERO));
        for part in 0..6 {
            assert_eq!(tris.iter().filter(|t| t.part == part).count(), 2);
        }
    }

    #[test]
    fn cylinder_area_converges_to_the_analytic_value() {
        let (r, h) = (0.5f32, 2.0f32);
        let n = 512;
        let tris = frustum(r, r, h, n);
        let exact = std::f32::consts::TAU * r * h + 2.0 * std::f32::consts::PI * r * r;
        assert!((area(&tris) - exact).abs() / exact < 1e-3);
        assert!(outward(&tris, Vec3::new(0.0, h / 2.0, 0.0)));
    }

    #[test]
    fn cone_faces_outward() {
        let tris = frustum(1.0, 0.0, 3.0, 32);
        assert!(outward(&tris, Vec3::new(0.0, 0.75, 0.0)));
    }

    #[test]
    fn quad_and_plane_face_their_axes() {
        let q = quad_xy([2.0, 1.0], 0);
        let n = (q[0].p[1] - q[0].p[0]).cross(q[0].p[2] - q[0].p[0]);
        assert!(n.normalize().abs_diff_eq(Vec3::Z, 1e-6));
        let p = plane_xz([2.0, 1.0]);
        let n = (p[0].p[1] - p[0].p[0]).cross(p[0].p[2] - p[0].p[0]);
        assert!(n.normalize().abs_diff_eq(Vec3::Y, 1e-6));
    }
}
