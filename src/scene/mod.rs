//! The scene description: what a scene file says, typed, validated and in world units.
//!
//! World frame: right-handed, metres, +y up. See `docs/reference/scene-format.md` for the
//! parameter table of every object kind; the defaults below are the ones documented there.

pub mod builtin;
pub mod coat_keys;
pub mod curved_body;
pub mod display_keys;
pub mod display_surface;
pub mod eyellipse;
pub mod eyellipse_keys;
pub mod fingerprint;
pub mod grow;
pub mod head_model;
pub mod head_path;
pub mod instances;
pub mod key_override;
pub mod lane_route;
pub mod lens_keys;
pub mod light_keys;
pub mod limits;
pub mod mesh_checks;
pub mod mesh_io;
pub mod motion;
pub mod procedural;
pub mod read;
pub mod road_keys;
pub mod road_map;
pub mod sensor_keys;
pub mod shape_mesh;
pub mod shapes;
pub mod shutter_keys;
pub mod source;
pub mod sun_position;
pub mod surface_grid;
pub mod table_reader;
pub mod texture;
pub mod world;

use std::path::PathBuf;

use glam::{DAffine3, DVec3};

use crate::geometry::calibration::Calibration;
use crate::geometry::camera::Camera;

/// Which cameras can see an object. A bit set over [`CameraKind`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CameraKind {
    /// The driver's eye (views `truth`, `occluded`, `seethru`).
    Driver,
    /// The frontal camera on the obstacle's far side.
    Frontal,
    /// The back camera on the display's top edge, facing the driver.
    Back,
}

impl CameraKind {
    pub const NAMES: [&'static str; 3] = ["driver", "frontal", "back"];
    /// The bits of every camera: an object all of them see.
    pub const ALL: u8 = 0b111;

    pub fn bit(self) -> u8 {
        1 << self as u8
    }

    fn parse(name: &str) -> Self {
        match name {
            "driver" => CameraKind::Driver,
            "frontal" => CameraKind::Frontal,
            _ => CameraKind::Back,
        }
    }
}

/// A surface material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Base colour, sRGB-encoded components in [0, 1] (as a colour picker shows them).
    pub color: [f64; 3],
    /// Optional image texture (PNG), multiplied with `color`.
    pub texture: Option<PathBuf>,
    /// How often the texture repeats across the surface's [0, 1]² UV range, per axis, > 0.
    pub uv_repeat: [f64; 2],
    /// The glossy lobe's reflectance at normal incidence F0, [0, 1] (0: no lobe, the
    /// surface is Lambertian; water 0.02, glass and car clear coat 0.04).
    pub specular: f64,
    /// The glossy lobe's GGX roughness α (Mitsuba's `alpha`: the microfacets' slope width),
    /// [`MIN_ROUGHNESS`](limits::MIN_ROUGHNESS), 1]; read only where `specular` > 0.
    pub roughness: f64,
}

impl Material {
    /// An untextured Lambertian material of sRGB colour `color`.
    pub fn matte(name: impl Into<String>, color: [f64; 3]) -> Material {
        Material {
            name: name.into(),
            color,
            texture: None,
            uv_repeat: [1.0, 1.0],
            specular: 0.0,
            roughness: limits::DEFAULT_ROUGHNESS,
        }
    }
}

/// A primitive's shape in its object space.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// Ground plane: a rectangle in the local xz plane, normal +y, `size` = [x, z] metres.
    Plane { size: [f64; 2] },
    /// Box centred at the origin, `size` = [x, y, z] metres.
    Box { size: [f64; 3] },
    /// Sphere of `radius` metres centred at the origin (intersected analytically).
    Sphere { radius: f64 },
    /// Cylinder along +y from y = 0 to `height`, tessellated into `segments` facets.
    Cylinder {
        radius: f64,
        height: f64,
        segments: usize,
    },
    /// Cone along +y, base at y = 0, apex at `height`.
    Cone {
        radius: f64,
        height: f64,
        segments: usize,
    },
    /// Rectangle in the local xy plane facing +z, `size` = [x, y] metres.
    Quad { size: [f64; 2] },
    /// Triangle mesh from an OBJ or glTF/GLB file.
    Mesh { path: PathBuf },
    /// The road of `[road] xodr`: an OpenDRIVE map's lanes, marks, kerb faces and objects,
    /// in the map's frame (`scene/road_map.rs`); the object's transform places the map.
    Road {
        path: PathBuf,
        look: road_map::RoadLook,
        /// The map as read with the scene (not read again to build the world).
        map: road_map::ParsedMap,
    },
    /// The built-in head mesh (`scene/head_model.rs`, the triangles of `assets/head.obj`,
    /// built into the binary): the driver's face of `[camera.driver] face = "mesh"`.
    HeadMesh,
}

