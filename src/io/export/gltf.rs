//! The export as binary glTF 2.0 (.glb), self-contained: one node per object with its seethru
//! id in `extras`, one primitive per part and material (POSITION, NORMAL, TEXCOORD_0), the
//! materials (linear base colour, the texture embedded as PNG), the three cameras, the display
//! as a node of its own, and the sun as a KHR_lights_punctual directional light.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Result;
use glam::{DQuat, DVec3, Vec2, Vec3};
use serde_json::{Value, json};

use crate::geometry::camera::world_from_camera_rotation;
use crate::io::atomic::write_atomically;
use crate::io::export::content::{
    CAMERA_ZNEAR, ExportObject, ExportScene, SPHERE_BANDS, display_json, texture_png, vertical_fov,
};

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const LINEAR: u32 = 9729;
const REPEAT: u32 = 10497;

/// The binary chunk and the buffer views and accessors that point into it.
#[derive(Default)]
struct Binary {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Binary {
    /// Appends `data` as a buffer view (4-byte aligned); returns its index.
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut view =
            json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(view);
        self.views.len() - 1
    }

    fn accessor(&mut self, data: &[u8], target: u32, mut accessor: Value) -> usize {
        accessor["bufferView"] = json!(self.view(data, Some(target)));
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn vec3(&mut self, values: &[Vec3], min_max: bool) -> usize {
        let data: Vec<u8> = values
            .iter()
            .flat_map(|v| v.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let mut a = json!({"componentType": FLOAT, "count": values.len(), "type": "VEC3"});
        if min_max {
            let min = values.iter().fold(Vec3::INFINITY, |m, v| m.min(*v));
            let max = values.iter().fold(Vec3::NEG_INFINITY, |m, v| m.max(*v));
            a["min"] = json!(min.to_array());
            a["max"] = json!(max.to_array());
        }
        self.accessor(&data, ARRAY_BUFFER, a)
    }

    fn vec2(&mut self, values: &[Vec2]) -> usize {
        let data: Vec<u8> = values
            .iter()
            .flat_map(|v| v.to_array())
            .flat_map(f32::to_le_bytes)
            .collect();
        let a = json!({"componentType": FLOAT, "count": values.len(), "type": "VEC2"});
        self.accessor(&data, ARRAY_BUFFER, a)
    }

    fn indices(&mut self, triangles: &[[u32; 3]]) -> usize {
        let data: Vec<u8> = triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let a =
            json!({"componentType": UNSIGNED_INT, "count": 3 * triangles.len(), "type": "SCALAR"});
        self.accessor(&data, ELEMENT_ARRAY_BUFFER, a)
    }
}

/// A node's translation and unit rotation quaternion (x, y, z, w) from a rigid pose.
fn pose(position: DVec3, rotation: glam::DMat3) -> (Value, Value) {
    let q = DQuat::from_mat3(&rotation).normalize();
    (json!(position.to_array()), json!(q.to_array()))
}

fn object_extras(o: &ExportObject) -> Value {
    let mut extras = json!({
        "seethru_id": o.id,
        "seethru_kind": o.kind,
        "hidden_from": o.hidden_from(),
        "views": o.view_names(),
        "casts_shadow": o.casts_shadow,
    });
    if o.kind == "sphere" {
        extras["tessellation_lat_lon"] = json!([SPHERE_BANDS.0, SPHERE_BANDS.1]);
    }
    extras
}

/// The glTF JSON document and its binary chunk.
fn document(content: &ExportScene) -> Result<(Value, Vec<u8>)> {
    let scene = content.scene;
    let mut bin = Binary::default();

    let (mut images, mut textures, mut materials) = (vec![], vec![], vec![]);
    for m in &content.materials {
        let c = m.linear_color;
        // glTF's roughness is the square root of GGX's α.
        let mut pbr = json!({
            "baseColorFactor": [c.x, c.y, c.z, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": if m.specular > 0.0 { m.roughness.sqrt() } else { 1.0 },
        });
        if let Some(t) = &m.texture {
            let view = bin.view(&texture_png(t)?, None);
            images.push(json!({"bufferView": view, "mimeType": "image/png", "name": m.name}));
            textures.push(json!({"sampler": 0, "source": images.len() - 1, "name": m.name}));
            pbr["baseColorTexture"] = json!({"index": textures.len() - 1});
        }
        materials.push(json!({
            "name": m.name,
            "pbrMetallicRoughness": pbr,
            // A Lambertian surface has no specular reflection; a glossy one a dielectric
            // coat of the index that reflects its F0. Every surface is seen from both sides.
            "extensions": if m.specular > 0.0 {
                json!({"KHR_materials_specular": {"specularFactor": 1.0},
                       "KHR_materials_ior": {"ior": m.coat_ior()}})
            } else {
                json!({"KHR_materials_specular": {"specularFactor": 0.0}})
            },
            "doubleSided": true,
            "extras": {
                "uv_repeat": m.uv_repeat.to_array(),
                "note": "TEXCOORD_0 already includes uv_repeat",
            },
        }));
    }

    let (mut nodes, mut meshes, mut roots): (Vec<Value>, Vec<Value>, Vec<usize>) =
        (vec![], vec![], vec![]);
    for o in &content.objects {
        let mut node = json!({"name": o.name, "extras": object_extras(o)});
        if !o.primitives.is_empty() {
            let primitives: Vec<Value> = o
                .primitives
                .iter()
                .map(|p| {
                    json!({
                        "attributes": {
                            "POSITION": bin.vec3(&p.positions, true),
                            "NORMAL": bin.vec3(&p.normals, false),
                            "TEXCOORD_0": bin.vec2(&p.uvs),
                        },
                        "indices": bin.indices(&p.triangles),
                        "material": p.material,
                        "extras": {"seethru_part": p.part},
                    })
                })
                .collect();
            node["mesh"] = json!(meshes.len());
            meshes.push(json!({"name": o.name, "primitives": primitives}));
        }
        if o.kind == "display" {
            // The display's face: UV (0, 0) is its top-left corner as the driver sees it,
            // (1, 1) its bottom-right, so a `display.png` maps onto it as it is.
            node["extras"]["seethru_part"] = json!(crate::scene::shapes::box_face::POS_Z);
            node["extras"]["display"] = display_json(scene);
            let obstacle = nodes.len() - 1;
            nodes[obstacle]["children"] = json!([nodes.len()]);
        } else {
            roots.push(nodes.len());
        }
        nodes.push(node);
    }

    let mut cameras = vec![];
    for (name, c) in content.cameras() {
        let (translation, rotation) = pose(c.position(), c.world_from_camera.matrix3);
        roots.push(nodes.len());
        nodes.push(json!({
            "name": name,
            "camera": cameras.len(),
            "translation": translation,
            "rotation": rotation,
            "extras": {
                "seethru_camera": name,
                "half_angle_x_deg": c.half_angle_x.to_degrees(),
                "resolution": [c.width, c.height],
            },
        }));
        cameras.push(json!({
            "name": name,
            "type": "perspective",
            "perspective": {
                "aspectRatio": c.width as f64 / c.height as f64,
                "yfov": vertical_fov(c),
                "znear": CAMERA_ZNEAR,
            },
        }));
    }

    // The sun: a directional light shines down its node's −z.
    let light = &content.lighting;
    let towards_sun = scene.sun.direction;
    let up = if towards_sun.cross(DVec3::Y).length() > 1e-6 {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let rotation = world_from_camera_rotation(-towards_sun, up)?;
    let color = light.sun_irradiance / light.sun_irradiance.max_element().max(f32::MIN_POSITIVE);
    roots.push(nodes.len());
    nodes.push(json!({
        "name": "sun",
        "rotation": pose(DVec3::ZERO, rotation).1,
        "extensions": {"KHR_lights_punctual": {"light": 0}},
    }));
    // The lamps: a point or spot light each, in the sun's units (its radiant intensity over
    // its colour's largest channel); a spot shines down its node's −z.
    let mut lights = vec![json!({
        "name": "sun",
        "type": "directional",
        "color": color.to_array(),
        "intensity": light.sun_irradiance.max_element(),
    })];
    for lamp in &content.lamps {
        let peak = lamp.intensity.max_element().max(f32::MIN_POSITIVE);
        let mut entry = json!({
            "name": lamp.name,
            "type": "point",
            "color": (lamp.intensity / peak).to_array(),
            "intensity": lamp.intensity.max_element(),
        });
        let mut rotation = json!([0.0, 0.0, 0.0, 1.0]);
        if let Some(spot) = &lamp.spot {
            let up = if spot.direction.cross(DVec3::Y).length() > 1e-6 {
                DVec3::Y
            } else {
                DVec3::Z
            };
            rotation = pose(DVec3::ZERO, world_from_camera_rotation(spot.direction, up)?).1;
            // glTF needs the inner cone strictly inside the outer one.
            let outer = spot.cone_deg.to_radians();
            entry["type"] = json!("spot");
            entry["spot"] = json!({
                "innerConeAngle": spot.falloff_deg.to_radians().min(outer * (1.0 - 1e-6)),
                "outerConeAngle": outer,
            });
        }
        entry["extras"] = json!({"seethru_casts_shadow": lamp.casts_shadow, "seethru_cutoff_deg": lamp.spot.and_then(|s| s.cutoff_deg)});
        roots.push(nodes.len());
        nodes.push(json!({
            "name": lamp.name,
            "translation": lamp.position.to_array(),
            "rotation": rotation,
            "extensions": {"KHR_lights_punctual": {"light": lights.len()}},
        }));
        lights.push(entry);
    }

    let mut extensions_used = vec!["KHR_lights_punctual", "KHR_materials_specular"];
    if content.materials.iter().any(|m| m.specular > 0.0) {
        extensions_used.push("KHR_materials_ior");
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": concat!("seethru ", env!("CARGO_PKG_VERSION"))},
        "extensionsUsed": extensions_used,
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "scene": 0,
        "scenes": [{
            "name": scene.path.file_stem().unwrap_or_default().to_string_lossy(),
            "nodes": roots,
            "extras": {"seethru": {
                "units": "metres; world frame right-handed, +y up",
                "ids": "node extras seethru_id: the object's position in the scene file's object list + 1, the obstacle (and its display) last; as in the id AOV",
                "lighting": "seethru shades albedo × (sun × cos θ × shadow + ambient); the sun's intensity here is π × seethru's, as a physical renderer divides by π",
                "sky_up_radiance": light.sky_up.to_array(),
                "sky_down_radiance": light.sky_down.to_array(),
                "sun_direction": light.sun_direction.to_array(),
            }},
        }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "textures": textures,
        "images": images,
        "samplers": [{"magFilter": LINEAR, "minFilter": LINEAR, "wrapS": REPEAT, "wrapT": REPEAT}],
        "cameras": cameras,
        "accessors": bin.accessors,
        "bufferViews": bin.views,
        "buffers": [{"byteLength": bin.bytes.len()}],
    });
    Ok((doc, bin.bytes))
}

/// The GLB container: header, JSON chunk, binary chunk.
fn glb(doc: &Value, mut bin: Vec<u8>) -> Vec<u8> {
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

/// Writes the export as one self-contained .glb file.
pub fn write_glb(content: &ExportScene, path: &Path) -> Result<Vec<PathBuf>> {
    let (doc, bin) = document(content)?;
    let bytes = glb(&doc, bin);
    write_atomically(path, |file| Ok(file.write_all(&bytes)?))?;
    Ok(vec![path.to_path_buf()])
}
