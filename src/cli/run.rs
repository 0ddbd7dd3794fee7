//! `seethru run`: the see-through system end to end on a scene, with every view, run.json and
//! the metrics written to a directory.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use rayon::prelude::*;
use seethru::io::atomic::write_text;
use seethru::io::frame_files::write_frame;
use seethru::measure::maps::write_metrics;
use seethru::measure::metrics::measure;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::system::display::{DisplayModel, Filter};
use seethru::system::options::{HeadSource, Method, Outside, RunOptions, WorkingDistance};
use seethru::system::pipeline::run;

use crate::cli::args::{RenderArgs, with_threads};

#[derive(clap::Args)]
pub struct Run {
    scene: PathBuf,
    #[arg(long)]
    out: PathBuf,
    /// none: the whole frontal image in the display; planar: the paper's compensation.
    #[arg(long, value_enum, default_value_t = Method::Planar)]
    method: Method,
    /// Working distance of the planar model: inf, auto (median frontal depth behind the
    /// display) or metres.
    #[arg(long, default_value = "inf")]
    d2: WorkingDistance,
    /// oracle: the true eye; estimated: face detection on the back camera's image.
    #[arg(long, value_enum, default_value_t = HeadSource::Oracle)]
    head: HeadSource,
    /// Head-tracking bias, obstacle frame, centimetres: x,y,z.
    #[arg(long = "head-bias-cm", value_delimiter = ',', num_args = 3, allow_hyphen_values = true, default_values_t = [0.0, 0.0, 0.0])]
    head_bias_cm: Vec<f64>,
    /// Head-tracking jitter, standard deviation per axis, centimetres.
    #[arg(long = "head-jitter-cm", default_value_t = 0.0)]
    head_jitter_cm: f64,
    /// Seed of the jitter.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// The detector's known feature width A (interpupillary distance), metres.
    #[arg(long = "feature-width", default_value_t = 0.064)]
    feature_width: f64,
    /// When the crop leaves the frontal view: error, or black (flagged as missing).
    #[arg(long, value_enum, default_value_t = Outside::Error)]
    outside: Outside,
    /// Colour resampling of the display image.
    #[arg(long, value_enum, default_value_t = Filter::Bilinear)]
    filter: Filter,
    /// pixels: the physical display; ideal: unlimited display and frontal resolution, so
    /// that only the planar model's error remains.
    #[arg(long, value_enum, default_value_t = DisplayModel::Pixels)]
    display: DisplayModel,
    /// Frontal camera width in pixels (aspect ratio kept).
    #[arg(long = "frontal-width")]
    frontal_width: Option<u32>,
    /// Back camera width in pixels (aspect ratio kept).
    #[arg(long = "back-width")]
    back_width: Option<u32>,
    /// Width of the border band of the mismatch metrics, display pixels.
    #[arg(long, default_value_t = 5)]
    band: u32,
    /// Sizes (width and height: the driver views truth, occluded, seethru), samples, threads.
    #[command(flatten)]
    render: RenderArgs,
}

impl Run {
    pub fn run(self) -> Result<()> {
        let options = RunOptions {
            method: self.method,
            d2: self.d2,
            head: self.head,
            head_bias_cm: [
                self.head_bias_cm[0],
                self.head_bias_cm[1],
                self.head_bias_cm[2],
            ],
            head_jitter_cm: self.head_jitter_cm,
            seed: self.seed,
            feature_width: self.feature_width,
            width: self.render.width,
            height: self.render.height,
            frontal_width: self.frontal_width,
            back_width: self.back_width,
            spp: self.render.spp,
            outside: self.outside,
            filter: self.filter,
            display: self.display,
            progress: true,
        };
        let (scene, out, band) = (&self.scene, &self.out, self.band);
        with_threads(self.render.threads, || {
            run_command(scene, out, &options, band)
        })?
    }
}

/// `seethru run`: renders the six views into `out` with `run.json` and the metrics.
fn run_command(scene_path: &Path, out: &Path, options: &RunOptions, band: u32) -> Result<()> {
    let scene = Scene::load(scene_path)?;
    let ctx = RenderContext::new(scene)?;
    let result = run(&ctx, options)?;
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output directory {}", out.display()))?;
    let views = [
        ("truth", &result.truth),
        ("occluded", &result.occluded),
        ("frontal", &result.frontal),
        ("back", &result.back),
        ("display", &result.display),
        ("seethru", &result.seethru),
    ];
    // Encoding PNGs and EXRs is mostly single-threaded work: the six views are written side
    // by side, and beside the metrics. The files are the same whatever the order.
    let (written, (maps, metrics)) = rayon::join(
        || {
            views
                .par_iter()
                .try_for_each(|(name, frame)| write_frame(frame, out, name))
        },
        || {
            let frames = [&result.truth, &result.seethru, &result.occluded];
            measure(&ctx, &ctx.scene, ctx.scene.eye(), frames, band)
        },
    );
    written?;
    write_text(
        &out.join("run.json"),
        &serde_json::to_string_pretty(&result.report)?,
    )?;
    write_metrics(out, &maps, &result.truth, &metrics)?;
    eprintln!(
        "wrote the six views (PNG, ids PNG, EXR), run.json and the metrics to {}",
        out.display()
    );
    Ok(())
}