impl Shape {
    /// The `kind` key of the shape in a scene file.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Plane { .. } => "plane",
            Shape::Box { .. } => "box",
            Shape::Sphere { .. } => "sphere",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Cone { .. } => "cone",
            Shape::Quad { .. } => "quad",
            Shape::Mesh { .. } | Shape::HeadMesh => "mesh",
            Shape::Road { .. } => "road",
        }
    }
}

/// One `[[object]]` of the scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub name: String,
    pub shape: Shape,
    /// Index into [`Scene::materials`]; `None` for meshes that bring their own materials.
    pub material: Option<usize>,
    /// A mesh's own materials replaced by name: (the file's material name, index into
    /// [`Scene::materials`]); empty for every other object.
    pub file_materials: Vec<(String, usize)>,
    /// Object space to world space: translate · rotate · scale.
    pub world_from_object: DAffine3,
    /// Bit set of [`CameraKind::bit`]s of the cameras that see the object.
    pub visible_to: u8,
    /// Whether the object blocks sunlight.
    pub casts_shadow: bool,
    /// Whether it is a road user the driver must see (a pedestrian, a cyclist): the hazard
    /// visibility metric follows it. Default false.
    pub hazard: bool,
    /// How it moves during a `sequence` (nothing else reads it).
    pub motion: motion::ObjectMotion,
    /// Placements of a mesh object (`instances`): rows x, y, z (metres, world frame),
    /// yaw (degrees about +y), each placing the object as `world_from_object` leaves it.
    /// Empty: the object once, at `world_from_object`.
    pub instances: Vec<[f64; 4]>,
}

/// The sun: a directional light that casts hard shadows.
#[derive(Clone, Debug, PartialEq)]
pub struct Sun {
    /// Unit direction from the scene towards the sun, world frame.
    pub direction: DVec3,
    /// sRGB colour in [0, 1].
    pub color: [f64; 3],
    /// Irradiance multiplier, ≥ 0.
    pub intensity: f64,
}

/// A scene's light in physical units (`[sun] illuminance_lux`, `[sky]
/// zenith_luminance_cd_m2`, `[photometry]`). Its renders count radiance in units of
/// `white_cd_m2` (a frame's linear 1.0, the PNGs' white); its EXRs hold cd/m².
#[derive(Clone, Debug, PartialEq)]
pub struct Photometry {
    /// Illuminance of the sun on a surface facing it, lux, in [0, 150 000].
    pub sun_illuminance_lux: f64,
    /// Luminance of the sky at the zenith, cd/m², in [0, 100 000]: the sky's colours (its
    /// gradient and clouds) are scaled so that the zenith colour has it.
    pub sky_zenith_cd_m2: f64,
    /// The luminance shown as white, cd/m², in [1e-6, 1e10]: a frame's linear 1.0. Default:
    /// [`Photometry::lit_white_cd_m2`].
    pub white_cd_m2: f64,
    /// How the lamps' shadow rays are spent (`lamp_sampling`; default every lamp's).
    pub lamp_sampling: LampSampling,
}

/// How a lit point gathers the shadow-casting lamps' light (`[photometry] lamp_sampling`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LampSampling {
    /// A shadow ray to every lamp that lights the point: no noise from the lamps, a ray per
    /// lamp (`"every"`, the default).
    #[default]
    Every,
    /// One shadow ray per sample, to one light drawn among the sun and the shadow-casting
    /// lamps in proportion to its unshadowed light's luminance at the point; that light over
    /// the probability of its draw where the ray reaches it (`"one"`): unbiased; the
    /// luminance exact wherever every light or none is seen (the colour is the drawn
    /// light's), noisy only in partial shadow; one ray however many lamps.
    One,
}

