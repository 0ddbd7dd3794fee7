//! The renderable world: every object of a scene flattened into world-space primitives
//! (triangles and analytic ellipsoids) with their materials, textures and ids, but for
//! instanced meshes, kept once with their placements ([`InstanceSet`]).
//!
//! Primitive indices run over the triangles, then the instanced triangles (set by set,
//! placement by placement), then the ellipsoids: the order of the same world
//! [`World::flattened`], so that both break ties between equally near hits alike.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use glam::{Affine3A, DAffine3, DVec3, Mat3A, Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::ray::Ray;
use obvhs::rt_triangle::RtTriangle;
use rayon::prelude::*;

use crate::scene::instances::{self, MAX_INSTANCED_TRIANGLES, placed_triangle};
use crate::scene::limits::{check_placed_mesh, out_of_world};
use crate::scene::mesh_io::{LoadedMesh, SharedMesh, load_mesh_sharing};
use crate::scene::motion::check_keyframed_mesh;
use crate::scene::shape_mesh::shape_mesh;
use crate::scene::shapes::{Tri, box_face, cuboid, frustum, plane_xz, quad_xy};
use crate::scene::texture::Texture;
use crate::scene::{CameraKind, Object, Obstacle, Scene, Shape};
use crate::util::color::srgb_to_linear3;

/// The views a primitive can be visible in, as bits of a mask.
pub mod view_bit {
    pub const TRUTH: u8 = 1;
    pub const OCCLUDED: u8 = 2;
    pub const SEETHRU: u8 = 4;
    pub const FRONTAL: u8 = 8;
    pub const BACK: u8 = 16;
    pub const DRIVER: u8 = TRUTH | OCCLUDED | SEETHRU;
}

/// Object id of "nothing hit" (the sky) in id AOVs; objects are numbered from 1.
pub const SKY_ID: u32 = 0;

#[derive(Clone, Debug)]
pub struct SurfaceMaterial {
    /// Base colour, linear RGB.
    pub albedo: Vec3,
    pub texture: Option<usize>,
    pub uv_repeat: Vec2,
    /// The glossy lobe's reflectance at normal incidence, [0, 1]; 0: Lambertian only.
    pub specular: f32,
    /// The glossy lobe's GGX roughness α, (0, 1].
    pub roughness: f32,
}

impl SurfaceMaterial {
    /// A Lambertian material of linear colour `albedo`, untextured.
    pub fn matte(albedo: Vec3) -> SurfaceMaterial {
        SurfaceMaterial {
            albedo,
            texture: None,
            uv_repeat: Vec2::ONE,
            specular: 0.0,
            roughness: 1.0,
        }
    }
}

#[derive(Clone, Debug)]
pub struct ObjectInfo {
    pub name: String,
    /// Bit set of [`view_bit`]s of the views that show the object.
    pub views: u8,
    pub casts_shadow: bool,
}

/// Per-triangle data that the intersection itself does not need.
#[derive(Clone, Copy, Debug)]
pub struct TriAttr {
    pub uv: [Vec2; 3],
    /// Unit geometric normal, world frame (counter-clockwise front).
    pub normal: Vec3,
    pub part: u32,
    /// Object id: index into [`World::objects`] plus one.
    pub object: u32,
    pub material: u32,
}

/// One mesh and its placements.
pub struct InstanceSet {
    /// The mesh's triangles in its object frame (metres), degenerate ones dropped.
    pub triangles: Vec<RtTriangle>,
    /// Per triangle: texture coordinates, part, object id and material (`normal` unused: the
    /// placed triangle's own is used).
    pub attrs: Vec<TriAttr>,
    /// World from object of each placement, f32: the transform [`placed`] applies.
    pub world_from_object: Vec<Affine3A>,
    /// Primitive index of the first placement's first triangle; placement `i`'s triangle `j`
    /// is `first_prim + i × triangles + j`.
    pub first_prim: u32,
}

