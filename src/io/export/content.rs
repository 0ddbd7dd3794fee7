//! What a scene export holds, gathered once from the scene and its world: the traced
//! triangles (spheres tessellated) with normals and UVs per object, part and material; the
//! materials; the lighting in physical terms. The writers (`gltf.rs`, `obj.rs`,
//! `mitsuba.rs`) turn it into files.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use glam::{DVec3, Vec2, Vec3, Vec3A};
use serde_json::json;

use crate::geometry::camera::Camera;
use crate::io::atomic::write_atomically;
use crate::render::sky::SkyModel;
use crate::scene::shape_mesh::shape_mesh;
use crate::scene::texture::Texture;
use crate::scene::world::{Ellipsoid, TriAttr, World, view_bit};
use crate::scene::{Scene, Shape};
use crate::util::color::encode_srgb8;

/// Latitude × longitude bands of the spheres' tessellation in exports.
pub const SPHERE_BANDS: (usize, usize) = (24, 48);

/// Near clipping distance written to the exported cameras, metres. seethru's cameras have no
/// near plane; rasterisers need one, and nothing a camera sees lies closer than this.
pub const CAMERA_ZNEAR: f64 = 0.01;

/// Triangles of one object that share a part and a material: one glTF primitive.
#[derive(Clone, Debug)]
pub struct Primitive {
    /// Part id, as in the part-id AOV.
    pub part: u32,
    /// Index into [`ExportScene::materials`].
    pub material: usize,
    /// Vertex positions, world frame, metres.
    pub positions: Vec<Vec3>,
    /// Unit shading normals, world frame: the face normal of a flat triangle (the renderer
    /// shades triangles flat), the ellipsoid's own normal on tessellated spheres.
    pub normals: Vec<Vec3>,
    /// Texture coordinates with the material's `uv_repeat` applied: u right, v down from the
    /// texture's top-left corner, repeating (the glTF convention).
    pub uvs: Vec<Vec2>,
    /// Vertex indices, counter-clockwise seen from the side the normals point to.
    pub triangles: Vec<[u32; 3]>,
}

impl Primitive {
    /// An empty primitive.
    pub fn new(part: u32, material: usize) -> Self {
        Self {
            part,
            material,
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            triangles: Vec::new(),
        }
    }

    /// Appends `other`'s vertices and triangles.
    pub fn append(&mut self, other: &Primitive) {
        let base = self.positions.len() as u32;
        self.positions.extend(&other.positions);
        self.normals.extend(&other.normals);
        self.uvs.extend(&other.uvs);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| base + i)));
    }
}

/// One node of the export: a scene object, the obstacle, or the display (the obstacle's
/// driver-facing face, exported on its own so that it can be found and textured).
#[derive(Clone, Debug)]
pub struct ExportObject {
    pub name: String,
    /// seethru object id as in the id AOV: position in the scene file's object list + 1; the
    /// obstacle (and its display) last.
    pub id: u32,
    /// `plane`, `box`, `sphere`, …, `obstacle` or `display`.
    pub kind: &'static str,
    /// Bit set of the [`view_bit`]s of the seethru views that show the object.
    pub views: u8,
    pub casts_shadow: bool,
    pub primitives: Vec<Primitive>,
}

impl ExportObject {
    /// Names of the seethru views that show the object.
    pub fn view_names(&self) -> Vec<&'static str> {
        VIEWS
            .iter()
            .filter(|(_, bit, _)| self.views & bit != 0)
            .map(|(name, _, _)| *name)
            .collect()
    }

    /// The cameras (`driver`, `frontal`, `back`) that never see the object, as the scene
    /// file's `hidden_from` says (the obstacle: frontal and back; the truth view lacks it too).
    pub fn hidden_from(&self) -> Vec<&'static str> {
        [
            ("driver", view_bit::DRIVER),
            ("frontal", view_bit::FRONTAL),
            ("back", view_bit::BACK),
        ]
        .into_iter()
        .filter(|(_, bits)| self.views & bits == 0)
        .map(|(name, _)| name)
        .collect()
    }

    pub fn triangle_count(&self) -> usize {
        self.primitives.iter().map(|p| p.triangles.len()).sum()
    }
}

/// seethru's views, the view bit of each and the camera that renders it.
pub const VIEWS: [(&str, u8, &str); 5] = [
    ("truth", view_bit::TRUTH, "driver"),
    ("occluded", view_bit::OCCLUDED, "driver"),
    ("seethru", view_bit::SEETHRU, "driver"),
    ("frontal", view_bit::FRONTAL, "frontal"),
    ("back", view_bit::BACK, "back"),
];

