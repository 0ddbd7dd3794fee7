//! Loading triangle meshes from OBJ (tobj) and glTF/GLB (gltf) files.
//!
//! Colours in mesh files (OBJ `Kd`, glTF `baseColorFactor`) are taken as linear RGB, as the
//! exporters of Blender and most DCC tools write them. Part ids are the OBJ object/group
//! index or the glTF primitive index, so a measurement can tell a car's body from its wheels.

use std::path::Path;

use anyhow::{Context, Result, bail};
use glam::{Mat4, Vec2, Vec3};

use crate::scene::shapes::Tri;

/// A material that a mesh file defines.
#[derive(Clone, Debug, PartialEq)]
pub struct FileMaterial {
    pub name: String,
    /// Base colour, linear RGB in [0, 1].
    pub linear_color: [f32; 3],
}

/// Triangles of a mesh file, in the file's own frame (glTF node transforms applied).
#[derive(Clone, Debug, Default)]
pub struct LoadedMesh {
    pub tris: Vec<Tri>,
    pub materials: Vec<FileMaterial>,
}

pub fn load_mesh(path: &Path) -> Result<LoadedMesh> {
    let lower = path.to_string_lossy().to_ascii_lowercase();
    let mesh = if lower.ends_with(".obj") {
        load_obj(path)
    } else if lower.ends_with(".gltf") || lower.ends_with(".glb") {
        load_gltf(path)
    } else {
        bail!("unsupported mesh format (use .obj, .gltf or .glb)")
    }
    .with_context(|| format!("cannot load mesh {}", path.display()))?;
    if mesh.tris.is_empty() {
        bail!("mesh {} has no triangles", path.display());
    }
    if mesh.tris.iter().any(|t| t.p.iter().any(|p| !p.is_finite())) {
        bail!("mesh {} has non-finite vertex positions", path.display());
    }
    Ok(mesh)
}

fn load_obj(path: &Path) -> Result<LoadedMesh> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(path, &options).map_err(|e| anyhow::anyhow!("{e}"))?;
    let materials = materials.map_err(|e| anyhow::anyhow!("material library: {e}"))?;
    let mut out = LoadedMesh {
        materials: materials
            .iter()
            .map(|m| FileMaterial {
                name: m.name.clone(),
                linear_color: m.diffuse.unwrap_or([0.8; 3]),
            })
            .collect(),
        ..Default::default()
    };
    for (part, model) in models.iter().enumerate() {
        let mesh = &model.mesh;
        let vertex = |i: u32| {
            let i = i as usize;
            Vec3::new(
                mesh.positions[3 * i],
                mesh.positions[3 * i + 1],
                mesh.positions[3 * i + 2],
            )
        };
        let uv = |i: u32| {
            let i = i as usize;
            match mesh.texcoords.get(2 * i..2 * i + 2) {
                // OBJ puts v = 0 at the image's bottom; ours is at the top.
                Some(t) => Vec2::new(t[0], 1.0 - t[1]),
                None => Vec2::ZERO,
            }
        };
        for idx in mesh.indices.chunks_exact(3) {
            if idx
                .iter()
                .any(|&i| 3 * i as usize + 2 >= mesh.positions.len())
            {
                bail!(
                    "object `{}` indexes a vertex that does not exist",
                    model.name
                );
            }
            out.tris.push(Tri {
                p: [vertex(idx[0]), vertex(idx[1]), vertex(idx[2])],
                uv: [uv(idx[0]), uv(idx[1]), uv(idx[2])],
                part: part as u32,
                file_material: mesh.material_id.map(|m| m as u32),
            });
        }
    }
    Ok(out)
}

fn load_gltf(path: &Path) -> Result<LoadedMesh> {
    let (doc, buffers, _images) = gltf::import(path)?;
    let mut out = LoadedMesh {
        materials: doc
            .materials()
            .map(|m| {
                let c = m.pbr_metallic_roughness().base_color_factor();
                FileMaterial {
                    name: m.name().unwrap_or("").to_string(),
                    linear_color: [c[0], c[1], c[2]],
                }
            })
            .collect(),
        ..Default::default()
    };
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    let Some(scene) = scene else {
        bail!("the file has no scene")
    };
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    let mut part = 0u32;
    while let Some((node, parent)) = stack.pop() {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                if primitive.mode() != gltf::mesh::Mode::Triangles {
                    bail!(
                        "mesh `{}` has a primitive that is not a triangle list",
                        mesh.name().unwrap_or("")
                    );
                }
                let reader = primitive.reader(|b| Some(&buffers[b.index()]));
                let positions: Vec<Vec3> = reader
                    .read_positions()
                    .context("a primitive has no POSITION attribute")?
                    .map(|p| world.transform_point3(Vec3::from_array(p)))
                    .collect();
                let uvs: Vec<Vec2> = match reader.read_tex_coords(0) {
                    Some(t) => t.into_f32().map(Vec2::from_array).collect(),
                    None => vec![Vec2::ZERO; positions.len()],
                };
                let indices: Vec<u32> = match reader.read_indices() {
                    Some(i) => i.into_u32().collect(),
                    None => (0..positions.len() as u32).collect(),
                };
                for idx in indices.chunks_exact(3) {
                    let [a, b, c] = [idx[0] as usize, idx[1] as usize, idx[2] as usize];
                    if a.max(b).max(c) >= positions.len() {
                        bail!("a primitive indexes a vertex that does not exist");
                    }
                    out.tris.push(Tri {
                        p: [positions[a], positions[b], positions[c]],
                        uv: [uvs[a], uvs[b], uvs[c]],
                        part,
                        file_material: primitive.material().index().map(|m| m as u32),
                    });
                }
                part += 1;
            }
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    Ok(out)
}