impl InstanceSet {
    /// Triangles of all placements together.
    pub fn len(&self) -> usize {
        self.triangles.len() * self.world_from_object.len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Placement and triangle of the set's `k`-th triangle (0-based within the set).
    pub fn split(&self, k: usize) -> (usize, usize) {
        (k / self.triangles.len(), k % self.triangles.len())
    }

    /// The set's `k`-th triangle in the world frame, and its attributes.
    pub fn triangle(&self, k: usize) -> (RtTriangle, &TriAttr) {
        let (instance, tri) = self.split(k);
        (
            placed_triangle(&self.world_from_object[instance], &self.triangles[tri]),
            &self.attrs[tri],
        )
    }
}

/// A unit sphere under an affine transform.
#[derive(Clone, Copy, Debug)]
pub struct Ellipsoid {
    pub world_from_object: Affine3A,
    pub object_from_world: Affine3A,
    /// Inverse transpose of the linear part, for normals.
    pub normal_from_object: Mat3A,
    pub object: u32,
    pub material: u32,
}

/// What a ray hit, with everything shading and the AOVs need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Distance along the (unit) ray, metres.
    pub t: f32,
    /// World position, metres.
    pub position: Vec3,
    /// Unit geometric normal, world frame, facing the incoming ray.
    pub normal: Vec3,
    /// Texture coordinates; computed for textured materials only (zero otherwise).
    pub uv: Vec2,
    pub object: u32,
    pub part: u32,
    pub material: u32,
}

pub struct World {
    pub triangles: Vec<RtTriangle>,
    pub tri_attrs: Vec<TriAttr>,
    /// Meshes placed many times; their triangles' indices follow [`World::triangles`].
    pub instanced: Vec<InstanceSet>,
    pub ellipsoids: Vec<Ellipsoid>,
    pub objects: Vec<ObjectInfo>,
    pub materials: Vec<SurfaceMaterial>,
    pub textures: Vec<Texture>,
    /// Object id of the obstacle; its `box_face::POS_Z` part is the display.
    pub obstacle_id: u32,
}

/// Per material of the mesh file at `path` that `object` (of the scene file `scene`) places,
/// the scene material that replaces it (`materials = { name = "scene material" }`), if any;
/// an error names the scene, the key and the materials the file does define.
fn replaced_materials(
    scene: &Path,
    object: &Object,
    path: &Path,
    mesh: &LoadedMesh,
) -> Result<Vec<Option<u32>>> {
    let mut replaced = vec![None; mesh.materials.len()];
    for (name, scene_material) in &object.file_materials {
        let Some(i) = mesh.materials.iter().position(|m| &m.name == name) else {
            let defined: Vec<&str> = mesh.materials.iter().map(|m| m.name.as_str()).collect();
            let defined = if defined.is_empty() {
                "none".to_string()
            } else {
                defined.join(", ")
            };
            anyhow::bail!(
                "{}",
                crate::util::message::printable(&format!(
                    "{}: object `{}`: materials.{name}: {} defines no material `{name}` (it defines: {defined})",
                    scene.display(),
                    object.name,
                    path.display(),
                ))
            );
        };
        replaced[i] = Some(*scene_material as u32);
    }
    Ok(replaced)
}

fn views_of(visible_to: u8) -> u8 {
    let mut views = 0;
    if visible_to & CameraKind::Driver.bit() != 0 {
        views |= view_bit::DRIVER;
    }
    if visible_to & CameraKind::Frontal.bit() != 0 {
        views |= view_bit::FRONTAL;
    }
    if visible_to & CameraKind::Back.bit() != 0 {
        views |= view_bit::BACK;
    }
    views
}

impl World {
    /// Whether a hit on `object`'s `part` is on the display (the obstacle's `+z` face).
    pub fn is_display(&self, object: u32, part: u32) -> bool {
        object == self.obstacle_id && part == box_face::POS_Z
    }

