//! Reading a scene file into a [`Scene`]: every table and key, typed, range-checked and
//! defaulted as `scenes/reference.toml` documents.

use std::path::{Path, PathBuf};

use glam::{DAffine3, DMat3, DQuat, DVec3, EulerRot};

use crate::geometry::camera::{Camera, world_from_camera_rotation};
use crate::scene::source::{SceneError, SourceFile};
use crate::scene::table_reader::TableReader;
use crate::scene::{CameraKind, Material, Object, Obstacle, Scene, Shape, Sky, Sun};

const OBJECT_KINDS: [&str; 7] = ["plane", "box", "sphere", "cylinder", "cone", "quad", "mesh"];
/// Largest length accepted anywhere in a scene, metres: beyond it f32 ray tracing loses
/// millimetre precision.
const MAX_LENGTH: f64 = 100_000.0;

impl Scene {
    /// Reads and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let file = SourceFile::read(path)?;
        Self::from_source(&file)
    }

    pub fn from_source(file: &SourceFile) -> Result<Scene, SceneError> {
        let doc = file.parse()?;
        let root = TableReader::root(file, &doc);
        let sun = read_sun(&root)?;
        let sky = read_sky(&root)?;
        let materials = read_materials(&root, file)?;
        let objects = root
            .array_of_tables("object")?
            .into_iter()
            .map(|t| read_object(t, &materials, file))
            .collect::<Result<Vec<_>, _>>()?;
        let obstacle_table = root
            .table("obstacle")?
            .ok_or_else(|| root.error("obstacle", "the scene needs an [obstacle] table"))?;
        let obstacle = read_obstacle(&obstacle_table)?;
        obstacle_table.finish()?;
        let cameras = root.table("camera")?.ok_or_else(|| {
            root.error(
                "camera",
                "the scene needs [camera.driver], [camera.frontal] and [camera.back]",
            )
        })?;
        let driver = read_driver(&cameras, &obstacle)?;
        let frontal = read_frontal(&cameras, &obstacle)?;
        let back = read_back(&cameras, &obstacle)?;
        cameras.finish()?;
        root.finish()?;
        Ok(Scene {
            path: file.path.clone(),
            sun,
            sky,
            materials,
            objects,
            obstacle,
            driver,
            frontal,
            back,
        })
    }
}

fn dvec3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

fn read_sun(root: &TableReader) -> Result<Sun, SceneError> {
    let d = Sun::default();
    let Some(t) = root.table("sun")? else {
        return Ok(d);
    };
    let direction = dvec3(t.array_or("direction", d.direction.to_array())?);
    if direction.length() < 1e-9 {
        return Err(t.error("direction", "must not be the zero vector"));
    }
    let sun = Sun {
        direction: direction.normalize(),
        color: t.color("color", d.color)?,
        intensity: t.f64_in("intensity", d.intensity, 0.0, 1000.0)?,
    };
    t.finish()?;
    Ok(sun)
}

fn read_sky(root: &TableReader) -> Result<Sky, SceneError> {
    let d = Sky::default();
    let Some(t) = root.table("sky")? else {
        return Ok(d);
    };
    let sky = Sky {
        zenith_color: t.color("zenith_color", d.zenith_color)?,
        horizon_color: t.color("horizon_color", d.horizon_color)?,
        ground_color: t.color("ground_color", d.ground_color)?,
        ambient: t.f64_in("ambient", d.ambient, 0.0, 1000.0)?,
        cloud_cover: t.f64_in("cloud_cover", d.cloud_cover, 0.0, 1.0)?,
        cloud_height: t.positive("cloud_height", d.cloud_height, MAX_LENGTH)?,
        cloud_size: t.positive("cloud_size", d.cloud_size, MAX_LENGTH)?,
        cloud_seed: t.usize_in("cloud_seed", d.cloud_seed as usize, 0, u32::MAX as usize)? as u32,
    };
    t.finish()?;
    Ok(sky)
}

