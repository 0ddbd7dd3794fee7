//! `seethru capture`: what a real see-through system's algorithm receives, written to a
//! folder — the frontal and back images, the depth sensor's image when asked for, the head
//! tracker's output, calibration.json and a fingerprint — with the truth kept apart in
//! `truth/` (a method must not read it; `seethru score` does).

use std::path::PathBuf;

use anyhow::{Result, bail};
use seethru::io::frame_files::ExrContent;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::capture_files::{capture_spec, spec_scene, write_scoreable_capture};
use seethru::render::integrator::RenderContext;
use seethru::system::capture::capture;
use seethru::system::eyes::{Eye, Eyes, MAX_IPD};
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::options::{HeadSource, RunOptions};
use seethru::system::reads::capture_reads;

use crate::cli::args::{
    HeadErrorArgs, RenderArgs, choice, pixels, positive, refuse_ignored, with_threads,
};
use crate::cli::run_eyes::EyesFlag;
use crate::cli::scene_model_args::SceneModelArgs;

/// The flags of a capture (run's flags that decide what the system receives).
#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct CaptureArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output directory: the system's inputs, with the truth in OUT/truth/.
    #[arg(long)]
    pub out: PathBuf,
    /// A TOML file with a [calibration] table (as in a scene file) that replaces the scene's:
    /// the cameras calibration.json states.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
    /// oracle: the true eye; estimated: face detection on the back camera's image.
    #[arg(long, value_enum, value_parser = choice::<HeadSource>(), default_value_t = HeadSource::Oracle)]
    pub head: HeadSource,
    /// Head-tracking errors and the detector's feature width.
    #[command(flatten)]
    pub head_errors: HeadErrorArgs,
    /// Frontal camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "frontal-width", value_parser = pixels)]
    pub frontal_width: Option<u32>,
    /// Back camera width, pixels in [1, 16384] (aspect ratio kept; default: the scene's).
    #[arg(long = "back-width", value_parser = pixels)]
    pub back_width: Option<u32>,
    /// The eye the driver's views are rendered from: mono, left or right (not both).
    #[arg(long, value_enum, value_parser = choice::<EyesFlag>(), default_value_t = EyesFlag::Mono)]
    pub eyes: EyesFlag,
    /// Interpupillary distance, metres in [1e-6, 0.1].
    #[arg(long, default_value_t = 0.064, value_parser = positive(MAX_IPD))]
    pub ipd: f64,
    /// The eye the head estimate is for.
    #[arg(long = "target-eye", value_enum, value_parser = choice::<Eye>(), default_value_t = Eye::Cyclopean)]
    pub target_eye: Eye,
    /// Write the depth sensor's image (depth.npy, depth.exr), as --method depth models it
    /// with --depth-sensor and its settings.
    #[arg(long)]
    pub depth: bool,
    /// The depth sensor (with --depth).
    #[command(flatten)]
    pub scene_model: SceneModelArgs,
    /// Which EXRs the capture writes: all (frontal.exr and back.exr in colour, depth.exr with
    /// --depth, truth/truth.exr with every AOV), lean (as all, truth/truth.exr with R, G, B,
    /// Z, N and the ids), colour (the colour EXRs only: truth/truth.exr is R, G, B, A, no
    /// depth.exr) or none (PNGs, depth.npy and the JSON files only).
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::All)]
    pub exr: ExrContent,
    /// Sizes of the driver's view (the truth), samples, threads.
    #[command(flatten)]
    pub render: RenderArgs,
}

impl CaptureArgs {
    /// The run options of the capture (the method's choices left at their defaults).
    pub fn options(&self) -> Result<RunOptions> {
        if self.eyes == EyesFlag::Both {
            bail!("--eyes both: a capture is for one eye (mono, left or right)");
        }
        let options = RunOptions {
            head: self.head,
            head_bias_cm: self.head_errors.head_bias_cm,
            head_jitter_cm: self.head_errors.head_jitter_cm,
            seed: self.head_errors.seed,
            feature_width: self.head_errors.feature_width,
            require_confident_head: self.head_errors.require_confident_head,
            width: self.render.width,
            height: self.render.height,
            frontal_width: self.frontal_width,
            back_width: self.back_width,
            spp: self.render.spp,
            eyes: Eyes {
                view: self.eyes.view(),
                target: self.target_eye,
                ipd: self.ipd,
            },
            scene_model: self.scene_model.options(),
            progress: true,
            ..RunOptions::default()
        };
        refuse_ignored(&capture_reads(&options, self.depth))?;
        Ok(options)
    }

    pub fn run(self) -> Result<()> {
        let mut inputs = vec![Input::file("SCENE", &self.scene)];
        inputs.extend(
            self.calibration
                .as_deref()
                .map(|c| Input::file("--calibration", c)),
        );
        check_paths(&inputs, &[Output::folder("--out", &self.out)])?;
        let options = self.options()?;
        let spec = capture_spec(
            &self.scene,
            self.calibration.as_deref(),
            self.depth,
            &options,
        )?;
        with_threads(self.render.threads, || {
            let scene = spec_scene(&spec)?;
            check_memory(&run_estimate(&scene, &options)?, self.render.max_memory)?;
            let ctx = RenderContext::new(scene)?;
            let captured = capture(&ctx, &options, self.depth)?;
            let staged = StagedDir::new(&self.out)?;
            write_scoreable_capture(staged.path(), &captured, &spec, self.exr)?;
            staged.commit()?;
            seethru::util::progress::summary(format!(
                "captured {} (fingerprint {}): frontal {}×{}, back {}×{}{}, head.json, calibration.json; the truth in {}",
                self.out.display(),
                captured.fingerprint,
                captured.frontal.width,
                captured.frontal.height,
                captured.back.width,
                captured.back.height,
                captured.depth.as_ref().map_or(String::new(), |d| format!(
                    ", depth {}×{}",
                    d.camera.width, d.camera.height
                )),
                self.out.join("truth").display()
            ));
            Ok(())
        })?
    }
}