    /// Builds the world of a scene: tessellates shapes, loads meshes and textures.
    pub fn build(scene: &Scene) -> Result<World> {
        Self::build_part(scene, &|_| true, true)
    }

    /// The world of the objects `keep` selects (by index) and, if `obstacle`, the obstacle.
    /// Object ids and the obstacle id are those of the whole scene's world, so that two parts
    /// traced together (a sequence's static and moving parts) name objects alike; material
    /// indices are the part's own.
    pub fn build_part(
        scene: &Scene,
        keep: &dyn Fn(usize) -> bool,
        obstacle: bool,
    ) -> Result<World> {
        let mut world = World::of_triangles(Vec::new(), Vec::new());
        // A part loads only the textures its objects use (the whole world loads them all, so
        // that a broken texture is an error whether or not an object uses it).
        let whole = (0..scene.objects.len()).all(keep);
        let mut used = vec![whole; scene.materials.len()];
        for (_, o) in scene.objects.iter().enumerate().filter(|&(i, _)| keep(i)) {
            let replacing = o.file_materials.iter().map(|(_, m)| *m);
            for m in o.material.into_iter().chain(replacing) {
                used[m] = true;
            }
        }
        // Each mesh file is read once, however many objects place it, and the files are read
        // side by side, and beside the textures (parsing is most of a big scene's start); a
        // texture's error comes first, then a file's when its first object is reached, as if
        // read in turn.
        let mesh_path = |shape: &Shape| match shape {
            Shape::Mesh { path } | Shape::Road { path, .. } => Some(path.clone()),
            Shape::HeadMesh => Some(PathBuf::from("(built-in head mesh)")),
            _ => None,
        };
        let mut firsts: Vec<(PathBuf, &Shape)> = Vec::new();
        for (index, object) in scene.objects.iter().enumerate() {
            if let Some(path) = mesh_path(&object.shape).filter(|_| keep(index))
                && !firsts.iter().any(|(p, _)| *p == path)
            {
                firsts.push((path, &object.shape));
            }
        }
        // The meshes first, on this thread: the longer task, while an idle thread (the
        // sky's table done) takes the textures.
        let (loaded, textures) = rayon::join(
            || -> Vec<Result<LoadedMesh>> {
                firsts
                    .par_iter()
                    .map(|(_, shape)| match shape {
                        // A glTF mesh several nodes place is instanced, not flattened.
                        Shape::Mesh { path } => load_mesh_sharing(path),
                        _ => shape_mesh(shape).expect("a mesh shape"),
                    })
                    .collect()
            },
            || -> Vec<Option<Result<Texture>>> {
                let load = |(index, m): (usize, &crate::scene::Material)| match &m.texture {
                    Some(path) if used[index] => {
                        Some(Texture::load(path).with_context(|| format!("material `{}`", m.name)))
                    }
                    _ => None,
                };
                scene.materials.iter().enumerate().map(load).collect()
            },
        );
        for (m, texture) in scene.materials.iter().zip(textures) {
            let texture = match texture.transpose()? {
                Some(texture) => {
                    world.textures.push(texture);
                    Some(world.textures.len() - 1)
                }
                None => None,
            };
            world.materials.push(SurfaceMaterial {
                albedo: srgb_to_linear3(m.color),
                texture,
                uv_repeat: Vec2::new(m.uv_repeat[0] as f32, m.uv_repeat[1] as f32),
                specular: m.specular as f32,
                roughness: m.roughness as f32,
            });
        }
        let mut meshes: HashMap<PathBuf, Result<LoadedMesh>> = firsts
            .into_iter()
            .map(|(path, _)| path)
            .zip(loaded)
            .collect();
        let mut texture_base: HashMap<PathBuf, usize> = HashMap::new();
        for (index, object) in scene.objects.iter().enumerate() {
            world.objects.push(ObjectInfo {
                name: object.name.clone(),
                views: views_of(object.visible_to),
                casts_shadow: object.casts_shadow,
            });
            let id = world.objects.len() as u32;
            if !keep(index) {
                continue;
            }
            let material = object.material.map(|m| m as u32);
            let size2 = |s: [f64; 2]| [s[0] as f32, s[1] as f32];
            let tris = match &object.shape {
                Shape::Sphere { radius } => {
                    let scale = DAffine3::from_scale(DVec3::splat(*radius));
                    world.add_ellipsoid(
                        object.world_from_object * scale,
                        id,
                        material.unwrap_or(0),
                    );
                    continue;
                }
                Shape::Plane { size } => plane_xz(size2(*size)),
                Shape::Box { size } => cuboid(size.map(|s| s as f32)),
                Shape::Cylinder {
                    radius,
                    height,
                    segments,
                } => frustum(*radius as f32, *radius as f32, *height as f32, *segments),
                Shape::Cone {
                    radius,
                    height,
                    segments,
                } => frustum(*radius as f32, 0.0, *height as f32, *segments),
                Shape::Quad { size } => quad_xy(size2(*size), 0),
                Shape::Mesh { .. } | Shape::HeadMesh | Shape::Road { .. } => {
                    let path = &mesh_path(&object.shape).expect("a mesh shape");
                    let mesh = match meshes.get(path).expect("read above") {
                        Ok(mesh) => mesh,
                        Err(_) => {
                            return Err(meshes.remove(path).expect("read above").unwrap_err());
                        }
                    };
                    // A moving object stays flat: the moving layer is refitted triangle by
                    // triangle.
                    let flat;
                    let (tris, shared): (&[Tri], &[SharedMesh]) = if object.motion.moves() {
                        flat = mesh.flat_tris();
                        (&flat, &[])
                    } else {
                        (&mesh.tris, &mesh.shared)
                    };
                    if object.instances.is_empty() {
                        check_placed_mesh(
                            path,
                            &object.name,
                            tris,
                            &object.world_from_object,
                            world.triangles.len(),
                        )?;
                    }
                    check_keyframed_mesh(path, &object.name, tris, &object.motion)?;
                    let first = world.materials.len() as u32;
                    // A file's textures once, however many objects place it.
                    let first_texture = *texture_base.entry(path.clone()).or_insert_with(|| {
                        world.textures.extend(mesh.textures.iter().cloned());
                        world.textures.len() - mesh.textures.len()
                    });
                    world
                        .materials
                        .extend(mesh.materials.iter().map(|m| SurfaceMaterial {
                            texture: m.texture.map(|t| first_texture + t),
                            specular: m.specular,
                            roughness: m.roughness,
                            ..SurfaceMaterial::matte(Vec3::from_array(m.linear_color))
                        }));
                    if mesh.materials.is_empty() && material.is_none() {
                        (world.materials).push(SurfaceMaterial::matte(Vec3::splat(0.6)));
                    }
                    let fallback = world.materials.len() as u32 - 1;
                    let replaced = replaced_materials(&scene.path, object, path, mesh)?;
                    let material_of = |t: &Tri| {
                        material
                            .or(t
                                .file_material
                                .map(|m| replaced[m as usize].unwrap_or(first + m)))
                            .unwrap_or(fallback)
                    };
                    // The object's placements: its instances rows, or its own transform.
                    let rows = &object.instances;
                    let placements: Vec<DAffine3> = if rows.is_empty() {
                        world.add_tris(tris, object.world_from_object, id, material_of);
                        vec![object.world_from_object]
                    } else {
                        let placements: Vec<DAffine3> = rows
                            .iter()
                            .map(|r| instances::world_from_object(*r, &object.world_from_object))
                            .collect();
                        world.add_instances(
                            path,
                            object,
                            tris,
                            &placements,
                            (id, 1),
                            material_of,
                        )?;
                        placements
                    };
                    for s in shared {
                        let nodes = &s.file_from_mesh;
                        let each: Vec<DAffine3> = placements
                            .iter()
                            .flat_map(|p| nodes.iter().map(move |m| *p * *m))
                            .collect();
                        world.add_instances(
                            path,
                            object,
                            &s.tris,
                            &each,
                            (id, nodes.len()),
                            material_of,
                        )?;
                    }
                    continue;
                }
            };
            world.add_tris(&tris, object.world_from_object, id, |_| {
                material.unwrap_or(0)
            });
        }
        world.add_obstacle(&scene.obstacle, obstacle);
        let mut first = world.triangles.len();
        for set in &mut world.instanced {
            set.first_prim = first as u32;
            first += set.len();
        }
        Ok(world)
    }

