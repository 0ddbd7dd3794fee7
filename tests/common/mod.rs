//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod golden;

use std::path::{Path, PathBuf};

use seethru::scene::Scene;
use seethru::scene_file::{SceneError, SourceFile};

pub fn repo_path(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

pub fn das() -> Scene {
    Scene::load(&repo_path("scenes/das.toml")).expect("das.toml loads")
}

/// A small valid scene: a ground plane, a sphere and the obstacle with its cameras.
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
