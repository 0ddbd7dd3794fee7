//! `seethru measure`: the metrics of a `run` directory recomputed from its EXRs.

use crate::cli::load_scene;
use crate::cli::with_flags;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use seethru::io::output_paths::{Input, check_paths};
use seethru::io::run_dir::MAX_RUN_JSON_BYTES;
use seethru::io::run_dir::{read_measured_frames, read_run_json};
use seethru::io::staged::StagedDir;
use seethru::measure::holes::{hole_metrics, read_hole_mask};
use seethru::measure::maps::write_metrics;
use seethru::measure::metrics::measure;
use seethru::measure::metrics_json::Metrics;
use seethru::measure::viewer::{RunPixels, write_run_view};
use seethru::render::frame_over::FrameView;
use seethru::render::integrator::RenderContext;
use seethru::util::input_file::read_input_text;

use crate::cli::args::band;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Measure {
    /// A `seethru run` output directory (its run.json names the scene).
    dir: PathBuf,
    /// Width of the border band of the mismatch metrics, display pixels in [1, 1000].
    #[arg(long, default_value_t = 5, value_parser = band)]
    band: u32,
}

impl Measure {
    pub fn run(self) -> Result<()> {
        check_paths(&[Input::folder("DIR", &self.dir)], &[])?;
        let metrics = measure_command(&self.dir, self.band)?;
        println!(
            "{}",
            serde_json::to_string_pretty(&with_flags(&metrics.to_json()))?
        );
        Ok(())
    }
}

/// `seethru measure`: the metrics of a run directory, from its saved EXRs.
fn measure_command(dir: &Path, band: u32) -> Result<Metrics> {
    let record = read_run_json(dir)?;
    let run_json = dir.join("run.json");
    // `run` records the scene as given (relative to the folder it was started in) and
    // absolute; older run.json files have only the first, read relative to this folder.
    let scene_path = record
        .scene_absolute
        .clone()
        .unwrap_or(record.scene.clone());
    let scene = load_scene(&scene_path).with_context(|| {
        format!(
            "the scene {} that {} names (`scene` = {})",
            shown_absolute(&scene_path),
            run_json.display(),
            record.scene.display()
        )
    })?;
    if let Some(recorded) = &record.scene_hash
        && *recorded != scene.source_hash
    {
        bail!(
            "{} has changed since the run that wrote {} (its content hash is {}, the run recorded {}): measure needs the scene the run rendered; run `seethru run` again",
            shown_absolute(&scene_path),
            run_json.display(),
            scene.source_hash,
            recorded
        );
    }
    let ctx = RenderContext::new(scene)?;
    let [truth, seethru, occluded] = read_measured_frames(dir)?;
    // The eye the run's views were rendered from (`--eyes left|right`), else the scene's.
    let eye = record
        .view_eye
        .map_or(ctx.scene.eye(), glam::DVec3::from_array);
    let (maps, mut metrics) = measure(
        &ctx,
        &ctx.scene,
        eye,
        [&truth, &seethru, &occluded].map(FrameView::from),
        band,
    );
    // A depth run's holes, as its holes.png has them.
    if let Some(holes) = read_hole_mask(&dir.join("holes.png"), truth.width, truth.height)? {
        let run: serde_json::Value =
            serde_json::from_str(&read_input_text(&dir.join("run.json"), MAX_RUN_JSON_BYTES)?)?;
        let fill = run["scene_model"]["holes"]["fill"].clone();
        metrics.holes = Some(hole_metrics(&holes, &maps, &truth, &seethru, fill));
    }
    // Whole or not at all: staged beside the run folder, moved in when all are written.
    let staged = StagedDir::new(dir)?;
    write_metrics(
        staged.path(),
        &maps,
        &truth,
        &with_flags(&metrics.to_json()),
    )?;
    let pixels = RunPixels::of_run(&maps, &truth, FrameView::from(&seethru));
    write_run_view(staged.path(), dir, &pixels)?;
    staged.commit()?;
    Ok(metrics)
}

/// `path` made absolute for a message (as found from this folder), else as it is.
fn shown_absolute(path: &Path) -> String {
    std::path::absolute(path)
        .unwrap_or_else(|_| path.to_path_buf())
        .display()
        .to_string()
}