    /// One set of triangles `tris` (a mesh's frame) at `placements` (world from that frame),
    /// `per_row` of them for each of `object`'s instances rows (for messages); each
    /// placement must stay inside the world.
    fn add_instances(
        &mut self,
        path: &std::path::Path,
        object: &crate::scene::Object,
        tris: &[Tri],
        placements: &[DAffine3],
        (id, per_row): (u32, usize),
        material: impl Fn(&Tri) -> u32,
    ) -> Result<()> {
        let mut set = InstanceSet {
            triangles: Vec::new(),
            attrs: Vec::new(),
            world_from_object: Vec::with_capacity(placements.len()),
            first_prim: 0,
        };
        let mut lo = Vec3::INFINITY;
        let mut hi = Vec3::NEG_INFINITY;
        for tri in tris {
            let [a, b, c] = tri.p;
            if (b - a).cross(c - a).length_squared() == 0.0 {
                continue;
            }
            for p in tri.p {
                (lo, hi) = (lo.min(p), hi.max(p));
            }
            set.triangles
                .push(RtTriangle::new(a.into(), b.into(), c.into()));
            set.attrs.push(TriAttr {
                uv: tri.uv,
                normal: Vec3::ZERO,
                part: tri.part,
                object: id,
                material: material(tri),
            });
        }
        let before: u64 = self.instanced.iter().map(|s| s.len() as u64).sum();
        let total = before + (set.triangles.len() * placements.len()) as u64;
        if total > MAX_INSTANCED_TRIANGLES {
            anyhow::bail!(
                "object `{}`: {} placements of mesh {} bring the world's instances to {total} triangles, more than the limit of {MAX_INSTANCED_TRIANGLES}",
                object.name,
                placements.len(),
                path.display()
            );
        }
        for (k, place) in placements.iter().enumerate() {
            let m = instances::in_f32(place);
            // A placement that flattens its mesh (a glTF node scaled by 0, to hide it) shows
            // nothing, and has no object frame for a ray to enter: left out.
            if !m.matrix3.determinant().is_normal() {
                continue;
            }
            for p in instances::box_corners(lo, hi) {
                if let Some(why) = out_of_world(m.transform_point3(p).as_dvec3()) {
                    let row = if object.instances.is_empty() {
                        String::new()
                    } else {
                        format!(" (data row {} of its instances file)", k / per_row + 1)
                    };
                    anyhow::bail!(
                        "object `{}`: placement {k}{row} puts mesh {} outside the world: {why}",
                        object.name,
                        path.display()
                    );
                }
            }
            set.world_from_object.push(m);
        }
        self.instanced.push(set);
        Ok(())
    }