fn read_materials(root: &TableReader, file: &SourceFile) -> Result<Vec<Material>, SceneError> {
    let mut materials: Vec<Material> = Vec::new();
    for t in root.array_of_tables("material")? {
        let name = t.required_str("name")?.to_string();
        if materials.iter().any(|m| m.name == name) {
            return Err(t.error("name", format!("material `{name}` is defined twice")));
        }
        let texture = match t.opt_str("texture")? {
            Some(rel) => Some(existing_asset(&t, "texture", rel, file)?),
            None => None,
        };
        materials.push(Material {
            name,
            color: t.color("color", [0.8, 0.8, 0.8])?,
            texture,
            uv_repeat: t.positive_array("uv_repeat", [1.0, 1.0])?,
        });
        t.finish()?;
    }
    Ok(materials)
}

/// Resolves an asset path relative to the scene file and checks that it exists.
fn existing_asset(
    t: &TableReader,
    key: &str,
    rel: &str,
    file: &SourceFile,
) -> Result<PathBuf, SceneError> {
    let path = file.dir().join(rel);
    if !path.is_file() {
        return Err(t.error(key, format!("asset not found: {}", path.display())));
    }
    Ok(path)
}

fn read_transform(t: &TableReader) -> Result<DAffine3, SceneError> {
    let translate = dvec3(t.array_or("translate", [0.0; 3])?);
    let [rx, ry, rz] = t.array_or("rotate_deg", [0.0; 3])?;
    let scale = match t.opt_f64("scale") {
        Ok(Some(s)) => [s; 3],
        Ok(None) => [1.0; 3],
        Err(_) => t.required_array("scale")?,
    };
    if scale.iter().any(|&s| !(s > 0.0 && s <= MAX_LENGTH)) {
        return Err(t.error(
            "scale",
            format!("every factor must be in (0, {MAX_LENGTH}], got {scale:?}"),
        ));
    }
    if translate.abs().max_element() > MAX_LENGTH {
        return Err(t.error(
            "translate",
            format!("coordinates must be within ±{MAX_LENGTH} m"),
        ));
    }
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

fn read_object(
    t: TableReader,
    materials: &[Material],
    file: &SourceFile,
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
    let shape = match kind {
        "plane" => Shape::Plane {
            size: t.positive_array("size", [200.0, 200.0])?,
        },
        "box" => Shape::Box {
            size: t.positive_array("size", [1.0, 1.0, 1.0])?,
        },
        "sphere" => Shape::Sphere {
            radius: t.positive("radius", 0.5, MAX_LENGTH)?,
        },
        "cylinder" => Shape::Cylinder {
            radius: t.positive("radius", 0.5, MAX_LENGTH)?,
            height: t.positive("height", 1.0, MAX_LENGTH)?,
            segments: segments(&t)?,
        },
        "cone" => Shape::Cone {
            radius: t.positive("radius", 0.5, MAX_LENGTH)?,
            height: t.positive("height", 1.0, MAX_LENGTH)?,
            segments: segments(&t)?,
        },
        "quad" => Shape::Quad {
            size: t.positive_array("size", [1.0, 1.0])?,
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
                path: existing_asset(&t, "path", rel, file)?,
            }
        }
    };
    let material = match t.opt_str("material")? {
        Some(m) => Some(materials.iter().position(|x| x.name == m).ok_or_else(|| {
            let names: Vec<&str> = materials.iter().map(|x| x.name.as_str()).collect();
            t.error(
                "material",
                format!("no material named `{m}` (defined: {})", names.join(", ")),
            )
        })?),
        None if matches!(shape, Shape::Mesh { .. }) => None,
        None => {
            return Err(t.error(
                "material",
                "required key is missing (only meshes may omit it)",
            ));
        }
    };
    let hidden = t.str_list("hidden_from", &CameraKind::NAMES)?;
    let visible_to = hidden
        .iter()
        .fold(0b111u8, |mask, name| mask & !CameraKind::parse(name).bit());
    let object = Object {
        name,
        shape,
        material,
        world_from_object: read_transform(&t)?,
        visible_to,
        casts_shadow: t.bool_or("casts_shadow", true)?,
    };
    t.finish()?;
    Ok(object)
}

