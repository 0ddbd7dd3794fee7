//! The triangles a shape places from a file or a table built into the binary: a mesh file
//! (scene/mesh_io.rs), the built-in head, an OpenDRIVE map (scene/road_map.rs).

use anyhow::Result;

use crate::scene::Shape;
use crate::scene::mesh_io::{LoadedMesh, builtin_head, load_mesh};
use crate::scene::road_map::road_triangles;

/// The triangles `shape` places, in its object frame: a mesh file's ([`load_mesh`]), the
/// built-in head's ([`builtin_head`]) or a road map's ([`road_triangles`] of the map the scene read); `None` for the
/// analytic shapes.
pub fn shape_mesh(shape: &Shape) -> Option<Result<LoadedMesh>> {
    match shape {
        Shape::Mesh { path } => Some(load_mesh(path)),
        Shape::HeadMesh => Some(Ok(builtin_head().clone())),
        Shape::Road { map, look, .. } => Some(Ok(road_triangles(&map.network, look))),
        _ => None,
    }
}
