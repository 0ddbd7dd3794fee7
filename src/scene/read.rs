//! Reading a scene file into a [`Scene`]: every table and key, typed, range-checked and
//! defaulted as `scenes/reference.toml` documents.

use std::collections::HashMap;
use std::path::Path;

use glam::{DAffine3, DMat3, DQuat, DVec3, EulerRot};

use crate::geometry::camera::{Camera, world_from_camera_rotation};
use crate::scene::coat_keys::read_coat;
use crate::scene::light_keys::{read_photometry, read_sky, read_sun};
use crate::scene::limits::{
    MAX_DISPLAY_SIZE, MAX_LENGTH, MAX_MATERIALS, MAX_MOUNT_OFFSET, MAX_OBJECTS, MAX_ROTATION_DEG,
    MAX_TRIANGLES, MAX_UV_REPEAT, MIN_LENGTH, out_of_world,
};
use crate::scene::motion::read_object_motion;
use crate::scene::source::{SceneError, SourceFile};
use crate::scene::table_reader::TableReader;
use crate::scene::{CameraKind, DriverFace, Material, Object, Obstacle, Photometry, Scene, Shape};

const OBJECT_KINDS: [&str; 7] = ["plane", "box", "sphere", "cylinder", "cone", "quad", "mesh"];

impl Scene {
    /// A scene of the repository's `scenes/` folder, for unit tests.
    #[cfg(test)]
    pub(crate) fn bundled(name: &str) -> Scene {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(name);
        Scene::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
    }

    /// Reads and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let file = SourceFile::read(path)?;
        Self::from_source(&file)
    }

    pub fn from_source(file: &SourceFile) -> Result<Scene, SceneError> {
        let doc = file.parse()?;
        let root = TableReader::root(file, &doc);
        let (sun, sun_lux) = read_sun(&root)?;
        let (sky, zenith_cd_m2) = read_sky(&root, sun_lux)?;
        let photometry = read_photometry(&root, &sun, &sky, sun_lux, zenith_cd_m2)?;
        let lights = crate::scene::light_keys::read_lights(&root, photometry.as_ref())?;
        let materials = read_materials(&root)?;
        let mut objects = read_objects(&root, &materials)?;
        let road = crate::scene::road_keys::read_road(&root, &objects)?;
        let mut warnings = Vec::new();
        let ego_route = road.and_then(|road| {
            objects.push(road.object);
            warnings = road.warnings;
            road.route
        });
        let obstacle_table = root
            .table("obstacle")?
            .ok_or_else(|| root.error("obstacle", "the scene needs an [obstacle] table"))?;
        let obstacle = read_obstacle(&obstacle_table, file, photometry.as_ref())?;
        obstacle_table.finish()?;
        let cameras = root.table("camera")?.ok_or_else(|| {
            root.error(
                "camera",
                "the scene needs [camera.driver], [camera.frontal] and [camera.back]",
            )
        })?;
        let eyellipse = crate::scene::eyellipse_keys::read_eyellipse(&root)?;
        let (driver, face) = read_driver(&cameras, &obstacle, eyellipse.as_ref(), &objects)?;
        if let Some(head) = face_object(face, driver.position()) {
            objects.push(head);
        }
        let frontal = read_frontal(&cameras, &obstacle, photometry.as_ref())?;
        let back = read_back(&cameras, &obstacle, photometry.as_ref())?;
        cameras.finish()?;
        let calibration = crate::scene::lens_keys::read_calibration(&root, &frontal, &back)?;
        root.finish()?;
        Ok(Scene {
            path: file.path.clone(),
            source_hash: file.content_hash(),
            sun,
            sky,
            photometry,
            lights,
            materials,
            objects,
            obstacle,
            driver,
            frontal,
            back,
            calibration,
            eyellipse,
            face,
            ego_route,
            warnings,
        })
    }
}

fn dvec3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

/// A length in [[`MIN_LENGTH`], `max`] metres.
fn length(t: &TableReader, key: &str, default: f64, max: f64) -> Result<f64, SceneError> {
    t.f64_in(key, default, MIN_LENGTH, max)
}

/// The tables of `[[key]]`, at most `limit` of them.
fn bounded_tables<'a>(
    root: &TableReader<'a>,
    key: &str,
    limit: usize,
) -> Result<Vec<TableReader<'a>>, SceneError> {
    let tables = root.array_of_tables(key)?;
    if tables.len() > limit {
        return Err(tables[limit].table_error(format!(
            "the scene has {} [[{key}]] tables, more than the limit of {limit}",
            tables.len()
        )));
    }
    Ok(tables)
}