    /// The same world with every instanced triangle a triangle of its own, at the same
    /// index: what tracing the instances must equal, bit for bit.
    pub fn flattened(mut self) -> World {
        for set in std::mem::take(&mut self.instanced) {
            for k in 0..set.len() {
                let (rt, attr) = set.triangle(k);
                self.triangles.push(rt);
                self.tri_attrs.push(TriAttr {
                    normal: geometric_normal(&rt),
                    ..*attr
                });
            }
        }
        self
    }

    /// A world of these triangles alone (an instanced mesh in its object frame, for its
    /// hierarchy): no objects, materials or textures.
    pub fn of_triangles(triangles: Vec<RtTriangle>, tri_attrs: Vec<TriAttr>) -> World {
        World {
            triangles,
            tri_attrs,
            instanced: Vec::new(),
            ellipsoids: Vec::new(),
            objects: Vec::new(),
            materials: Vec::new(),
            textures: Vec::new(),
            obstacle_id: 0,
        }
    }

    /// Instanced triangles of all sets together.
    pub fn instanced_count(&self) -> usize {
        self.instanced.iter().map(InstanceSet::len).sum()
    }

    /// Index of the first ellipsoid: past the triangles and the instanced triangles.
    pub fn ellipsoid_base(&self) -> usize {
        self.triangles.len() + self.instanced_count()
    }