impl Photometry {
    /// cd/m² per unit of the sky's linear colours (the zenith's then has `sky_zenith_cd_m2`).
    pub fn sky_cd_m2_per_unit(&self, sky: &Sky) -> f64 {
        let zenith = crate::util::color::srgb_to_linear3(sky.zenith_color);
        match self.sky_zenith_cd_m2 {
            0.0 => 0.0,
            l => l / f64::from(crate::util::color::luminance(zenith)),
        }
    }

    /// cd/m² per unit of the sun's linear colour: its luminance is then `illuminance_lux`.
    pub fn sun_lux_per_unit(&self, sun: &Sun) -> f64 {
        let colour = crate::util::color::srgb_to_linear3(sun.color);
        match self.sun_illuminance_lux {
            0.0 => 0.0,
            lux => lux / f64::from(crate::util::color::luminance(colour)),
        }
    }

    /// The luminance of a white Lambertian floor under the sun and the cloudless sky, cd/m²:
    /// (E_sun · sin⁺(elevation) + E_sky) / π, E_sky = π × the sky's cosine-weighted mean
    /// luminance ([`Sky::cosine_mean`]).
    pub fn lit_white_cd_m2(&self, sun: &Sun, sky: &Sky) -> f64 {
        let sun_part = self.sun_illuminance_lux * sun.direction.y.max(0.0) / std::f64::consts::PI;
        let [zenith, horizon] = [sky.zenith_color, sky.horizon_color].map(|c| {
            f64::from(crate::util::color::luminance(
                crate::util::color::srgb_to_linear3(c),
            ))
        });
        sun_part + self.sky_cd_m2_per_unit(sky) * Sky::cosine_mean(horizon, zenith)
    }
}

/// The sky: a gradient with procedural clouds; also the ambient light.
#[derive(Clone, Debug, PartialEq)]
pub struct Sky {
    pub zenith_color: [f64; 3],
    pub horizon_color: [f64; 3],
    /// Colour below the horizon (seen only where there is no ground).
    pub ground_color: [f64; 3],
    /// Ambient light multiplier, ≥ 0.
    pub ambient: f64,
    /// Fraction of the sky covered by clouds, in [0, 1].
    pub cloud_cover: f64,
    /// Height of the cloud layer above y = 0, metres.
    pub cloud_height: f64,
    /// Typical size of a cloud, metres.
    pub cloud_size: f64,
    /// Seed of the cloud pattern.
    pub cloud_seed: u32,
}

/// The obstacle (A-pillar, panel) and the display on its driver-facing side.
///
/// Obstacle frame: origin at the display centre, display in the plane z = 0, the driver on
/// the +z side, the scene on the −z side.
#[derive(Clone, Debug, PartialEq)]
pub struct Obstacle {
    /// Rigid transform from the obstacle frame to the world frame.
    pub world_from_obstacle: DAffine3,
    /// Display width `D`, metres, > 0 (obstacle frame x).
    pub width: f64,
    /// Display height `H`, metres, > 0 (obstacle frame y).
    pub height: f64,
    /// Depth of the obstacle body behind the display (towards −z), metres, > 0.
    pub thickness: f64,
    /// The physical display's resolution, [width, height] pixels.
    pub display_resolution: [u32; 2],
    /// Colour of the switched-off display, sRGB in [0, 1].
    pub display_off_color: [f64; 3],
    /// Colour of the obstacle body, sRGB in [0, 1].
    pub body_color: [f64; 3],
    /// The display's surface: flat (the `width` × `height` rectangle at z = 0), or curved
    /// (triangles with UVs in the obstacle frame; `width` × `height` is then its reference
    /// rectangle, which the crop's report and the flat formulas use).
    pub display_shape: display_surface::DisplayShape,
    /// How the display's rows take each new image and how long they stay lit (a sequence's
    /// display refreshes; every other command shows one still image).
    pub scanout: crate::geometry::shutter::Scanout,
    /// The display as a light source (a scene lit in physical units only); `None`: an ideal
    /// display, emitting the frontal camera's radiance as it is, unbounded.
    pub display_light: Option<DisplayLight>,
}

