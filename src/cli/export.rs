//! `seethru export`: the scene for other renderers — binary glTF, OBJ + MTL, or Mitsuba 3 XML
//! scenes — and its cameras as JSON.

use crate::cli::args::choice;
use crate::cli::load_scene;
use std::path::{Path, PathBuf};

use anyhow::Result;
use seethru::io::export::ExportFormat;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::scene::world::World;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Export {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Output file: .glb (glTF), .obj or .xml (Mitsuba 3); <name>.cameras.json goes beside it.
    #[arg(long)]
    out: PathBuf,
    /// Output format; by default the one --out's extension names.
    #[arg(long, value_enum, value_parser = choice::<ExportFormat>())]
    format: Option<ExportFormat>,
}

impl Export {
    pub fn run(self) -> Result<()> {
        check_paths(
            &[Input::file("SCENE", &self.scene)],
            &[Output::file("--out", &self.out)],
        )?;
        export_scene(&self.scene, &self.out, self.format)
    }
}

fn export_scene(scene_path: &Path, out: &Path, format: Option<ExportFormat>) -> Result<()> {
    let scene = load_scene(scene_path)?;
    let world = World::build(&scene)?;
    // The formats are written flat: every placement of an instanced mesh its own triangles.
    let flat = world.triangles.len() + world.instanced_count();
    if flat > seethru::scene::limits::MAX_TRIANGLES {
        anyhow::bail!(
            "{}: its instanced meshes flatten to {flat} triangles, more than export's limit of {}",
            scene_path.display(),
            seethru::scene::limits::MAX_TRIANGLES
        );
    }
    let world = world.flattened();
    let exported = seethru::io::export::export(&scene, &world, out, format)?;
    let assets = seethru::io::export::content::assets_dir(out);
    let (in_assets, beside): (Vec<_>, Vec<_>) =
        exported.files.iter().partition(|f| f.starts_with(&assets));
    let beside: Vec<String> = beside.iter().map(|f| f.display().to_string()).collect();
    let mut message = format!(
        "wrote {} triangles as {}: {}",
        exported.triangles,
        exported.format.name(),
        beside.join(", ")
    );
    if !in_assets.is_empty() {
        let n = in_assets.len();
        let files = if n == 1 { "file" } else { "files" };
        message += &format!(" and {n} {files} in {}", assets.display());
    }
    seethru::util::progress::summary(message);
    Ok(())
}