    /// What primitive index `prim` names.
    #[inline]
    fn primitive(&self, prim: usize) -> Primitive {
        if prim < self.triangles.len() {
            return Primitive::Triangle(prim);
        }
        let mut k = prim - self.triangles.len();
        for (s, set) in self.instanced.iter().enumerate() {
            if k < set.len() {
                return Primitive::Instanced(s, k);
            }
            k -= set.len();
        }
        Primitive::Ellipsoid(k)
    }

    fn add_tris(
        &mut self,
        tris: &[Tri],
        world_from_object: DAffine3,
        object: u32,
        material: impl Fn(&Tri) -> u32,
    ) {
        let m = world_from_object;
        let to_world = |p: Vec3| m.transform_point3(p.as_dvec3()).as_vec3();
        for tri in tris {
            let [a, b, c] = tri.p.map(to_world);
            // Degenerate triangles can never be hit; keeping them would only cost traversal time.
            if (b - a).cross(c - a).length_squared() == 0.0 {
                continue;
            }
            let rt = RtTriangle::new(a.into(), b.into(), c.into());
            self.triangles.push(rt);
            self.tri_attrs.push(TriAttr {
                uv: tri.uv,
                normal: geometric_normal(&rt),
                part: tri.part,
                object,
                material: material(tri),
            });
        }
    }

    fn add_ellipsoid(&mut self, world_from_object: DAffine3, object: u32, material: u32) {
        let world_from_object =
            Affine3A::from_cols_array(&world_from_object.to_cols_array().map(|v| v as f32));
        let object_from_world = world_from_object.inverse();
        self.ellipsoids.push(Ellipsoid {
            world_from_object,
            object_from_world,
            normal_from_object: object_from_world.matrix3.transpose(),
            object,
            material,
        });
    }

    fn add_obstacle(&mut self, obstacle: &Obstacle, geometry: bool) {
        self.objects.push(ObjectInfo {
            name: "obstacle".into(),
            views: view_bit::OCCLUDED | view_bit::SEETHRU,
            // The truth has no obstacle; a shadow only the other views had would be a
            // difference the compensation cannot be blamed for.
            casts_shadow: false,
        });
        self.obstacle_id = self.objects.len() as u32;
        if !geometry {
            return;
        }
        let body = self.materials.len() as u32;
        // Two materials: the body, then the switched-off display.
        for color in [obstacle.body_color, obstacle.display_off_color] {
            (self.materials).push(SurfaceMaterial::matte(srgb_to_linear3(color)));
        }
        let (tris, obstacle_from_box) = match obstacle.display_shape.curved() {
            Some(surface) => (
                crate::scene::curved_body::curved_obstacle_tris(surface, obstacle.thickness),
                DAffine3::IDENTITY,
            ),
            None => (
                cuboid([
                    obstacle.width as f32,
                    obstacle.height as f32,
                    obstacle.thickness as f32,
                ]),
                DAffine3::from_translation(DVec3::new(0.0, 0.0, -obstacle.thickness / 2.0)),
            ),
        };
        self.add_tris(
            &tris,
            obstacle.world_from_obstacle * obstacle_from_box,
            self.obstacle_id,
            |t| {
                if t.part == box_face::POS_Z {
                    body + 1
                } else {
                    body
                }
            },
        );
    }