/// A lamp: a point light, or a spot (a street light, a headlight), in a scene lit in
/// physical units. A surface of albedo ρ at distance d, at incidence θ from it, gains the
/// luminance ρ I cos θ / (π d²), I its intensity towards the surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Lamp {
    pub name: String,
    /// Where it shines from, world frame, metres.
    pub position: DVec3,
    /// Luminous intensity, cd, in [0, 1e7]: on its axis for a spot.
    pub intensity_cd: f64,
    /// Its chromaticity (sRGB in [0, 1]; scaled so that its luminance is the intensity).
    pub color: [f64; 3],
    /// `None`: it shines the same in every direction.
    pub spot: Option<Spot>,
    /// Whether what stands between it and a surface shades the surface (default true).
    pub casts_shadow: bool,
    /// Whether it stands in the world (a street lamp) or rides with the vehicle (its
    /// headlights, its instrument cluster) in a `sequence`; `position` and the spot's
    /// `direction` are where it is at t = 0. Never [`motion::MovesWith::Head`].
    pub moves_with: motion::MovesWith,
}

/// A spot's beam: full intensity within `falloff` of its axis, none beyond `cone`, a
/// smoothstep of the cosine between.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    /// Unit axis, world frame.
    pub direction: DVec3,
    /// Cosine of the half angle beyond which it gives nothing (`cone_deg`, (0, 90]).
    pub cos_cone: f64,
    /// Cosine of the half angle within which it gives its full intensity (`falloff_deg`,
    /// [0, cone]).
    pub cos_falloff: f64,
    /// A low beam's cut-off line: the sine of the elevation (above the horizontal, world +y)
    /// above which the beam gives nothing (`cutoff_deg`, [−90, 90]); `None`: no cut-off.
    pub cutoff_sin: Option<f64>,
    /// An asymmetric low beam's step-up (`cutoff_kerb`): on the kerb side of its axis the
    /// cut-off line rises at 15° (ECE R112), as a screen across the axis shows it; `None`:
    /// the line is flat.
    pub kerb_step: Option<KerbStep>,
}

/// The kerb side's rising cut-off line of a low beam ([`Spot::kerb_step`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KerbStep {
    /// The axis's horizontal direction, unit, world frame.
    pub forward: DVec3,
    /// Towards the kerb, horizontal and across `forward`, unit, world frame.
    pub kerb: DVec3,
    /// Tangent of the cut-off's elevation (`cutoff_deg`).
    pub cutoff_tan: f64,
}

/// The slope of the kerb side's cut-off line: 15° (ECE R112's asymmetric low beam).
pub const KERB_STEP_DEG: f64 = 15.0;

impl Spot {
    /// The fraction of the axis's intensity towards the unit direction `to` (from the lamp).
    pub fn profile(&self, to: DVec3) -> f64 {
        if self.cutoff_sin.is_some_and(|limit| to.y > limit) && !self.under_kerb_step(to) {
            return 0.0;
        }
        let cos = self.direction.dot(to);
        if cos >= self.cos_falloff {
            return 1.0;
        }
        if cos <= self.cos_cone {
            return 0.0;
        }
        let t = (cos - self.cos_cone) / (self.cos_falloff - self.cos_cone);
        t * t * (3.0 - 2.0 * t)
    }

    /// Whether `to` is under the kerb side's rising line: on a screen across the axis (at
    /// forward distance f, kerb-side offset l > 0, height v), v / f ≤ tan(cutoff) +
    /// (l / f) tan 15°. At l = 0 the line meets the flat one.
    fn under_kerb_step(&self, to: DVec3) -> bool {
        let Some(step) = self.kerb_step else {
            return false;
        };
        let (f, l) = (to.dot(step.forward), to.dot(step.kerb));
        f > 0.0 && l > 0.0 && to.y <= f * step.cutoff_tan + l * KERB_STEP_DEG.to_radians().tan()
    }
}

/// A display's light: what it emits for an image, and what it reflects of the light that
/// falls on it. Its colour channels emit `black + (peak − black) × the frontal image's
/// linear value clamped to [0, 1]`, the image's 1.0 being the scene's white
/// ([`Photometry::white_cd_m2`]): a world brighter than the white, or a peak below it,
/// shows darker on the display than behind it.
#[derive(Clone, Debug, PartialEq)]
pub struct DisplayLight {
    /// Luminance of full white, cd/m², in [0.01, 100 000] (default 1000).
    pub peak_cd_m2: f64,
    /// Luminance of black (the backlight's leak), cd/m², in [0, peak) (default 0).
    pub black_cd_m2: f64,
    /// Diffuse (Lambertian) reflectance of the display's face, in [0, 1] (default 0): it
    /// adds reflectance × the illuminance on the face / π (the sky, the ground, the sun
    /// where it reaches the face).
    pub reflectance: f64,
    /// How a code becomes light (default linear: a frontal image in linear light, shown as
    /// it is).
    pub transfer: DisplayTransfer,
}

