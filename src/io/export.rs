//! Exporting a scene's triangles (OBJ or binary glTF) and its cameras (JSON), so that other
//! renderers can be run on exactly the same scene.

use std::path::Path;

use anyhow::{Result, bail};
use glam::{Vec3, Vec3A};
use serde_json::json;

use crate::geometry::camera::Camera;
use crate::io::atomic::{write_atomically, write_text};
use crate::scene::Scene;
use crate::scene::world::World;

/// Latitude × longitude bands of the spheres' tessellation in exports.
const SPHERE_BANDS: (usize, usize) = (24, 48);

/// Every object's world-space triangles, spheres tessellated; index = object id − 1.
pub fn object_triangles(world: &World) -> Vec<Vec<[Vec3; 3]>> {
    let mut out = vec![Vec::new(); world.objects.len()];
    for (tri, attr) in world.triangles.iter().zip(&world.tri_attrs) {
        let v0 = Vec3::from(tri.v0);
        out[attr.object as usize - 1].push([v0, v0 - Vec3::from(tri.e1), v0 + Vec3::from(tri.e2)]);
    }
    let (lat, lon) = SPHERE_BANDS;
    for el in &world.ellipsoids {
        let point = |i: usize, j: usize| {
            let (theta, phi) = (
                std::f32::consts::PI * i as f32 / lat as f32,
                std::f32::consts::TAU * j as f32 / lon as f32,
            );
            let local = Vec3A::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            Vec3::from(el.world_from_object.transform_point3a(local))
        };
        let tris = &mut out[el.object as usize - 1];
        for i in 0..lat {
            for j in 0..lon {
                let (a, b, c, d) = (
                    point(i, j),
                    point(i + 1, j),
                    point(i + 1, j + 1),
                    point(i, j + 1),
                );
                if i > 0 {
                    tris.push([a, b, d]);
                }
                if i + 1 < lat {
                    tris.push([b, c, d]);
                }
            }
        }
    }
    out
}

fn camera_json(c: &Camera) -> serde_json::Value {
    let m = glam::DMat4::from(c.world_from_camera);
    json!({
        "position": c.position().to_array(),
        "forward": c.forward().to_array(),
        "up": c.world_from_camera.matrix3.y_axis.to_array(),
        "world_from_camera_column_major": m.to_cols_array(),
        "half_angle_x_deg": c.half_angle_x.to_degrees(),
        "half_angle_y_deg": c.tan_half_y().atan().to_degrees(),
        "resolution": [c.width, c.height],
        "convention": "camera looks down -z, +x right, +y up; pinhole, square pixels",
    })
}

/// The cameras and the display rectangle as JSON.
pub fn cameras_json(scene: &Scene) -> serde_json::Value {
    let o = &scene.obstacle;
    json!({
        "units": "metres, world frame right-handed +y up",
        "driver": camera_json(&scene.driver),
        "frontal": camera_json(&scene.frontal),
        "back": camera_json(&scene.back),
        "display": {
            "corners_tl_tr_br_bl": o.display_corners().map(|c| c.to_array()),
            "normal_towards_driver": o.normal().to_array(),
            "width_m": o.width,
            "height_m": o.height,
            "resolution": o.display_resolution,
        },
    })
}

fn obj_text(world: &World, objects: &[Vec<[Vec3; 3]>]) -> String {
    use std::fmt::Write;
    let mut s = String::from("# seethru export: world-space triangles, metres, +y up\n");
    let mut base = 1;
    for (info, tris) in world.objects.iter().zip(objects) {
        let _ = writeln!(s, "o {}", info.name.replace(char::is_whitespace, "_"));
        for t in tris {
            for v in t {
                let _ = writeln!(s, "v {} {} {}", v.x, v.y, v.z);
            }
        }
        for i in 0..tris.len() {
            let _ = writeln!(
                s,
                "f {} {} {}",
                base + 3 * i,
                base + 3 * i + 1,
                base + 3 * i + 2
            );
        }
        base += 3 * tris.len();
    }
    s
}

fn glb_bytes(world: &World, objects: &[Vec<[Vec3; 3]>]) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let (mut nodes, mut meshes, mut accessors, mut views) = (vec![], vec![], vec![], vec![]);
    for (info, tris) in world
        .objects
        .iter()
        .zip(objects)
        .filter(|(_, t)| !t.is_empty())
    {
        let count = tris.len() * 3;
        let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        let start = bin.len();
        for v in tris.iter().flatten() {
            (min, max) = (min.min(*v), max.max(*v));
            bin.extend(v.to_array().iter().flat_map(|f| f.to_le_bytes()));
        }
        let index_start = bin.len();
        bin.extend((0..count as u32).flat_map(|i| i.to_le_bytes()));
        let a = accessors.len();
        views.push(json!({"buffer": 0, "byteOffset": start, "byteLength": index_start - start, "target": 34962}));
        views.push(json!({"buffer": 0, "byteOffset": index_start, "byteLength": 4 * count, "target": 34963}));
        accessors.push(json!({"bufferView": a, "componentType": 5126, "count": count, "type": "VEC3", "min": min.to_array(), "max": max.to_array()}));
        accessors.push(
            json!({"bufferView": a + 1, "componentType": 5125, "count": count, "type": "SCALAR"}),
        );
        nodes.push(json!({"mesh": meshes.len(), "name": info.name}));
        meshes.push(json!({"name": info.name, "primitives": [{"attributes": {"POSITION": a}, "indices": a + 1}]}));
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "seethru"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes, "meshes": meshes, "accessors": accessors, "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    let mut json_chunk = doc.to_string().into_bytes();
    while !json_chunk.len().is_multiple_of(4) {
        json_chunk.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json_chunk.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json_chunk.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json_chunk);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// Writes the scene's triangles to `path` (.obj or .glb) and the cameras to
/// `<path without extension>.cameras.json`. Returns the number of triangles written.
pub fn export(scene: &Scene, world: &World, path: &Path) -> Result<usize> {
    let objects = object_triangles(world);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("obj") => write_text(path, &obj_text(world, &objects))?,
        Some("glb") => {
            let bytes = glb_bytes(world, &objects);
            write_atomically(path, |tmp| Ok(std::fs::write(tmp, bytes)?))?
        }
        _ => bail!("export writes .obj or .glb files, not {}", path.display()),
    }
    let cameras = serde_json::to_string_pretty(&cameras_json(scene))?;
    write_text(&path.with_extension("cameras.json"), &cameras)?;
    Ok(objects.iter().map(Vec::len).sum())
}