fn read_materials(root: &TableReader) -> Result<Vec<Material>, SceneError> {
    let mut materials: Vec<Material> = Vec::new();
    let mut first_line: HashMap<String, Option<usize>> = HashMap::new();
    for (i, t) in bounded_tables(root, "material", MAX_MATERIALS)?
        .into_iter()
        .enumerate()
    {
        let name = t.required_str("name")?.to_string();
        let line = t.error("name", "").line;
        if let Some(first) = first_line.insert(name.clone(), line) {
            let at = first.map_or(String::new(), |l| format!(" at line {l}"));
            return Err(t.error(
                "name",
                format!("material `{name}` is defined twice: material[{i}] repeats the name of an earlier material{at}"),
            ));
        }
        let texture = match t.opt_str("texture")? {
            Some(rel) => Some(t.existing_asset("texture", rel)?),
            None => None,
        };
        let (specular, roughness) = read_coat(&t)?;
        materials.push(Material {
            name,
            color: t.color("color", [0.8, 0.8, 0.8])?,
            texture,
            uv_repeat: t.array_in("uv_repeat", [1.0, 1.0], MIN_LENGTH, MAX_UV_REPEAT)?,
            specular,
            roughness,
        });
        t.finish()?;
    }
    Ok(materials)
}

/// Resolves an asset path relative to the scene file and checks that it exists.
fn read_transform(t: &TableReader) -> Result<DAffine3, SceneError> {
    let (translate, [rx, ry, rz], scale) = read_placement(t)?;
    // Rotations apply about x, then y, then z (world axes).
    let rotation = DQuat::from_euler(
        EulerRot::ZYX,
        rz.to_radians(),
        ry.to_radians(),
        rx.to_radians(),
    );
    Ok(DAffine3::from_scale_rotation_translation(
        dvec3(scale),
        rotation,
        translate,
    ))
}

/// `translate`, `rotate_deg` and `scale` of an object table.
fn read_placement(t: &TableReader) -> Result<(DVec3, [f64; 3], [f64; 3]), SceneError> {
    let translate = t.point("translate", Some([0.0; 3]))?;
    let [rx, ry, rz] = t.array_in("rotate_deg", [0.0; 3], -MAX_ROTATION_DEG, MAX_ROTATION_DEG)?;
    // One factor or three, each in [MIN_LENGTH, MAX_LENGTH].
    let scale = if t.is_number("scale") {
        [t.f64_in("scale", 1.0, MIN_LENGTH, MAX_LENGTH)?; 3]
    } else {
        t.array_in("scale", [1.0; 3], MIN_LENGTH, MAX_LENGTH)?
    };
    Ok((translate, [rx, ry, rz], scale))
}

/// Reads every `[[object]]`, within the limits on objects and triangles.
fn read_objects(root: &TableReader, materials: &[Material]) -> Result<Vec<Object>, SceneError> {
    let by_name: HashMap<&str, usize> = materials
        .iter()
        .enumerate()
        .map(|(i, m)| (m.name.as_str(), i))
        .collect();
    let mut triangles = 0usize;
    let mut objects = Vec::new();
    // Names given explicitly are unique (measurements and exports find objects by them);
    // the default, the kind, may repeat.
    let mut named: HashMap<String, Option<usize>> = HashMap::new();
    for (i, t) in bounded_tables(root, "object", MAX_OBJECTS)?
        .into_iter()
        .enumerate()
    {
        let object = read_object(&t, materials, &by_name)?;
        if let Some(name) = t.opt_str("name")?
            && let Some(first) = named.insert(name.to_string(), t.error("name", "").line)
        {
            let at = first.map_or(String::new(), |l| format!(" at line {l}"));
            return Err(t.error(
                "name",
                format!("object `{name}` is named twice: object[{i}] repeats the name of an earlier object{at}"),
            ));
        }
        triangles += triangle_count(&object.shape);
        if triangles > MAX_TRIANGLES {
            return Err(t.table_error(format!(
                "the scene's shapes reach {triangles} triangles here, more than the limit of {MAX_TRIANGLES}"
            )));
        }
        if let Some(why) = object_bounds(&object.shape)
            .into_iter()
            .find_map(|corner| out_of_world(object.world_from_object.transform_point3(corner)))
        {
            return Err(t.table_error(format!(
                "the {} `{}` reaches outside the world after its transform: {why} (check translate, scale and size)",
                Shape::kind(&object.shape),
                object.name
            )));
        }
        t.finish()?;
        objects.push(object);
    }
    Ok(objects)
}

