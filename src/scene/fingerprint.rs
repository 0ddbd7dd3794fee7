//! A scene's fingerprint: a hash of everything its renders depend on — the scene as read
//! (every key, defaults filled in), the triangles and materials of each mesh file it places
//! (with the MTL files and buffers those read) and the texels of each texture — but not the
//! paths they were read from, so that a scene and its assets moved elsewhere, or named from
//! another folder, keep their fingerprint. A sweep records it to refuse resuming with rows of
//! another scene.

use std::collections::HashSet;
use std::fmt::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};

use crate::scene::shape_mesh::shape_mesh;
use crate::scene::texture::Texture;
use crate::scene::{Scene, Shape};
use crate::util::hash::Fnv64;

/// The fingerprint of `scene` as 16 hexadecimal digits. Reads every mesh and texture file the
/// scene names (once each); errors name the file.
pub fn fingerprint(scene: &Scene) -> Result<String> {
    let mut hash = Fnv64::default();
    let mut key = scene.clone();
    key.path = PathBuf::new();
    let mut seen = HashSet::new();
    for object in &mut key.objects {
        // Where the keyframes are written (for messages) is not what they hold.
        object.motion.places.clear();
        let file = match &mut object.shape {
            Shape::Mesh { path } | Shape::Road { path, .. } => Some(path),
            _ => None,
        };
        if let Some(path) = file {
            // The mesh's content (a road map's: its triangles as baked), in the order the
            // objects place it (a second placement of the same file adds its name only).
            let first = seen.insert(path.clone());
            write!(hash, "mesh {first};").ok();
            if first {
                let mesh = shape_mesh(&object.shape).expect("a file's shape")?;
                for tri in &mesh.tris {
                    for v in tri.p.iter().flat_map(|p| p.to_array()) {
                        hash.bytes(&v.to_bits().to_le_bytes());
                    }
                    for v in tri.uv.iter().flat_map(|p| p.to_array()) {
                        hash.bytes(&v.to_bits().to_le_bytes());
                    }
                    hash.bytes(&tri.part.to_le_bytes());
                    hash.bytes(&tri.file_material.map_or(u64::MAX, u64::from).to_le_bytes());
                }
                write!(hash, "{:?}", mesh.materials).ok();
                for texture in &mesh.textures {
                    hash_texture(&mut hash, texture);
                }
            }
            if let Shape::Mesh { path } | Shape::Road { path, .. } = &mut object.shape {
                *path = PathBuf::new();
            }
        }
        if object.shape == Shape::HeadMesh {
            // The built-in head: the files built into the binary.
            for bytes in crate::scene::mesh_io::BUILTIN_HEAD {
                hash.bytes(bytes);
            }
        }
    }
    for material in &mut key.materials {
        if let Some(path) = &mut material.texture {
            let texture =
                Texture::load(path).with_context(|| format!("material `{}`", material.name))?;
            hash_texture(&mut hash, &texture);
            *path = PathBuf::new();
        }
    }
    write!(hash, "{key:?}").ok();
    Ok(format!("{:016x}", hash.finish()))
}

/// A texture's size and every texel's bits.
fn hash_texture(hash: &mut Fnv64, texture: &Texture) {
    write!(hash, "texture {}×{};", texture.width, texture.height).ok();
    for v in texture.texels.iter().flat_map(|t| t.to_array()) {
        hash.bytes(&v.to_bits().to_le_bytes());
    }
}
