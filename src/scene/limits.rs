//! The limits of what seethru accepts, in one place (docs/reference/limits-and-errors.md lists them).
//!
//! The renderer traces in f32 and its BVH builder (obvhs) sorts primitives by Morton codes of
//! their bounding boxes: a coordinate of 1e30 m, a NaN or an infinity makes it index out of
//! range. So every coordinate of the world, after every transform, stays within
//! ±[`MAX_COORDINATE`]; every size, radius and scale factor within
//! [[`MIN_LENGTH`], [`MAX_LENGTH`]]; and inputs that would need unbounded time or memory
//! (objects, triangles, file sizes) are refused up front with the limit in the message.

use anyhow::{Result, bail};
use glam::{DAffine3, DVec3, Vec3};

use crate::scene::shapes::Tri;
use crate::util::number::short;

/// Largest absolute world coordinate, metres, of any vertex, sphere bound, camera or point.
/// f32 spacing there is 6 cm; at 1 km it is 0.06 mm.
pub const MAX_COORDINATE: f64 = 1e6;
/// Largest size, radius, height or scale factor, metres (or a pure factor).
pub const MAX_LENGTH: f64 = 1e5;
/// Smallest size, radius, height or scale factor: below it, f32 geometry degenerates.
pub const MIN_LENGTH: f64 = 1e-6;
/// Largest side of the obstacle (its display), metres.
pub const MAX_DISPLAY_SIZE: f64 = 100.0;
/// Largest rotation angle in a scene file, degrees (either sign).
pub const MAX_ROTATION_DEG: f64 = 360.0;
/// Largest distance of a camera mounted on the obstacle from the display centre, metres.
pub const MAX_MOUNT_OFFSET: f64 = 100.0;
/// Largest texture repetition factor.
pub const MAX_UV_REPEAT: f64 = 1e6;
/// The smallest GGX roughness α of a material's glossy lobe: below it a highlight of a point
/// lamp shrinks under a pixel and flickers from sample to sample.
pub const MIN_ROUGHNESS: f64 = 0.01;
/// A material's GGX roughness α by default: a satin clear coat, a damp road.
pub const DEFAULT_ROUGHNESS: f64 = 0.2;
/// Largest image side accepted anywhere (renders, textures, EXRs), pixels.
pub const MAX_RESOLUTION: u32 = 16384;
/// Largest image accepted anywhere, pixels (16k × 8k).
pub const MAX_PIXELS: u64 = 16384 * 8192;
/// Most `[[object]]` tables in one scene.
pub const MAX_OBJECTS: usize = 100_000;
/// Most `[[material]]` tables in one scene (mesh files add theirs on top, within the triangle
/// budget).
pub const MAX_MATERIALS: usize = 100_000;
/// Most triangles in one world: scene shapes, meshes and the obstacle together (about 5 GB
/// with the BVH; das grown 1000× for the scaling benchmark has 13 million).
pub const MAX_TRIANGLES: usize = 20_000_000;
/// Largest scene file, bytes.
pub const MAX_SCENE_BYTES: u64 = 64 << 20;
/// Largest mesh file (OBJ, MTL, glTF, GLB, .bin), bytes.
pub const MAX_MESH_BYTES: u64 = 1 << 30;

/// The first coordinate of `p` outside ±[`MAX_COORDINATE`] (or not finite), as text.
pub fn out_of_world(p: DVec3) -> Option<String> {
    let bad = p
        .to_array()
        .into_iter()
        .zip(["x", "y", "z"])
        .find(|(v, _)| !v.is_finite() || v.abs() > MAX_COORDINATE)?;
    Some(format!(
        "{} = {} m is outside the world, [{}, {}] m",
        bad.1,
        short(bad.0),
        short(-MAX_COORDINATE),
        short(MAX_COORDINATE)
    ))
}

/// Checks a mesh placed in the world: every vertex inside the world after `world_from_object`,
/// and the world's triangle budget (`triangles_before` are already in it). Errors name the
/// mesh file and the object.
pub fn check_placed_mesh(
    path: &std::path::Path,
    object: &str,
    tris: &[Tri],
    world_from_object: &DAffine3,
    triangles_before: usize,
) -> Result<()> {
    let total = triangles_before.saturating_add(tris.len());
    if total > MAX_TRIANGLES {
        bail!(
            "object `{object}`: mesh {} brings the world to {total} triangles, more than the limit of {MAX_TRIANGLES}",
            path.display()
        );
    }
    for (i, tri) in tris.iter().enumerate() {
        for p in tri.p {
            let world = world_from_object.transform_point3(p.as_dvec3());
            if let Some(why) = out_of_world(world) {
                bail!(
                    "object `{object}`: triangle {i} of mesh {} is placed outside the world: {why}",
                    path.display()
                );
            }
        }
    }
    Ok(())
}

/// The first vertex of `tris` that is not finite or not within ±[`MAX_COORDINATE`], if any.
pub fn first_bad_vertex<'a>(tris: impl IntoIterator<Item = &'a Tri>) -> Option<(usize, Vec3)> {
    tris.into_iter().enumerate().find_map(|(i, t)| {
        t.p.iter()
            .find(|p| out_of_world(p.as_dvec3()).is_some())
            .map(|&p| (i, p))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_world_is_closed_and_excludes_non_finite_points() {
        assert!(out_of_world(DVec3::splat(MAX_COORDINATE)).is_none());
        assert!(out_of_world(DVec3::new(0.0, -MAX_COORDINATE, 0.0)).is_none());
        let why = out_of_world(DVec3::new(0.0, 0.0, -1.5e6)).unwrap();
        assert_eq!(
            why,
            "z = -1500000 m is outside the world, [-1000000, 1000000] m"
        );
        assert!(out_of_world(DVec3::new(f64::NAN, 0.0, 0.0)).is_some());
        assert!(out_of_world(DVec3::new(0.0, f64::INFINITY, 0.0)).is_some());
    }
}