/// Triangles a shape tessellates into (meshes are counted when they are loaded).
fn triangle_count(shape: &Shape) -> usize {
    match shape {
        Shape::Plane { .. } | Shape::Quad { .. } => 2,
        Shape::Box { .. } => 12,
        Shape::Sphere { .. } | Shape::Mesh { .. } | Shape::HeadMesh | Shape::Road { .. } => 0,
        Shape::Cylinder { segments, .. } => 4 * segments,
        Shape::Cone { segments, .. } => 2 * segments,
    }
}

/// Corners of a box around the shape in object space (empty for meshes: their vertices are
/// checked when the mesh is loaded).
fn object_bounds(shape: &Shape) -> Vec<DVec3> {
    let (lo, hi) = match *shape {
        Shape::Plane { size: [x, z] } => {
            (DVec3::new(-x, 0.0, -z) / 2.0, DVec3::new(x, 0.0, z) / 2.0)
        }
        Shape::Box { size } => (-dvec3(size) / 2.0, dvec3(size) / 2.0),
        Shape::Sphere { radius } => (DVec3::splat(-radius), DVec3::splat(radius)),
        Shape::Cylinder { radius, height, .. } | Shape::Cone { radius, height, .. } => (
            DVec3::new(-radius, 0.0, -radius),
            DVec3::new(radius, height, radius),
        ),
        Shape::Quad { size: [x, y] } => {
            (DVec3::new(-x, -y, 0.0) / 2.0, DVec3::new(x, y, 0.0) / 2.0)
        }
        Shape::Mesh { .. } | Shape::HeadMesh | Shape::Road { .. } => return Vec::new(),
    };
    (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect()
}

fn read_object(
    t: &TableReader,
    materials: &[Material],
    by_name: &HashMap<&str, usize>,
) -> Result<Object, SceneError> {
    let kind = t.choice("kind", "", &OBJECT_KINDS).map_err(|e| {
        if t.has("kind") {
            e
        } else {
            t.error(
                "kind",
                format!(
                    "required key is missing (one of: {})",
                    OBJECT_KINDS.join(", ")
                ),
            )
        }
    })?;
    let name = t.opt_str("name")?.unwrap_or(kind).to_string();
    let segments = |t: &TableReader| t.usize_in("segments", 48, 3, 4096);
    let size = |default| t.array_in("size", default, MIN_LENGTH, MAX_LENGTH);
    let shape = match kind {
        "plane" => Shape::Plane {
            size: size([200.0, 200.0])?,
        },
        "box" => Shape::Box {
            size: t.array_in("size", [1.0, 1.0, 1.0], MIN_LENGTH, MAX_LENGTH)?,
        },
        "sphere" => Shape::Sphere {
            radius: length(t, "radius", 0.5, MAX_LENGTH)?,
        },
        "cylinder" => Shape::Cylinder {
            radius: length(t, "radius", 0.5, MAX_LENGTH)?,
            height: length(t, "height", 1.0, MAX_LENGTH)?,
            segments: segments(t)?,
        },
        "cone" => Shape::Cone {
            radius: length(t, "radius", 0.5, MAX_LENGTH)?,
            height: length(t, "height", 1.0, MAX_LENGTH)?,
            segments: segments(t)?,
        },
        "quad" => Shape::Quad {
            size: size([1.0, 1.0])?,
        },
        _ => {
            let rel = t.required_str("path")?;
            let lower = rel.to_ascii_lowercase();
            if ![".obj", ".gltf", ".glb"]
                .iter()
                .any(|ext| lower.ends_with(ext))
            {
                return Err(t.error(
                    "path",
                    format!("`{rel}`: mesh files must be .obj, .gltf or .glb"),
                ));
            }
            Shape::Mesh {
                path: t.existing_asset("path", rel)?,
            }
        }
    };
    // A scene material by name, or an error at `key` that lists the defined ones.
    let scene_material = |t: &TableReader, key: &str, m: &str| {
        by_name.get(m).copied().ok_or_else(|| {
            let mut names: Vec<&str> = materials.iter().map(|x| x.name.as_str()).take(20).collect();
            if materials.len() > names.len() {
                names.push("…");
            }
            t.error(
                key,
                format!("no material named `{m}` (defined: {})", names.join(", ")),
            )
        })
    };
    let file_materials = match t.table("materials")? {
        None => Vec::new(),
        Some(_) if !matches!(shape, Shape::Mesh { .. }) => {
            return Err(t.error(
                "materials",
                "replaces a mesh file's materials by name: only a `mesh` object has them",
            ));
        }
        Some(_) if t.has("material") => {
            return Err(t.error(
                "materials",
                "`material` already replaces every material of the file: give one of the two",
            ));
        }
        Some(table) => {
            let mut pairs = Vec::new();
            for file_name in table.keys() {
                let m = table.required_str(file_name)?;
                pairs.push((file_name.to_string(), scene_material(&table, file_name, m)?));
            }
            table.finish()?;
            pairs
        }
    };
    let material = match t.opt_str("material")? {
        Some(m) => Some(scene_material(t, "material", m)?),
        None if matches!(shape, Shape::Mesh { .. }) => None,
        None => {
            return Err(t.error(
                "material",
                "required key is missing (only meshes may omit it)",
            ));
        }
    };
    let hidden = t.str_list("hidden_from", &CameraKind::NAMES)?;
    let visible_to = hidden.iter().fold(CameraKind::ALL, |mask, name| {
        mask & !CameraKind::parse(name).bit()
    });
    let shape_for_bounds = shape.clone();
    let instances = read_instances(t, &shape)?;
    let motion = {
        let (translate, rotate_deg, scale) = read_placement(t)?;
        let corners = object_bounds(&shape_for_bounds);
        read_object_motion(t, translate, dvec3(rotate_deg), dvec3(scale), &corners)?
    };
    if !instances.is_empty() && motion.moves() {
        return Err(t.error(
            "instances",
            "an instanced object cannot move (keyframes, moves_with): instances are static",
        ));
    }
    Ok(Object {
        name,
        shape,
        material,
        file_materials,
        world_from_object: read_transform(t)?,
        visible_to,
        casts_shadow: t.bool_or("casts_shadow", true)?,
        hazard: t.bool_or("hazard", false)?,
        motion,
        instances,
    })
}

/// `instances`: the placements file of a mesh object ([`crate::scene::instances`]).
fn read_instances(t: &TableReader, shape: &Shape) -> Result<Vec<[f64; 4]>, SceneError> {
    let Some(rel) = t.opt_str("instances")? else {
        return Ok(Vec::new());
    };
    if !matches!(shape, Shape::Mesh { .. }) {
        return Err(t.error(
            "instances",
            "only a mesh object (kind = \"mesh\") can be instanced",
        ));
    }
    let path = t.existing_asset("instances", rel)?;
    crate::scene::instances::read_placements(&path, rel)
        .map_err(|e| t.error("instances", format!("{e:#}")))
}

fn read_obstacle(
    t: &TableReader,
    file: &SourceFile,
    photometry: Option<&Photometry>,
) -> Result<Obstacle, SceneError> {
    let center = t.point("center", None)?;
    let facing = t.direction("facing", [0.0, 0.0, 1.0])?;
    let up = t.direction("up", [0.0, 1.0, 0.0])?;
    // The display normal is obstacle +z; a camera looking along −facing has the same axes.
    let rotation = world_from_camera_rotation(-facing, up)
        .map_err(|_| t.error("facing", "must not be parallel to `up`"))?;
    let (width, height) = (
        length(t, "width", 0.3, MAX_DISPLAY_SIZE)?,
        length(t, "height", 0.4, MAX_DISPLAY_SIZE)?,
    );
    let obstacle = Obstacle {
        world_from_obstacle: DAffine3::from_mat3_translation(rotation, center),
        width,
        height,
        thickness: length(t, "thickness", 0.04, MAX_DISPLAY_SIZE)?,
        display_resolution: t.resolution("display_resolution", [300, 400])?,
        display_off_color: t.color("display_off_color", [0.02, 0.02, 0.025])?,
        body_color: t.color("body_color", [0.18, 0.18, 0.2])?,
        display_shape: crate::scene::display_keys::read_display_shape(t, file, width, height)?,
        scanout: crate::scene::shutter_keys::read_scanout(t)?,
        display_light: crate::scene::light_keys::read_display_light(t, photometry)?,
    };
    let half = DVec3::new(obstacle.width, obstacle.height, 2.0 * obstacle.thickness) / 2.0;
    let curved = crate::scene::display_keys::surface_corners(&obstacle.display_shape);
    for corner in [-half, half].into_iter().chain(curved) {
        if let Some(why) = out_of_world(obstacle.world_from_obstacle.transform_point3(corner)) {
            return Err(t.error(
                "center",
                format!("the obstacle reaches outside the world: {why}"),
            ));
        }
    }
    Ok(obstacle)
}

/// Narrowest half angle of view, degrees: below it, projections overflow f32 pixel
/// coordinates.
pub const MIN_HALF_ANGLE_DEG: f64 = 0.01;
/// Widest half angle of view, degrees (a pinhole camera cannot reach 90°).
pub const MAX_HALF_ANGLE_DEG: f64 = 89.0;

fn half_angle(t: &TableReader, default_deg: f64) -> Result<f64, SceneError> {
    Ok(t.f64_in(
        "half_angle_deg",
        default_deg,
        MIN_HALF_ANGLE_DEG,
        MAX_HALF_ANGLE_DEG,
    )?
    .to_radians())
}

fn camera_table<'a>(cameras: &TableReader<'a>, name: &str) -> Result<TableReader<'a>, SceneError> {
    cameras
        .table(name)?
        .ok_or_else(|| cameras.error(name, format!("the scene needs a [camera.{name}] table")))
}

