//! The `render` and `export` commands.

use std::path::Path;

use anyhow::{Context, Result};

use crate::accel::BvhKind;
use crate::options::resized;
use crate::output::write_frame;
use crate::render::{RenderContext, RenderSettings};
use crate::scene::Scene;
use crate::views::View;
use crate::world::World;

pub struct RenderOptions {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub spp: u32,
    pub bvh: BvhKind,
    pub progress: bool,
}

/// Renders `views` of the scene into `out` (created if needed).
pub fn render_views(
    scene_path: &Path,
    views: &[View],
    out: &Path,
    options: &RenderOptions,
) -> Result<()> {
    crate::options::check_spp(options.spp)?;
    let scene = Scene::load(scene_path)?;
    // Check every camera before the first (possibly long) render.
    let cameras = views
        .iter()
        .map(|v| resized(v.camera(&scene), options.width, options.height))
        .collect::<Result<Vec<_>>>()?;
    let context = RenderContext::new(scene, options.bvh)?;
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output directory {}", out.display()))?;
    let settings = RenderSettings {
        spp: options.spp,
        progress: options.progress,
    };
    for (view, camera) in views.iter().zip(&cameras) {
        let (frame, stats) = context.render(camera, view.bit(), settings, view.name());
        write_frame(&frame, out, view.name())?;
        eprintln!(
            "{}: {}×{} in {:.2} s → {}",
            view.name(),
            camera.width,
            camera.height,
            stats.seconds,
            out.join(format!("{}.png", view.name())).display()
        );
    }
    Ok(())
}

pub fn export_scene(scene_path: &Path, out: &Path) -> Result<()> {
    let scene = Scene::load(scene_path)?;
    let world = World::build(&scene)?;
    let count = crate::export::export(&scene, &world, out)?;
    eprintln!(
        "wrote {count} triangles to {} and cameras to {}",
        out.display(),
        out.with_extension("cameras.json").display()
    );
    Ok(())
}