#[derive(Clone, Debug)]
pub struct ExportMaterial {
    pub name: String,
    /// Base colour, linear RGB (the scene file's sRGB colour decoded), multiplied with the
    /// texture.
    pub linear_color: Vec3,
    /// The texture, linear RGB texels as the renderer samples them.
    pub texture: Option<Texture>,
    /// Texture repetitions per unit of the surface's own UVs; exported UVs include it.
    pub uv_repeat: Vec2,
    /// The glossy lobe's reflectance at normal incidence, [0, 1]; 0: Lambertian.
    pub specular: f32,
    /// The glossy lobe's GGX roughness α, (0, 1].
    pub roughness: f32,
}

impl ExportMaterial {
    /// The refractive index of a dielectric coat that reflects `specular` at normal
    /// incidence, ((n − 1)/(n + 1))² = F0, held below 2 000 (F0 → 1 has none).
    pub fn coat_ior(&self) -> f32 {
        let r = self.specular.sqrt().min(0.999);
        (1.0 + r) / (1.0 - r)
    }
}

/// Everything an export writes, gathered from the scene and its world.
pub struct ExportScene<'a> {
    pub scene: &'a Scene,
    /// Objects in id order; the display follows the obstacle.
    pub objects: Vec<ExportObject>,
    pub materials: Vec<ExportMaterial>,
    /// The lighting in physical terms (see [`Lighting`]).
    pub lighting: Lighting,
    /// The scene's `[[light]]` lamps, as a physical renderer states them.
    pub lamps: Vec<ExportLamp>,
}

/// A `[[light]]` lamp as a physically based renderer states it: a point of radiant
/// intensity `intensity` (linear RGB in the units of the export's sun, π × seethru's
/// per-unit term: a Lambertian surface of albedo ρ at distance d and incidence θ gets
/// ρ / π × intensity × cos θ / d²), a spot where `spot` says so.
#[derive(Clone, Debug)]
pub struct ExportLamp {
    pub name: String,
    /// World frame, metres.
    pub position: DVec3,
    pub intensity: Vec3,
    pub spot: Option<ExportSpot>,
    /// Whether objects shade what it lights (a physical renderer's lamps always do).
    pub casts_shadow: bool,
}

/// A spot's beam as the exporters can state it: its axis and two half angles. seethru's
/// smoothstep between them and a low beam's cut-off line are not (the writers say so).
#[derive(Clone, Copy, Debug)]
pub struct ExportSpot {
    /// Unit axis, world frame.
    pub direction: DVec3,
    /// Half angle of the full intensity, degrees.
    pub falloff_deg: f64,
    /// Half angle beyond which it gives nothing, degrees.
    pub cone_deg: f64,
    /// A low beam's cut-off line, degrees above the horizontal (`None`: none).
    pub cutoff_deg: Option<f64>,
}

/// seethru's light as a physically based renderer states it. seethru shades Lambertian
/// surfaces as albedo × (sun × cos θ × shadow + ambient(n)); a physical renderer computes
/// albedo / π × irradiance, so the sun's irradiance is π × seethru's. seethru's ambient is
/// linear in n_y, which is exactly the irradiance an unoccluded surface receives from an
/// environment of uniform radiance `sky_up` above the horizon and `sky_down` below.
#[derive(Clone, Copy, Debug)]
pub struct Lighting {
    /// Unit direction towards the sun, world frame.
    pub sun_direction: Vec3,
    /// Irradiance on a surface facing the sun, linear RGB (π × colour × intensity).
    pub sun_irradiance: Vec3,
    /// Radiance of the upper and lower hemispheres of the environment, linear RGB.
    pub sky_up: Vec3,
    pub sky_down: Vec3,
}