/// The driver's eye (`[camera.driver]`) and face (`face`, `face_yaw_deg`). `objects` are the
/// file's own: with the mesh face, none of them may be named `head` (that is the mesh's name;
/// an object `head` is a face of the file's own, as das's ellipsoid head is).
fn read_driver(
    cameras: &TableReader,
    obstacle: &Obstacle,
    eyellipse: Option<&crate::scene::eyellipse::Eyellipse>,
    objects: &[Object],
) -> Result<(Camera, DriverFace), SceneError> {
    let t = camera_table(cameras, "driver")?;
    // Without a position, the eye is the eyellipse's centre (the cyclopean eye J941 places).
    let eye = t.point("position", eyellipse.map(|e| e.centre.to_array()))?;
    let target = t.point("look_at", None)?;
    let up = t.direction("up", [0.0, 1.0, 0.0])?;
    let [w, h] = t.resolution("resolution", [1280, 720])?;
    let camera = Camera::look_at(eye, target, up, half_angle(&t, 40.0)?, w, h)
        .map_err(|e| t.error("look_at", e.to_string()))?;
    let d1 = obstacle
        .world_from_obstacle
        .inverse()
        .transform_point3(eye)
        .z;
    if d1 <= 0.0 {
        return Err(t.error(
            "position",
            format!("the driver's eye must be on the display's side of the obstacle (d1 > 0 m along the display normal), got d1 = {} m", crate::util::number::short(d1)),
        ));
    }
    let face = match t.choice("face", "ellipsoids", &DriverFace::NAMES)? {
        "mesh" => {
            if objects.iter().any(|o| o.name == FACE_MESH_NAME) {
                return Err(t.error(
                    "face",
                    format!("`mesh` adds the head mesh as the object `{FACE_MESH_NAME}`, but the scene has an [[object]] named `{FACE_MESH_NAME}` (a face of its own): remove the file's face objects, or rename that object"),
                ));
            }
            DriverFace::Mesh {
                yaw_deg: t.f64_in("face_yaw_deg", 0.0, -MAX_FACE_YAW_DEG, MAX_FACE_YAW_DEG)?,
            }
        }
        _ => {
            if t.has("face_yaw_deg") {
                return Err(t.error(
                    "face_yaw_deg",
                    "turns the head mesh: only with face = \"mesh\" (the ellipsoid face is the file's own objects; turn them with rotate_deg)",
                ));
            }
            DriverFace::Ellipsoids
        }
    };
    t.finish()?;
    Ok((camera, face))
}

