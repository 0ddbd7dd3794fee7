//! `seethru run`: the see-through system end to end on a scene, with every view, run.json and
//! the metrics written to a directory.

use crate::cli::load_scene;
use seethru::util::option_words::as_flags;
use std::path::{Path, PathBuf};

use anyhow::Result;
use seethru::io::frame_files::ExrContent;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::headline::{read_results, summary_text};
use seethru::measure::run_files::{RunWrites, write_run};
use seethru::render::integrator::RenderContext;
use seethru::scene::lens_keys::read_calibration_file;
use seethru::system::memory::{both_eyes_estimate, check_memory, run_estimate};
use seethru::system::options::RunOptions;
use seethru::system::pipeline::RunResult;
use seethru::system::reads::hazard_bound_reads;

use crate::cli::args::{choice, positive, refuse_ignored, threads, with_threads};
use crate::cli::option_args::{self, OptionArgs};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Run {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
    /// A TOML file with a [calibration] table (as in a scene file) that replaces the scene's:
    /// the compensation's own copy of the cameras.
    #[arg(long, value_name = "FILE")]
    calibration: Option<PathBuf>,
    /// The run's options: the option table's (`seethru::measure::option_table`).
    #[command(flatten)]
    options: OptionArgs<option_args::Run>,
    /// What each view's EXR holds: none; colour (R, G, B, A); lean (R, G, B, Z, N and the
    /// ids: every AOV that no other channel gives); all (lean with A, P and camera_z.Z: what
    /// `seethru measure` reads back).
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::Lean)]
    exr: ExrContent,
    /// Top of misregistration.png's scale, arc-minutes in [1e-6, 10000], so that heatmaps of
    /// runs compare (default: the 99th percentile of the display's values, labelled).
    #[arg(long = "heatmap-max", value_name = "ARCMIN", value_parser = positive(1e4))]
    heatmap_max: Option<f64>,
    /// Worker threads in [1, 1024] (default: all cores). Images are identical for any value.
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
}

impl Run {
    pub fn run(self) -> Result<()> {
        let mut inputs = vec![Input::file("SCENE", &self.scene)];
        inputs.extend(
            self.calibration
                .as_deref()
                .map(|c| Input::file("--calibration", c)),
        );
        check_paths(&inputs, &[Output::folder("--out", &self.out)])?;
        let spec = self.options.spec()?;
        let options = RunOptions {
            progress: true,
            ..spec.options
        };
        let both = spec.both_eyes;
        let (scene, out, max_memory) = (&self.scene, &self.out, spec.max_memory_gib);
        let writes = RunWrites {
            band: spec.measure.band,
            exr: self.exr,
            hazard_bound_arcmin: spec.measure.hazard_bound_arcmin,
            heatmap_max_arcmin: self.heatmap_max.map(|v| v as f32),
            timings: true,
        };
        let calibration = self.calibration.as_deref();
        with_threads(self.threads, || {
            run_command(scene, calibration, out, &options, writes, max_memory, both)
        })?
    }
}

/// `seethru run`: renders the six views into `out` with `run.json` and the metrics.
fn run_command(
    scene_path: &Path,
    calibration: Option<&Path>,
    out: &Path,
    options: &RunOptions,
    writes: RunWrites,
    max_memory: f64,
    both: bool,
) -> Result<()> {
    let mut scene = load_scene(scene_path)?;
    refuse_ignored(&[hazard_bound_reads(&scene)])?;
    if let Some(path) = calibration {
        scene.calibration = read_calibration_file(path, &scene.frontal, &scene.back)?;
    }
    let estimate = match both {
        true => both_eyes_estimate(&scene, options)?,
        false => run_estimate(&scene, options)?,
    };
    check_memory(&estimate, max_memory)?;
    let ctx = RenderContext::new(scene)?;
    // Written whole or not at all: a failure leaves `out` as it was.
    let staged = StagedDir::new(out)?;
    let summary = if both {
        crate::cli::run_eyes::run_both(&ctx, staged.path(), out, options, |options, dir| {
            write_run_told(&ctx, dir, options, writes)
        })?
    } else {
        write_run_told(&ctx, staged.path(), options, writes)?;
        let files = writes.exr.files();
        let (kind, metrics) = read_results(staged.path())?;
        format!(
            "{}; wrote the six views ({files}), run.json, the metrics and view.html to {}",
            summary_text(kind, &metrics),
            out.display()
        )
    };
    staged.commit()?;
    seethru::util::progress::summary(summary);
    Ok(())
}

/// [`write_run`] with its warnings on stderr.
fn write_run_told(
    ctx: &RenderContext,
    out: &Path,
    options: &RunOptions,
    writes: RunWrites,
) -> Result<RunResult> {
    let written = write_run(ctx, out, options, writes)?;
    for warning in &written.warnings {
        eprintln!("warning: {}", as_flags(warning));
    }
    Ok(written.result)
}