impl<'a> ExportScene<'a> {
    pub fn new(scene: &'a Scene, world: &World) -> Result<Self> {
        let names = material_names(scene, world)?;
        let materials = world
            .materials
            .iter()
            .zip(names)
            .map(|(m, name)| ExportMaterial {
                name,
                linear_color: m.albedo,
                texture: m.texture.map(|t| world.textures[t].clone()),
                uv_repeat: m.uv_repeat,
                specular: m.specular,
                roughness: m.roughness,
            })
            .collect::<Vec<_>>();

        // (object index or the display, part, material) → primitive.
        let display = world.objects.len();
        let mut groups: BTreeMap<(usize, u32, u32), Primitive> = BTreeMap::new();
        for (p, attr) in traced_triangles(world) {
            let owner = if world.is_display(attr.object, attr.part) {
                display
            } else {
                attr.object as usize - 1
            };
            let repeat = materials[attr.material as usize].uv_repeat;
            let n = face_normal(p);
            let prim = groups
                .entry((owner, attr.part, attr.material))
                .or_insert_with(|| Primitive::new(attr.part, attr.material as usize));
            let base = prim.positions.len() as u32;
            prim.positions.extend(p);
            prim.normals.extend([n; 3]);
            prim.uvs.extend(attr.uv.map(|uv| uv * repeat));
            prim.triangles.push([base, base + 1, base + 2]);
        }
        for el in &world.ellipsoids {
            let repeat = materials[el.material as usize].uv_repeat;
            groups
                .entry((el.object as usize - 1, 0, el.material))
                .or_insert_with(|| Primitive::new(0, el.material as usize))
                .append(&ellipsoid_mesh(el, repeat));
        }

        let mut objects = Vec::new();
        for (index, info) in world.objects.iter().enumerate() {
            let id = index as u32 + 1;
            let primitives_of = |owner: usize| {
                groups
                    .range((owner, 0, 0)..=(owner, u32::MAX, u32::MAX))
                    .map(|(_, p)| p.clone())
                    .collect::<Vec<_>>()
            };
            let kind = match scene.objects.get(index) {
                Some(o) => Shape::kind(&o.shape),
                None => "obstacle",
            };
            objects.push(ExportObject {
                name: info.name.clone(),
                id,
                kind,
                views: info.views,
                casts_shadow: info.casts_shadow,
                primitives: primitives_of(index),
            });
            if id == world.obstacle_id {
                objects.push(ExportObject {
                    name: "display".into(),
                    kind: "display",
                    primitives: primitives_of(display),
                    ..objects.last().unwrap().clone()
                });
            }
        }

        let sky = SkyModel::new(&scene.sky, &scene.sun, scene.photometry.as_ref());
        let lighting = Lighting {
            sun_direction: sky.sun_direction,
            sun_irradiance: sky.sun_irradiance * std::f32::consts::PI,
            sky_up: sky.ambient(Vec3::Y),
            sky_down: sky.ambient(-Vec3::Y),
        };
        let lamps = (scene.lights.iter())
            .zip(crate::render::integrator::lamps_of(scene).iter())
            .map(|(lamp, shading)| ExportLamp {
                name: lamp.name.clone(),
                position: lamp.position,
                intensity: shading.per_unit() * std::f32::consts::PI,
                spot: lamp.spot.map(|s| ExportSpot {
                    direction: s.direction,
                    falloff_deg: s.cos_falloff.clamp(-1.0, 1.0).acos().to_degrees(),
                    cone_deg: s.cos_cone.clamp(-1.0, 1.0).acos().to_degrees(),
                    cutoff_deg: s.cutoff_sin.map(|v| v.clamp(-1.0, 1.0).asin().to_degrees()),
                }),
                casts_shadow: lamp.casts_shadow,
            })
            .collect();
        Ok(Self {
            scene,
            objects,
            materials,
            lighting,
            lamps,
        })
    }

    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(ExportObject::triangle_count).sum()
    }

    /// The three cameras by name, in the order driver, frontal, back.
    pub fn cameras(&self) -> [(&'static str, &'a Camera); 3] {
        let s = self.scene;
        [
            ("driver", &s.driver),
            ("frontal", &s.frontal),
            ("back", &s.back),
        ]
    }
}

/// The renderer's triangles with their attributes: the one place the export reads the
/// world's triangle storage.
fn traced_triangles(world: &World) -> impl Iterator<Item = ([Vec3; 3], &TriAttr)> {
    world
        .triangles
        .iter()
        .zip(&world.tri_attrs)
        .map(|(tri, attr)| {
            let v0 = Vec3::from(tri.v0);
            ([v0, v0 - Vec3::from(tri.e1), v0 + Vec3::from(tri.e2)], attr)
        })
}

/// Unit normal of a counter-clockwise triangle (computed in f64: thin triangles stay unit).
fn face_normal(p: [Vec3; 3]) -> Vec3 {
    let [a, b, c] = p.map(Vec3::as_dvec3);
    let n = (b - a).cross(c - a).normalize_or_zero();
    if n == DVec3::ZERO {
        Vec3::Y
    } else {
        n.as_vec3()
    }
}