fn read_obstacle(t: &TableReader) -> Result<Obstacle, SceneError> {
    let center = dvec3(t.required_array("center")?);
    let facing = dvec3(t.array_or("facing", [0.0, 0.0, 1.0])?);
    let up = dvec3(t.array_or("up", [0.0, 1.0, 0.0])?);
    // The display normal is obstacle +z; a camera looking along −facing has the same axes.
    let rotation = world_from_camera_rotation(-facing, up)
        .map_err(|_| t.error("facing", "must be non-zero and not parallel to `up`"))?;
    Ok(Obstacle {
        world_from_obstacle: DAffine3::from_mat3_translation(rotation, center),
        width: t.positive("width", 0.3, 100.0)?,
        height: t.positive("height", 0.4, 100.0)?,
        thickness: t.positive("thickness", 0.04, 100.0)?,
        display_resolution: t.resolution("display_resolution", [300, 400])?,
        display_off_color: t.color("display_off_color", [0.02, 0.02, 0.025])?,
        body_color: t.color("body_color", [0.18, 0.18, 0.2])?,
    })
}

fn half_angle(t: &TableReader, default_deg: f64) -> Result<f64, SceneError> {
    let deg = t.opt_f64("half_angle_deg")?.unwrap_or(default_deg);
    if !(deg > 0.0 && deg < 89.0) {
        return Err(t.error(
            "half_angle_deg",
            format!("must be in (0, 89) degrees, got {deg}"),
        ));
    }
    Ok(deg.to_radians())
}

fn camera_table<'a>(cameras: &TableReader<'a>, name: &str) -> Result<TableReader<'a>, SceneError> {
    cameras
        .table(name)?
        .ok_or_else(|| cameras.error(name, format!("the scene needs a [camera.{name}] table")))
}

fn read_driver(cameras: &TableReader, obstacle: &Obstacle) -> Result<Camera, SceneError> {
    let t = camera_table(cameras, "driver")?;
    let eye = dvec3(t.required_array("position")?);
    let target = dvec3(t.required_array("look_at")?);
    let up = dvec3(t.array_or("up", [0.0, 1.0, 0.0])?);
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
            format!("the driver's eye must be on the display's side of the obstacle (d1 > 0 m along the display normal), got d1 = {d1:.3} m"),
        ));
    }
    t.finish()?;
    Ok(camera)
}

/// A camera mounted on the obstacle: pose from an offset (obstacle frame) and yaw/pitch about
/// a base viewing direction.
fn mounted_camera(
    t: &TableReader,
    obstacle: &Obstacle,
    default_offset: [f64; 3],
    base: DMat3,
    default_half_deg: f64,
    default_res: [u32; 2],
) -> Result<Camera, SceneError> {
    let offset = dvec3(t.array_or("offset", default_offset)?);
    let yaw = t.f64_in("yaw_deg", 0.0, -80.0, 80.0)?.to_radians();
    let pitch = t.f64_in("pitch_deg", 0.0, -80.0, 80.0)?.to_radians();
    let [w, h] = t.resolution("resolution", default_res)?;
    let obstacle_from_camera = DAffine3::from_mat3_translation(
        base * DMat3::from_rotation_y(yaw) * DMat3::from_rotation_x(pitch),
        offset,
    );
    Camera::new(
        obstacle.world_from_obstacle * obstacle_from_camera,
        half_angle(t, default_half_deg)?,
        w,
        h,
    )
    .map_err(|e| t.error("half_angle_deg", e.to_string()))
}

fn read_frontal(cameras: &TableReader, obstacle: &Obstacle) -> Result<Camera, SceneError> {
    let t = camera_table(cameras, "frontal")?;
    // Camera −z along obstacle −z: the identity rotation.
    let camera = mounted_camera(
        &t,
        obstacle,
        [0.0, 0.0, 0.0],
        DMat3::IDENTITY,
        45.0,
        [1280, 720],
    )?;
    let z = obstacle
        .world_from_obstacle
        .inverse()
        .transform_point3(camera.position())
        .z;
    if z > 1e-9 {
        return Err(t.error("offset", format!("the frontal camera must be on the scene side of the display (z ≤ 0 in the obstacle frame), got z = {z:.3} m")));
    }
    t.finish()?;
    Ok(camera)
}

fn read_back(cameras: &TableReader, obstacle: &Obstacle) -> Result<Camera, SceneError> {
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
    )?;
    t.finish()?;
    Ok(camera)
}
