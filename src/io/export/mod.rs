//! Exporting a scene so that other renderers can be run on exactly the same scene: the traced
//! triangles (spheres tessellated) with normals, UVs and materials, the three cameras, the
//! display, the sun and the sky, and every object's seethru id — as binary glTF, OBJ + MTL or
//! Mitsuba 3 scenes, and `<file>.cameras.json` beside each.

pub mod content;
pub mod gltf;
pub mod mitsuba;
pub mod obj;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde_json::json;

use crate::geometry::camera::Camera;
use crate::io::atomic::write_text;
use crate::io::export::content::{ExportScene, display_json};
use crate::io::staged::StagedDir;
use crate::scene::Scene;
use crate::scene::world::World;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// Binary glTF 2.0 (.glb): meshes, materials and texture, cameras, display, sun.
    Gltf,
    /// Wavefront OBJ with an MTL material library (.obj).
    Obj,
    /// Mitsuba 3 XML scenes with PLY meshes (.xml).
    Mitsuba,
}

impl ExportFormat {
    const ALL: [ExportFormat; 3] = [ExportFormat::Gltf, ExportFormat::Obj, ExportFormat::Mitsuba];

    pub fn extension(self) -> &'static str {
        match self {
            ExportFormat::Gltf => "glb",
            ExportFormat::Obj => "obj",
            ExportFormat::Mitsuba => "xml",
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ExportFormat::Gltf => "gltf",
            ExportFormat::Obj => "obj",
            ExportFormat::Mitsuba => "mitsuba",
        }
    }

    /// The format an output file name asks for, by its extension.
    pub fn of_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        Self::ALL.into_iter().find(|f| f.extension() == ext)
    }
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
    json!({
        "units": "metres, world frame right-handed +y up",
        "driver": camera_json(&scene.driver),
        "frontal": camera_json(&scene.frontal),
        "back": camera_json(&scene.back),
        "display": display_json(scene),
    })
}

/// What an export wrote.
#[derive(Clone, Debug)]
pub struct Exported {
    pub format: ExportFormat,
    pub triangles: usize,
    /// Every file written, the main one first.
    pub files: Vec<PathBuf>,
}

/// Exports the scene to `path` in `format` (by default the one `path`'s extension names),
/// and the cameras to `<path without extension>.cameras.json`.
pub fn export(
    scene: &Scene,
    world: &World,
    path: &Path,
    format: Option<ExportFormat>,
) -> Result<Exported> {
    let by_name = ExportFormat::of_path(path);
    let format = match (format, by_name) {
        (None, Some(f)) => f,
        (Some(f), named) if named == Some(f) => f,
        (Some(f), _) => bail!(
            "option `format` {} writes a .{} file, but option `out` is {}",
            f.name(),
            f.extension(),
            path.display()
        ),
        (None, None) => bail!(
            "export writes .obj or .glb (glTF) or .xml (Mitsuba) files, not {}; name the option `out` file with one of these extensions",
            path.display()
        ),
    };
    let content = ExportScene::new(scene, world)?;
    // Every file is written into a staging folder inside --out's folder and moved into place
    // when all are written: a failure leaves no file, and no folder the export created.
    let name = path
        .file_name()
        .with_context(|| format!("option `out` {} names no file", path.display()))?;
    let staged = StagedDir::inside(
        path.parent().unwrap_or(Path::new("")),
        &name.to_string_lossy(),
    )?;
    let staged_path = staged.path().join(name);
    let mut files = match format {
        ExportFormat::Gltf => crate::io::export::gltf::write_glb(&content, &staged_path)?,
        ExportFormat::Obj => crate::io::export::obj::write_obj(&content, &staged_path)?,
        ExportFormat::Mitsuba => crate::io::export::mitsuba::write_mitsuba(&content, &staged_path)?,
    };
    let cameras_path = staged_path.with_extension("cameras.json");
    write_text(
        &cameras_path,
        &serde_json::to_string_pretty(&cameras_json(scene))?,
    )?;
    files.push(cameras_path);
    let files: Vec<PathBuf> = files.iter().map(|f| staged.final_path(f)).collect();
    refuse_inputs(scene, path, &staged)?;
    staged.commit()?;
    Ok(Exported {
        format,
        triangles: content.triangle_count(),
        files,
    })
}

/// An error where a file the export staged would replace one of its inputs (the scene file,
/// a mesh, an MTL, a texture): `export scene.toml --out m.obj` must not overwrite the scene's
/// m.obj or its m.mtl.
fn refuse_inputs(scene: &Scene, out: &Path, staged: &StagedDir) -> Result<()> {
    let mut pending = vec![staged.path().to_path_buf()];
    while let Some(dir) = pending.pop() {
        let entries =
            std::fs::read_dir(&dir).with_context(|| format!("cannot read {}", dir.display()))?;
        for entry in entries {
            let entry = entry?;
            let staged_file = entry.path();
            if entry.file_type()?.is_dir() {
                pending.push(staged_file);
                continue;
            }
            let file = staged.final_path(&staged_file);
            if let Some(input) = crate::util::input_file::input_at(&file) {
                bail!(
                    "option `out` {}: the export would overwrite {}, an input of the scene {} (read as {}); name another option `out`",
                    out.display(),
                    file.display(),
                    scene.path.display(),
                    input.display()
                );
            }
        }
    }
    Ok(())
}
