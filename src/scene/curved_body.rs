//! The triangles of an obstacle with a curved display: the display surface itself (part
//! `box_face::POS_Z`, the display's part for every obstacle) and a body behind it, the
//! surface moved `thickness` metres along the obstacle's −z and closed along its rim.

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use crate::scene::display_surface::CurvedSurface;
use crate::scene::shapes::{Tri, box_face};

/// An edge by its corners' bits, lower first.
type EdgeKey = ([u32; 3], [u32; 3]);

/// Obstacle-frame triangles of the display (part `POS_Z`) and its body (`NEG_Z` behind,
/// `POS_X` round the rim).
pub fn curved_obstacle_tris(surface: &CurvedSurface, thickness: f64) -> Vec<Tri> {
    let back = Vec3::new(0.0, 0.0, -thickness as f32);
    let tri = |p: [Vec3; 3], part: u32| Tri {
        p,
        uv: [Vec2::ZERO; 3],
        part,
        file_material: None,
    };
    let mut out = Vec::with_capacity(4 * surface.tris.len());
    // Edges used by one triangle only are the rim (corners compared bit for bit).
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let mut edges: HashMap<EdgeKey, (usize, Vec3, Vec3)> = HashMap::new();
    let mut order = Vec::new();
    for t in &surface.tris {
        let p = t.p.map(|p| p.as_vec3());
        out.push(tri(p, box_face::POS_Z));
        out.push(tri(
            [p[0] + back, p[2] + back, p[1] + back],
            box_face::NEG_Z,
        ));
        for (a, b) in [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])] {
            let k = if key(a) < key(b) {
                (key(a), key(b))
            } else {
                (key(b), key(a))
            };
            let entry = edges.entry(k).or_insert_with(|| {
                order.push(k);
                (0, a, b)
            });
            entry.0 += 1;
        }
    }
    for k in order {
        let (count, a, b) = edges[&k];
        if count == 1 {
            out.push(tri([a, b + back, b], box_face::POS_X));
            out.push(tri([a, a + back, b + back], box_face::POS_X));
        }
    }
    out
}