    pub fn primitive_count(&self) -> usize {
        self.ellipsoid_base() + self.ellipsoids.len()
    }

    pub fn object_of(&self, prim: usize) -> u32 {
        match self.primitive(prim) {
            Primitive::Triangle(t) => self.tri_attrs[t].object,
            Primitive::Instanced(s, k) => {
                let set = &self.instanced[s];
                set.attrs[set.split(k).1].object
            }
            Primitive::Ellipsoid(e) => self.ellipsoids[e].object,
        }
    }

    /// Views that show primitive `prim` and whether it blocks sunlight.
    pub fn visibility(&self, prim: usize) -> (u8, bool) {
        let info = &self.objects[self.object_of(prim) as usize - 1];
        (info.views, info.casts_shadow)
    }

    pub fn aabb(&self, prim: usize) -> Aabb {
        match self.primitive(prim) {
            Primitive::Triangle(t) => self.triangles[t].aabb(),
            Primitive::Instanced(s, k) => self.instanced[s].triangle(k).0.aabb(),
            Primitive::Ellipsoid(e) => {
                // The unit sphere's box under an affine map: centre ± the rows' absolute sums.
                let m = &self.ellipsoids[e].world_from_object;
                let c = m.translation;
                let abs = Mat3A::from_cols(
                    m.matrix3.x_axis.abs(),
                    m.matrix3.y_axis.abs(),
                    m.matrix3.z_axis.abs(),
                );
                let r = abs * Vec3A::ONE;
                Aabb::new(c - r, c + r)
            }
        }
    }

    /// Ray parameter of the hit of `ray` (unit direction) with primitive `prim`, in
    /// [tmin, tmax], or infinity.
    #[inline(always)]
    pub fn intersect(&self, prim: usize, ray: &Ray) -> f32 {
        match self.primitive(prim) {
            Primitive::Triangle(t) => self.triangles[t].intersect(ray),
            Primitive::Instanced(s, k) => self.instanced[s].triangle(k).0.intersect(ray),
            Primitive::Ellipsoid(e) => {
                self.ellipsoids[e].intersect(ray.origin, ray.direction, ray.tmin, ray.tmax)
            }
        }
    }

    /// Details of the hit of a ray with primitive `prim` at parameter `t`.
    pub fn surface(&self, prim: usize, origin: Vec3, dir: Vec3, t: f32) -> SurfaceHit {
        let position = origin + dir * t;
        let textured = |material: u32| self.materials[material as usize].texture.is_some();
        let triangle = |tri: &RtTriangle, attr: &TriAttr, normal: Vec3| {
            let uv = if textured(attr.material) {
                let [v0, v1, v2] = vertices(tri);
                let [b0, b1, b2] = barycentric(position, v0, v1, v2);
                attr.uv[0] * b0 + attr.uv[1] * b1 + attr.uv[2] * b2
            } else {
                Vec2::ZERO
            };
            (normal, uv, attr.object, attr.part, attr.material)
        };
        let (normal, uv, object, part, material) = match self.primitive(prim) {
            Primitive::Triangle(t) => {
                let attr = &self.tri_attrs[t];
                triangle(&self.triangles[t], attr, attr.normal)
            }
            Primitive::Instanced(s, k) => {
                let (tri, attr) = self.instanced[s].triangle(k);
                triangle(&tri, attr, geometric_normal(&tri))
            }
            Primitive::Ellipsoid(e) => {
                let el = &self.ellipsoids[e];
                let local = el.object_from_world.transform_point3(position);
                let n = Vec3::from(el.normal_from_object * Vec3A::from(local)).normalize();
                let uv = if textured(el.material) {
                    // Equirectangular UVs: u around +y, v from the north pole down.
                    let u = 0.5 + local.z.atan2(local.x) / std::f32::consts::TAU;
                    let v = (local.y.clamp(-1.0, 1.0)).acos() / std::f32::consts::PI;
                    Vec2::new(u, v)
                } else {
                    Vec2::ZERO
                };
                (n, uv, el.object, 0, el.material)
            }
        };
        let normal = if normal.dot(dir) > 0.0 {
            -normal
        } else {
            normal
        };
        SurfaceHit {
            t,
            position,
            normal,
            uv,
            object,
            part,
            material,
        }
    }
}

