//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod golden;
pub mod photometric;
pub mod python_env;
pub mod refusal;

use std::path::{Path, PathBuf};

use seethru::scene::Scene;
use seethru::scene::source::{SceneError, SourceFile};

/// Runs the `seethru` binary in `dir`; (success, stdout, stderr).
pub fn seethru_in<S: AsRef<std::ffi::OsStr>>(dir: &Path, args: &[S]) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_seethru"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// Runs the `seethru` binary from the repository root; (success, stdout, stderr).
pub fn seethru<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> (bool, String, String) {
    seethru_in(Path::new(env!("CARGO_MANIFEST_DIR")), args)
}

pub fn repo_path(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// A shipped scene (`scenes/<name>`) with its pillar slanted as the issue's new user tried
/// (turned 31° towards the driver, leaning back), its asset paths made absolute.
pub fn slanted_scene_text(name: &str) -> String {
    let text = std::fs::read_to_string(repo_path("scenes").join(name)).unwrap();
    text.replace(
        "facing = [0.0, 0.0, 1.0]",
        "facing = [0.6, 0.0, 1.0]\nup = [0.0, 1.0, 1.5]",
    )
    .replace("../assets", repo_path("assets").to_str().unwrap())
}

/// `run SCENE --out OUT --head estimated` small and fast (48 px wide, 1 spp, black outside
/// the display), then `extra`.
pub fn estimated_run_args(scene: &Path, out: &Path, extra: &[&str]) -> Vec<String> {
    let mut args: Vec<String> = [
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--head",
        "estimated",
        "--outside",
        "black",
        "--width",
        "48",
        "--spp",
        "1",
    ]
    .map(String::from)
    .to_vec();
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

pub fn das() -> Scene {
    Scene::load(&repo_path("scenes/das.toml")).expect("das.toml loads")
}

/// das with its ellipsoid face (head, hair, two pupils) replaced by the mesh face
/// (`[camera.driver] face = "mesh"`): what `scenes/das_mesh_head.toml` holds.
pub fn das_with_mesh_head() -> String {
    let das = std::fs::read_to_string(repo_path("scenes/das.toml")).unwrap();
    let start = das
        .find("# The driver's head, for the back camera")
        .unwrap();
    let end = das.find("# Trees on both sides").unwrap();
    let first = das.find('\n').unwrap();
    let driver = "[camera.driver]\n";
    let face = "# The driver's face: the head mesh (scene/head_model.rs, assets/head.obj) at the eye,\n\
                # instead of das's ellipsoid face objects; `--head estimated` fits its yaw. Otherwise\n\
                # this file is scenes/das.toml: tests/head_poses.rs checks that it stays so.\n\
                face = \"mesh\"\n";
    let text = format!(
        "# das (scenes/das.toml) with the head mesh as the driver's face: the side-angle head tracker's scene.{}{}",
        &das[first..start],
        &das[end..]
    );
    assert!(text.contains(driver));
    text.replacen(driver, &format!("{driver}{face}"), 1)
}

/// [`das_with_mesh_head`] with absolute asset paths, so the text can be written anywhere.
pub fn das_with_mesh_head_text() -> String {
    das_with_mesh_head().replace("../assets", repo_path("assets").to_str().unwrap())
}

/// A small valid scene: a ground plane, a sphere and the obstacle with its cameras.
/// das's light, obstacle and cameras without its materials and objects: a scene to add
/// one thing to and trace it alone.
#[allow(dead_code)]
pub fn das_without_objects() -> String {
    let das = std::fs::read_to_string(repo_path("scenes/das.toml")).unwrap();
    das[..das.find("[[material]]").unwrap()].to_string()
}

pub const MINIMAL: &str = r#"
[obstacle]
center = [0.0, 1.2, -0.8]
width = 0.3
height = 0.4

[camera.driver]
position = [0.0, 1.2, 0.0]
look_at = [0.0, 1.2, -10.0]
resolution = [64, 36]

[camera.frontal]
resolution = [64, 36]

[camera.back]
resolution = [32, 24]

[[material]]
name = "grey"
color = [0.5, 0.5, 0.5]

[[object]]
name = "ground"
kind = "plane"
material = "grey"
size = [100.0, 100.0]

[[object]]
name = "ball"
kind = "sphere"
material = "grey"
radius = 1.0
translate = [0.0, 1.0, -10.0]
"#;

/// Parses scene text as if it were the file `dir/name`.
pub fn parse_in(dir: &Path, name: &str, text: &str) -> Result<Scene, SceneError> {
    Scene::from_source(&SourceFile::from_text(&dir.join(name), text.to_string()))
}

pub fn parse(text: &str) -> Result<Scene, SceneError> {
    parse_in(Path::new("test-scenes"), "scene.toml", text)
}

/// A textured wall (quad) `wall` metres behind a 0.3 × 0.2 m display at the origin facing +z.
pub struct WallScene {
    pub wall: f64,
    /// The eye (driver camera), world = obstacle frame.
    pub eye: [f64; 3],
    pub driver_half_angle: f64,
    pub driver_resolution: [u32; 2],
    pub display_resolution: [u32; 2],
    pub frontal_half_angle: f64,
    pub frontal_resolution: [u32; 2],
}

impl Default for WallScene {
    fn default() -> Self {
        Self {
            wall: 6.0,
            eye: [0.08, 0.03, 0.7],
            driver_half_angle: 20.0,
            driver_resolution: [200, 150],
            display_resolution: [150, 100],
            frontal_half_angle: 45.0,
            frontal_resolution: [640, 480],
        }
    }
}

impl WallScene {
    pub fn text(&self) -> String {
        let Self {
            wall,
            eye,
            driver_half_angle,
            driver_resolution: dr,
            display_resolution: sr,
            frontal_half_angle,
            frontal_resolution: fr,
        } = self;
        format!(
            r#"
[obstacle]
center = [0.0, 0.0, 0.0]
width = 0.3
height = 0.2
display_resolution = [{}, {}]

[camera.driver]
position = [{}, {}, {}]
look_at = [0.0, 0.0, -6.0]
half_angle_deg = {driver_half_angle}
resolution = [{}, {}]

[camera.frontal]
half_angle_deg = {frontal_half_angle}
resolution = [{}, {}]

[camera.back]
resolution = [32, 24]

[[material]]
name = "wall"
texture = "../assets/street.png"
uv_repeat = [6.0, 2.0]

[[object]]
name = "wall"
kind = "quad"
material = "wall"
size = [80.0, 60.0]
translate = [0.0, 0.0, -{wall}]
"#,
            sr[0], sr[1], eye[0], eye[1], eye[2], dr[0], dr[1], fr[0], fr[1]
        )
    }

    /// The scene written into `dir` as `wall.toml`, for the command line.
    pub fn file_in(&self, dir: &Path) -> PathBuf {
        scene_file_in(dir, "wall.toml", &self.text())
    }

    /// The scene, read as `scenes/wall.toml` would be.
    pub fn scene(&self) -> Scene {
        parse_in(&repo_path("scenes"), "wall.toml", &self.text()).unwrap()
    }

    pub fn context(&self) -> seethru::render::integrator::RenderContext {
        seethru::render::integrator::RenderContext::new(self.scene()).unwrap()
    }
}

/// A scene text of `scenes/` written into `dir` as `name`, its `../assets/street.png` by
/// absolute path, so that the command line can read it from there.
pub fn scene_file_in(dir: &Path, name: &str, text: &str) -> PathBuf {
    let street = repo_path("assets/street.png");
    let text = text.replace("../assets/street.png", street.to_str().unwrap());
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The coverage the planar model predicts for the driver's view of the display, by ray
/// casting alone: a display point is covered when the frontal camera sees the model point of
/// the eye's ray through it (or, for `model_d2 = None`, the direction d2 → ∞). Returns
/// (display pixels, covered, ambiguous): ambiguous pixels lie within one display pixel of the
/// coverage boundary, where the display's own pixels may round either way.
pub fn expected_coverage(
    scene: &Scene,
    driver: &seethru::geometry::camera::Camera,
    frontal: &seethru::geometry::camera::Camera,
    model_d2: Option<f64>,
) -> (usize, usize, usize) {
    use glam::{DVec2, DVec3};
    let obstacle = &scene.obstacle;
    let to_obstacle = obstacle.world_from_obstacle.inverse();
    let eye = to_obstacle.transform_point3(driver.position());
    let camera = to_obstacle.transform_point3(frontal.position());
    let covered = |x: DVec3| {
        let dir = match model_d2 {
            Some(d2) => eye + (x - eye) * (eye.z + d2) / eye.z - camera,
            None => x - eye,
        };
        frontal
            .project_direction(obstacle.world_from_obstacle.transform_vector3(dir))
            .is_some_and(|q| {
                q.x >= 0.0
                    && q.y >= 0.0
                    && q.x < frontal.width as f64
                    && q.y < frontal.height as f64
            })
    };
    let [dw, dh] = obstacle.display_resolution.map(f64::from);
    let step = DVec2::new(obstacle.width / dw, obstacle.height / dh);
    let (mut display, mut inside, mut ambiguous) = (0, 0, 0);
    for y in 0..driver.height {
        for x in 0..driver.width {
            let (origin, dir) = driver.world_ray(DVec2::new(x as f64 + 0.5, y as f64 + 0.5));
            let (o, d) = (
                to_obstacle.transform_point3(origin),
                to_obstacle.transform_vector3(dir),
            );
            let t = -o.z / d.z;
            let p = o + d * t;
            if !(t > 0.0 && p.x.abs() <= obstacle.width / 2.0 && p.y.abs() <= obstacle.height / 2.0)
            {
                continue;
            }
            display += 1;
            let here = covered(p);
            inside += here as usize;
            let neighbours = [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
                .map(|(a, b)| covered(p + DVec3::new(a * step.x, b * step.y, 0.0)));
            ambiguous += neighbours.iter().any(|&n| n != here) as usize;
        }
    }
    (display, inside, ambiguous)
}

/// The mean age, from the frame's completion, of the frontal rows the display's pixels show
/// on a wall `wall` metres ahead of the display (a rolling shutter of `readout` s, top to
/// bottom): a 60 × 40 grid over the display, each point's ray from the eye onto the wall,
/// projected into the frontal camera.
pub fn readout_age(scene: &seethru::scene::Scene, readout: f64, wall: f64) -> f64 {
    let (eye, frontal) = (scene.eye(), scene.frontal);
    let [a, b, _, d] = scene.obstacle.display_corners();
    let mut age = 0.0;
    for i in 0..60 {
        for j in 0..40 {
            let (u, v) = ((f64::from(i) + 0.5) / 60.0, (f64::from(j) + 0.5) / 40.0);
            let p = a + (b - a) * u + (d - a) * v;
            let on_wall = eye + (p - eye) * ((-wall - eye.z) / (p.z - eye.z));
            let row = frontal.project_point(on_wall).unwrap().y.floor();
            let last = f64::from(frontal.height - 1);
            age += readout * (last - row) / last / 2400.0;
        }
    }
    age
}

/// How a test measures a sequence: the truth and the metrics (FLIP only when `flip` says),
/// the window around the display, a 5-pixel band, no progress bar.
pub fn measuring(
    flip: seethru::measure::image_metrics::Flip,
) -> seethru::measure::sequence::Measuring {
    seethru::measure::sequence::Measuring {
        metrics: true,
        full_frames: false,
        band: 5,
        progress: false,
        flip,
    }
}

/// A sequence of `run` with the vehicle and the head still: `duration` seconds of frames at
/// `hz` (the display refreshing with them), the frontal image `latency_camera` seconds old.
pub fn still_sequence(
    run: seethru::system::options::RunOptions,
    duration: f64,
    hz: f64,
    latency_camera: f64,
) -> seethru::system::sequence::system_loop::SequenceOptions {
    seethru::system::sequence::system_loop::SequenceOptions {
        run,
        timeline: seethru::system::sequence::timeline::Timeline {
            duration,
            fps: hz,
            display_hz: hz,
            latency_camera,
            latency_tracking: 0.0,
        },
        head: seethru::system::sequence::head_motion::HeadMotion::Still,
        predict: seethru::system::sequence::predict::Prediction::None,
        reproject: false,
        byo: Default::default(),
    }
}

/// Every channel of an EXR's first layer, by name, read with the `exr` crate's own reader
/// (not seethru's): the tests' independent view of a file.
pub fn exr_channels(path: &Path) -> Vec<(String, exr::prelude::FlatSamples)> {
    use exr::prelude::*;
    read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .layer_data
        .channel_data
        .list
        .into_iter()
        .map(|c| (c.name.to_string(), c.sample_data))
        .collect()
}