/// A display's electro-optical transfer: the share of its range a code in [0, 1] gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DisplayTransfer {
    /// The code's value.
    Linear,
    /// IEC 61966-2-1's sRGB curve.
    Srgb,
    /// A power of 2.2.
    Gamma22,
    /// A power of 2.4 (ITU-R BT.1886 with a black of zero: the black is `black_cd_m2`'s).
    Gamma24,
}

impl DisplayTransfer {
    pub const NAMES: [&'static str; 4] = ["linear", "srgb", "gamma2.2", "gamma2.4"];

    pub fn from_name(name: &str) -> Option<DisplayTransfer> {
        let all = [Self::Linear, Self::Srgb, Self::Gamma22, Self::Gamma24];
        Some(all[Self::NAMES.iter().position(|n| *n == name)?])
    }

    /// The code in [0, 1] that gives `share` of the display's range: the inverse of
    /// [`DisplayTransfer::light`]; a share beyond [0, 1] is clamped.
    pub fn code(self, share: f32) -> f32 {
        let v = share.clamp(0.0, 1.0);
        match self {
            DisplayTransfer::Linear => v,
            DisplayTransfer::Srgb => crate::util::color::linear_to_srgb(v),
            DisplayTransfer::Gamma22 => v.powf(1.0 / 2.2),
            DisplayTransfer::Gamma24 => v.powf(1.0 / 2.4),
        }
    }

    /// The share of the display's range (peak − black) a code in [0, 1] gives; a code
    /// beyond is clamped.
    pub fn light(self, code: f32) -> f32 {
        let v = code.clamp(0.0, 1.0);
        match self {
            DisplayTransfer::Linear => v,
            DisplayTransfer::Srgb => crate::util::color::srgb_to_linear(v),
            DisplayTransfer::Gamma22 => v.powf(2.2),
            DisplayTransfer::Gamma24 => v.powf(2.4),
        }
    }
}

impl Obstacle {
    /// Display corners in world space: top-left, top-right, bottom-right, bottom-left.
    pub fn display_corners(&self) -> [DVec3; 4] {
        let (hw, hh) = (self.width / 2.0, self.height / 2.0);
        [(-hw, hh), (hw, hh), (hw, -hh), (-hw, -hh)].map(|(x, y)| {
            self.world_from_obstacle
                .transform_point3(DVec3::new(x, y, 0.0))
        })
    }

    /// Obstacle-frame bounding box (min, max) of the body with its display: the
    /// `width` × `height` × `thickness` box behind a flat display, or a curved display's
    /// surface and its copy `thickness` behind (a curved surface can bulge beyond the box).
    pub fn body_bounds(&self) -> (DVec3, DVec3) {
        let back = DVec3::new(0.0, 0.0, -self.thickness);
        match self.display_shape.curved() {
            Some(surface) => {
                let (lo, hi) = surface.bounds();
                (lo + back, hi)
            }
            None => {
                let half = DVec3::new(self.width / 2.0, self.height / 2.0, 0.0);
                (back - half, half)
            }
        }
    }

    /// Obstacle-frame coordinates of a world point.
    pub fn in_obstacle_frame(&self, world: DVec3) -> DVec3 {
        self.world_from_obstacle.inverse().transform_point3(world)
    }

