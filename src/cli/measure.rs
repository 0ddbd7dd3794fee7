//! `seethru measure`: the metrics of a `run` directory recomputed from its EXRs.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use seethru::io::frame_files::read_exr;
use seethru::measure::maps::write_metrics;
use seethru::measure::metrics::measure;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;

#[derive(clap::Args)]
pub struct Measure {
    dir: PathBuf,
    #[arg(long, default_value_t = 5)]
    band: u32,
}

impl Measure {
    pub fn run(self) -> Result<()> {
        let metrics = measure_command(&self.dir, self.band)?;
        println!("{}", serde_json::to_string_pretty(&metrics)?);
        Ok(())
    }
}

/// `seethru measure`: the metrics of a run directory, from its saved EXRs.
fn measure_command(dir: &Path, band: u32) -> Result<serde_json::Value> {
    let text = std::fs::read_to_string(dir.join("run.json")).with_context(|| {
        format!(
            "{}: no run.json (not a `seethru run` directory?)",
            dir.display()
        )
    })?;
    let run_json: serde_json::Value = serde_json::from_str(&text)?;
    let scene_path = run_json["scene"]
        .as_str()
        .context("run.json has no scene path")?;
    let ctx = RenderContext::new(Scene::load(Path::new(scene_path))?)?;
    let read = |name: &str| read_exr(&dir.join(format!("{name}.exr")));
    let (truth, seethru, occluded) = (read("truth")?, read("seethru")?, read("occluded")?);
    let (maps, metrics) = measure(
        &ctx,
        &ctx.scene,
        ctx.scene.eye(),
        [&truth, &seethru, &occluded],
        band,
    );
    write_metrics(dir, &maps, &truth, &metrics)?;
    Ok(metrics)
}