/// The object the mesh face adds ([`DriverFace::Mesh`]).
pub const FACE_MESH_NAME: &str = "head";

/// Largest `face_yaw_deg`, degrees: the yaw fit's search range about facing the back camera.
pub const MAX_FACE_YAW_DEG: f64 = 80.0;

/// The head mesh of the mesh face: its eye point (the midpoint of the pupils, the mesh's
/// origin) at the driver's eye `eye` (world), turned by the face's yaw, hidden from the
/// driver, riding with the head in sequences. `None` for the ellipsoid face.
pub fn face_object(face: DriverFace, eye: DVec3) -> Option<Object> {
    let DriverFace::Mesh { yaw_deg } = face else {
        return None;
    };
    Some(Object {
        name: FACE_MESH_NAME.to_string(),
        shape: Shape::HeadMesh,
        material: None,
        file_materials: Vec::new(),
        world_from_object: DAffine3::from_translation(eye)
            * DAffine3::from_rotation_y(yaw_deg.to_radians()),
        visible_to: CameraKind::ALL & !CameraKind::Driver.bit(),
        casts_shadow: true,
        hazard: false,
        motion: crate::scene::motion::ObjectMotion {
            moves_with: crate::scene::motion::MovesWith::Head,
            keyframes: Vec::new(),
            scale: DVec3::ONE,
            places: Vec::new(),
        },
        instances: Vec::new(),
    })
}