    /// Unit normal of the display, pointing towards the driver (obstacle +z), world frame.
    pub fn normal(&self) -> DVec3 {
        self.world_from_obstacle.matrix3.z_axis
    }
}

/// A fully read and validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The scene file this was read from.
    pub path: PathBuf,
    /// The content hash of that file's text (`util::hash::content_hash`), recorded by
    /// `run` so that `measure` can tell the scene changed.
    pub source_hash: String,
    pub sun: Sun,
    pub sky: Sky,
    /// The light in physical units: `Some` once `[sun] illuminance_lux` is given; `None`
    /// for a scene lit in relative units (`[sun] intensity`, `[sky] ambient`).
    pub photometry: Option<Photometry>,
    /// The `[[light]]` lamps (a photometric scene's only), world frame.
    pub lights: Vec<Lamp>,
    pub materials: Vec<Material>,
    pub objects: Vec<Object>,
    pub obstacle: Obstacle,
    /// The driver's eye (the paper's user), world frame.
    pub driver: Camera,
    /// The frontal camera behind the obstacle, filming the scene.
    pub frontal: Camera,
    /// The back camera on the display's top edge, filming the driver.
    pub back: Camera,
    /// The compensation's own copies of the frontal and back cameras (`[calibration]`):
    /// head estimation and the crop use them, rendering uses the true ones.
    pub calibration: Calibration,
    /// The SAE J941 eyellipse of the scene's `[eyellipse]` seat package, if it has one: the
    /// driver's eye defaults to its centre, and `sweep --param eye=eyellipse` samples it.
    pub eyellipse: Option<eyellipse::Eyellipse>,
    /// The driver's face the back camera films (`[camera.driver] face`); it chooses the head
    /// tracker of `--head estimated`.
    pub face: DriverFace,
    /// The lane route the vehicle drives in a `sequence` (and during a run's frontal
    /// exposure) at option `speed`, where `[road]` places it in a lane of a map: world frame,
    /// from the lane's centre at t = 0. `None`: the vehicle drives straight along −z, turning
    /// at option `yaw_rate`.
    pub ego_route: Option<lane_route::LaneRoute>,
    /// What reading the scene dropped or doubted, one line each (without `warning:`): the
    /// features of an OpenDRIVE map its importer skips. Commands print them on stderr.
    pub warnings: Vec<String>,
}

/// The driver's face (`[camera.driver] face`), and with it the head tracker `--head
/// estimated` runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DriverFace {
    /// `"ellipsoids"`: the face is the scene's own `[[object]]`s (das's ellipsoid head, hair
    /// and two pupil spheres); the frontal detector and the paper's eqs. d1, b_h find the eye.
    Ellipsoids,
    /// `"mesh"`: the built-in head mesh ([`Shape::HeadMesh`]) is added as the object `head`,
    /// its eye point at the driver's eye, hidden from the driver and riding with the head in
    /// sequences; the side-angle detector and the yaw fit find the eye.
    Mesh {
        /// The head's yaw about the world's +y, degrees in [−80, 80]; 0 faces world −z (the
        /// car's forward at rest), positive turns the face towards −x (the driver's left).
        yaw_deg: f64,
    },
}

impl DriverFace {
    /// The values of the `face` key.
    pub const NAMES: [&'static str; 2] = ["ellipsoids", "mesh"];
}

impl Scene {
    /// The driver's eye position, world frame.
    pub fn eye(&self) -> DVec3 {
        self.driver.position()
    }

    /// Moves the driver's eye to `eye` (world, m), keeping the driver camera's orientation,
    /// and the driver's head with it: every object riding with the head (the face the back
    /// camera films, `moves_with = "head"`) moves by the same offset, as in a sequence.
    pub fn move_eye(&mut self, eye: DVec3) {
        let moved = eye - self.eye();
        self.driver.world_from_camera.translation = eye;
        for object in &mut self.objects {
            if object.motion.moves_with == motion::MovesWith::Head {
                object.world_from_object.translation += moved;
            }
        }
    }
}

impl Default for Sun {
    fn default() -> Self {
        Sun {
            direction: DVec3::new(-0.4, 0.8, 0.45).normalize(),
            color: [1.0, 0.96, 0.9],
            intensity: 2.6,
        }
    }
}

impl Sky {
    /// The cosine-weighted mean over the upper hemisphere of the gradient from `horizon` to
    /// `zenith` (radiance h + (z − h)·√y at elevation sine y): 0.2 h + 0.8 z, so that a floor
    /// under it receives π × that (2π ∫₀¹ L(y) y dy).
    pub fn cosine_mean(horizon: f64, zenith: f64) -> f64 {
        0.2 * horizon + 0.8 * zenith
    }
}

impl Default for Sky {
    fn default() -> Self {
        Sky {
            zenith_color: [0.28, 0.48, 0.85],
            horizon_color: [0.78, 0.86, 0.95],
            ground_color: [0.36, 0.34, 0.3],
            ambient: 0.55,
            cloud_cover: 0.45,
            cloud_height: 1500.0,
            cloud_size: 900.0,
            cloud_seed: 1,
        }
    }
}