/// An ellipsoid as a latitude–longitude mesh: vertices on the exact surface, its normals,
/// and the renderer's equirectangular UVs (u around +y, v from the north pole down).
fn ellipsoid_mesh(el: &Ellipsoid, repeat: Vec2) -> Primitive {
    let (lat, lon) = SPHERE_BANDS;
    let mut prim = Primitive::new(0, el.material as usize);
    for i in 0..=lat {
        for j in 0..=lon {
            let (theta, phi) = (
                std::f32::consts::PI * i as f32 / lat as f32,
                std::f32::consts::TAU * j as f32 / lon as f32,
            );
            let local = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            prim.positions
                .push(el.world_from_object.transform_point3(local));
            prim.normals
                .push(Vec3::from(el.normal_from_object * Vec3A::from(local)).normalize());
            // The renderer's u = 0.5 + atan2(z, x) / 2π is 0.5 − φ / 2π here; unwrapped so
            // that the seam's triangles do not span the whole texture.
            prim.uvs
                .push(Vec2::new(0.5 - j as f32 / lon as f32, i as f32 / lat as f32) * repeat);
        }
    }
    // A mirroring transform turns the winding inside out; keep it counter-clockwise outside.
    let mirrored = el.world_from_object.matrix3.determinant() < 0.0;
    let vertex = |i: usize, j: usize| (i * (lon + 1) + j) as u32;
    let mut push = |t: [u32; 3]| {
        prim.triangles
            .push(if mirrored { [t[0], t[2], t[1]] } else { t })
    };
    for i in 0..lat {
        for j in 0..lon {
            let (a, b, c, d) = (
                vertex(i, j),
                vertex(i + 1, j),
                vertex(i + 1, j + 1),
                vertex(i, j + 1),
            );
            // The poles' degenerate triangles are left out.
            if i > 0 {
                push([a, b, d]);
            }
            if i + 1 < lat {
                push([b, c, d]);
            }
        }
    }
    prim
}

/// Names of the world's materials, in its order: the scene file's materials, then each
/// mesh file's own (`<object>.<material>`, or `<object>.default` for a mesh file without
/// materials), then the obstacle's body and display.
fn material_names(scene: &Scene, world: &World) -> Result<Vec<String>> {
    let mut names: Vec<String> = scene.materials.iter().map(|m| m.name.clone()).collect();
    for object in &scene.objects {
        if let Some(file) = shape_mesh(&object.shape) {
            let file = file?;
            names.extend(
                file.materials
                    .iter()
                    .map(|m| format!("{}.{}", object.name, m.name)),
            );
            if file.materials.is_empty() && object.material.is_none() {
                names.push(format!("{}.default", object.name));
            }
        }
    }
    names.extend(["obstacle_body".into(), "display".into()]);
    if names.len() != world.materials.len() {
        // The world numbers its materials differently from the scene file: plain names.
        names = (0..world.materials.len())
            .map(|i| format!("material{i}"))
            .collect();
    }
    Ok(names)
}

/// A name as a file or identifier part: ASCII letters, digits, `-` and `_`.
pub fn sanitize(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A texture as an 8-bit sRGB PNG: exactly the texels the renderer decoded.
pub fn texture_png(texture: &Texture) -> Result<Vec<u8>> {
    let bytes = texture
        .texels
        .iter()
        .flat_map(|&t| encode_srgb8(t))
        .collect();
    let image = image::RgbImage::from_raw(texture.width, texture.height, bytes)
        .context("texture size does not match its texels")?;
    let mut png = std::io::Cursor::new(Vec::new());
    image.write_to(&mut png, image::ImageFormat::Png)?;
    Ok(png.into_inner())
}

/// The folder beside `path` that holds an export's meshes and textures: `<stem>_assets`.
pub fn assets_dir(path: &Path) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}_assets"))
}

/// Writes `bytes` to `dir/name` (atomically, creating `dir`); returns the file's path.
pub fn write_asset(dir: &Path, name: &str, bytes: &[u8]) -> Result<PathBuf> {
    let path = dir.join(name);
    write_atomically(&path, |file| Ok(file.write_all(bytes)?))?;
    Ok(path)
}

/// Vertical field of view (full angle, radians) of a camera with square pixels:
/// 2 atan(tan θx · height / width).
pub fn vertical_fov(c: &Camera) -> f64 {
    2.0 * c.tan_half_y().atan()
}

/// The display rectangle: corners, normal, size and resolution.
pub fn display_json(scene: &Scene) -> serde_json::Value {
    let o = &scene.obstacle;
    json!({
        "corners_tl_tr_br_bl": o.display_corners().map(|c| c.to_array()),
        "normal_towards_driver": o.normal().to_array(),
        "world_from_display_column_major": glam::DMat4::from(o.world_from_obstacle).to_cols_array(),
        "width_m": o.width,
        "height_m": o.height,
        "resolution": o.display_resolution,
    })
}