/// A camera mounted on the obstacle: pose from an offset (obstacle frame) and yaw/pitch about
/// a base viewing direction, its lens and its shutter.
fn mounted_camera(
    t: &TableReader,
    obstacle: &Obstacle,
    default_offset: [f64; 3],
    base: DMat3,
    default_half_deg: f64,
    default_res: [u32; 2],
    photometry: Option<&Photometry>,
) -> Result<Camera, SceneError> {
    let offset = dvec3(t.array_in(
        "offset",
        default_offset,
        -MAX_MOUNT_OFFSET,
        MAX_MOUNT_OFFSET,
    )?);
    let yaw = t.f64_in("yaw_deg", 0.0, -80.0, 80.0)?.to_radians();
    let pitch = t.f64_in("pitch_deg", 0.0, -80.0, 80.0)?.to_radians();
    let [w, h] = t.resolution("resolution", default_res)?;
    let obstacle_from_camera = DAffine3::from_mat3_translation(
        base * DMat3::from_rotation_y(yaw) * DMat3::from_rotation_x(pitch),
        offset,
    );
    let camera = crate::scene::lens_keys::read_lens_camera(
        t,
        obstacle.world_from_obstacle * obstacle_from_camera,
        || half_angle(t, default_half_deg),
        w,
        h,
    )?;
    let shutter = crate::scene::shutter_keys::read_shutter(t)?;
    Ok(Camera {
        shutter,
        sensor: crate::scene::sensor_keys::read_sensor(t, &shutter, photometry)?,
        ..camera
    })
}

fn read_frontal(
    cameras: &TableReader,
    obstacle: &Obstacle,
    photometry: Option<&Photometry>,
) -> Result<Camera, SceneError> {
    let t = camera_table(cameras, "frontal")?;
    // Camera −z along obstacle −z: the identity rotation.
    let camera = mounted_camera(
        &t,
        obstacle,
        [0.0, 0.0, 0.0],
        DMat3::IDENTITY,
        45.0,
        [1280, 720],
        photometry,
    )?;
    let z = obstacle
        .world_from_obstacle
        .inverse()
        .transform_point3(camera.position())
        .z;
    if z > 1e-9 {
        return Err(t.error("offset", format!("the frontal camera must be on the scene side of the display (z ≤ 0 in the obstacle frame), got z = {} m", crate::util::number::short(z))));
    }
    if camera.sensor.is_some_and(|s| s.coding.is_some()) && obstacle.display_light.is_none() {
        return Err(t.error(
            "tone_curve",
            "makes the frontal camera deliver codes, which only a display with a light turns into light: give [obstacle] display_peak_cd_m2 (and display_transfer)",
        ));
    }
    t.finish()?;
    Ok(camera)
}

fn read_back(
    cameras: &TableReader,
    obstacle: &Obstacle,
    photometry: Option<&Photometry>,
) -> Result<Camera, SceneError> {
    let t = camera_table(cameras, "back")?;
    // Camera −z along obstacle +z (towards the driver): half a turn about y.
    let base = DMat3::from_rotation_y(std::f64::consts::PI);
    let camera = mounted_camera(
        &t,
        obstacle,
        [0.0, obstacle.height / 2.0, 0.0],
        base,
        35.0,
        [640, 480],
        photometry,
    )?;
    t.finish()?;
    Ok(camera)
}