/// What a primitive index names: a triangle, an instanced triangle (set, index within the
/// set) or an ellipsoid.
enum Primitive {
    Triangle(usize),
    Instanced(usize, usize),
    Ellipsoid(usize),
}

/// The corners of a triangle as the intersection test's edges give them back.
fn vertices(tri: &RtTriangle) -> [Vec3; 3] {
    let v0 = Vec3::from(tri.v0);
    [v0, v0 - Vec3::from(tri.e1), v0 + Vec3::from(tri.e2)]
}

/// Unit geometric normal of a triangle (counter-clockwise front), from its stored corners.
fn geometric_normal(tri: &RtTriangle) -> Vec3 {
    let [v0, v1, v2] = vertices(tri);
    (v1 - v0).cross(v2 - v0).normalize()
}

fn barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
    let (e0, e1, ep) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (ep.dot(e0), ep.dot(e1));
    let denom = d00 * d11 - d01 * d01;
    let v = (d11 * d20 - d01 * d21) / denom;
    let w = (d00 * d21 - d01 * d20) / denom;
    [1.0 - v - w, v, w]
}

impl Ellipsoid {
    /// Ray parameter of the first hit of the ray `origin + t dir` (unit `dir`, world frame)
    /// with the ellipsoid's surface in [tmin, tmax], or infinity.
    #[inline(always)]
    pub fn intersect(&self, origin: Vec3A, dir: Vec3A, tmin: f32, tmax: f32) -> f32 {
        let o = self.object_from_world.transform_point3a(origin);
        let d = self.object_from_world.transform_vector3a(dir);
        let a = d.dot(d);
        let b = o.dot(d);
        let c = o.dot(o) - 1.0;
        let disc = b * b - a * c;
        if disc < 0.0 {
            return f32::INFINITY;
        }
        let root = disc.sqrt();
        // The numerically stable pair of roots.
        let q = -(b + root.copysign(b));
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
        let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
        for t in [near, far] {
            if t >= tmin && t <= tmax {
                return t;
            }
        }
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A part (a sequence's static or moving objects) reads only the textures its objects use;
    /// the whole world reads them all.
    #[test]
    fn a_part_loads_only_the_textures_its_objects_use() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/das.toml");
        let scene = Scene::load(&path).expect("das loads");
        let textured = |m: &Option<usize>| m.is_some_and(|m| scene.materials[m].texture.is_some());
        let uses = |i: usize| textured(&scene.objects[i].material);
        let counts = |keep: &dyn Fn(usize) -> bool| {
            let world = World::build_part(&scene, keep, false).expect("the part builds");
            let indexed = world
                .materials
                .iter()
                .filter(|m| m.texture.is_some())
                .count();
            (world.textures.len(), indexed)
        };
        assert_eq!(counts(&|_| true), (1, 1));
        assert_eq!(counts(&uses), (1, 1));
        assert_eq!(counts(&|i| !uses(i)), (0, 0));

        // A textured scene material that replaces one of a mesh's own (`materials`): a part
        // of that mesh alone loads its texture.
        let mut scene = scene.clone();
        let street = (scene.materials.iter())
            .position(|m| m.texture.is_some())
            .unwrap();
        let car = scene.objects.iter().position(|o| o.name == "car").unwrap();
        scene.objects[car].file_materials = vec![("body".to_string(), street)];
        let world = World::build_part(&scene, &|i| i == car, false).expect("the part builds");
        let textured = world
            .materials
            .iter()
            .filter(|m| m.texture.is_some())
            .count();
        assert_eq!((world.textures.len(), textured), (1, 1));
    }
}
