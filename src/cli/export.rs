//! `seethru export`: the scene's triangles as OBJ or binary glTF, and its cameras as JSON.

use std::path::{Path, PathBuf};

use anyhow::Result;
use seethru::scene::Scene;
use seethru::scene::world::World;

#[derive(clap::Args)]
pub struct Export {
    scene: PathBuf,
    /// Output file, .obj or .glb.
    #[arg(long)]
    out: PathBuf,
}

impl Export {
    pub fn run(self) -> Result<()> {
        export_scene(&self.scene, &self.out)
    }
}

fn export_scene(scene_path: &Path, out: &Path) -> Result<()> {
    let scene = Scene::load(scene_path)?;
    let world = World::build(&scene)?;
    let count = seethru::io::export::export(&scene, &world, out)?;
    eprintln!(
        "wrote {count} triangles to {} and cameras to {}",
        out.display(),
        out.with_extension("cameras.json").display()
    );
    Ok(())
}
