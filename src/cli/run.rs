//! `seethru run`: the see-through system end to end on a scene, with every view, run.json and
//! the metrics written to a directory.

use std::path::{Path, PathBuf};

use anyhow::Result;
use rayon::prelude::*;
use seethru::io::atomic::write_text;
use seethru::io::frame_files::write_frame;
use seethru::io::staged::StagedDir;
use seethru::measure::maps::write_metrics;
use seethru::measure::metrics::measure;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::system::display::{DisplayModel, Filter};
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::options::{HeadSource, Method, Outside, RunOptions, WorkingDistance};
use seethru::system::pipeline::run;

use crate::cli::args::{
    RenderArgs, band, head_bias_cm, integer, pixels, positive, real, with_threads,
};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Run {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
    /// none: the whole frontal image in the display; planar: the paper's compensation.
    #[arg(long, value_enum, default_value_t = Method::Planar)]
    method: Method,
    /// Working distance of the planar model: inf, auto (median frontal depth behind the
    /// display) or metres in (0, 1e6].
    #[arg(long, default_value = "inf", value_name = "METRES|inf|auto")]
    d2: WorkingDistance,
    /// oracle: the true eye; estimated: face detection on the back camera's image.
    #[arg(long, value_enum, default_value_t = HeadSource::Oracle)]
    head: HeadSource,
    /// Head-tracking bias, obstacle frame, centimetres: x,y,z, each in [-500, 500]
    /// (e.g. `1,0,0` or `-1,0,0`).
    #[arg(long = "head-bias-cm", value_name = "X,Y,Z", allow_hyphen_values = true, default_value = "0,0,0", value_parser = head_bias_cm)]
    head_bias_cm: [f64; 3],
    /// Head-tracking jitter, standard deviation per axis, centimetres in [0, 100].
    #[arg(long = "head-jitter-cm", default_value_t = 0.0, value_parser = real(0.0, 100.0))]
    head_jitter_cm: f64,
    /// Seed of the jitter, an integer in [0, 4294967295].
    #[arg(long, default_value_t = 1, value_parser = integer::<u32>(0, u32::MAX as u64))]
    seed: u32,
    /// The detector's known feature width A (interpupillary distance), metres in (0, 1].
    #[arg(long = "feature-width", default_value_t = 0.064, value_parser = positive(1.0))]
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
    /// Frontal camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "frontal-width", value_parser = pixels)]
    frontal_width: Option<u32>,
    /// Back camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "back-width", value_parser = pixels)]
    back_width: Option<u32>,
    /// Width of the border band of the mismatch metrics, display pixels in [1, 1000].
    #[arg(long, default_value_t = 5, value_parser = band)]
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
            head_bias_cm: self.head_bias_cm,
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
        let (scene, out, band, max_memory) =
            (&self.scene, &self.out, self.band, self.render.max_memory);
        with_threads(self.render.threads, || {
            run_command(scene, out, &options, band, max_memory)
        })?
    }
}

/// `seethru run`: renders the six views into `out` with `run.json` and the metrics.
fn run_command(
    scene_path: &Path,
    out: &Path,
    options: &RunOptions,
    band: u32,
    max_memory: f64,
) -> Result<()> {
    let scene = Scene::load(scene_path)?;
    check_memory(&run_estimate(&scene, options)?, max_memory)?;
    let ctx = RenderContext::new(scene)?;
    let result = run(&ctx, options)?;
    // Written whole or not at all: a failure leaves `out` as it was.
    let staged = StagedDir::new(out)?;
    let (out, target) = (staged.path(), out);
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
    write_metrics(out, &maps, &result.truth, &metrics)?;
    // Last: a directory with run.json holds a finished run.
    write_text(
        &out.join("run.json"),
        &serde_json::to_string_pretty(&result.report)?,
    )?;
    staged.commit()?;
    seethru::util::progress::summary(format!(
        "wrote the six views (PNG, ids PNG, EXR), run.json and the metrics to {}",
        target.display()
    ));
    Ok(())
}
