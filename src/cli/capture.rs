//! `seethru capture`: what a real see-through system's algorithm receives, written to a
//! folder — the frontal and back images, the depth sensor's image when asked for, the head
//! tracker's output, calibration.json and a fingerprint — with the truth kept apart in
//! `truth/` (a method must not read it; `seethru score` does).

use std::path::PathBuf;

use anyhow::Result;
use seethru::io::frame_files::ExrContent;
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::capture_files::{capture_spec, spec_scene, write_scoreable_capture};
use seethru::render::integrator::RenderContext;
use seethru::system::capture::capture;
use seethru::system::memory::{check_memory, run_estimate};
use seethru::system::options::RunOptions;

use crate::cli::args::{choice, threads, with_threads};
use crate::cli::option_args::{self, OptionArgs};
use crate::cli::print_warnings;

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
    /// The capture's options: the option table's (`seethru::measure::option_table`).
    #[command(flatten)]
    pub options: OptionArgs<option_args::Capture>,
    /// Which EXRs the capture writes: all (frontal.exr and back.exr in colour, depth.exr with
    /// --depth, truth/truth.exr with every AOV), lean (as all, truth/truth.exr with R, G, B,
    /// Z, N and the ids), colour (the colour EXRs only: truth/truth.exr is R, G, B, A, no
    /// depth.exr) or none (PNGs, depth.npy and the JSON files only).
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::All)]
    pub exr: ExrContent,
    /// Worker threads in [1, 1024] (default: all cores). Images are identical for any value.
    #[arg(long, value_parser = threads)]
    pub threads: Option<usize>,
}

impl CaptureArgs {
    pub fn run(self) -> Result<()> {
        let mut inputs = vec![Input::file("SCENE", &self.scene)];
        inputs.extend(
            self.calibration
                .as_deref()
                .map(|c| Input::file("--calibration", c)),
        );
        check_paths(&inputs, &[Output::folder("--out", &self.out)])?;
        let run = self.options.spec()?;
        let options = RunOptions {
            progress: true,
            ..run.options
        };
        let spec = capture_spec(
            &self.scene,
            self.calibration.as_deref(),
            run.depth,
            &options,
        )?;
        with_threads(self.threads, || {
            let scene = spec_scene(&spec)?;
            print_warnings(&scene);
            check_memory(&run_estimate(&scene, &options)?, run.max_memory_gib)?;
            let ctx = RenderContext::new(scene)?;
            let captured = capture(&ctx, &options, run.depth)?;
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
