//! `seethru render`: views of a scene as colour PNG, id PNG and an EXR with every AOV.

use crate::cli::load_scene;
use std::path::{Path, PathBuf};

use anyhow::Result;
use seethru::io::frame_files::{ExrContent, write_frame};
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::run_spec::RunSpec;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::{RenderSettings, resized};
use seethru::render::views::View;
use seethru::system::memory::{check_memory, render_estimate};

use crate::cli::args::{choice, threads, with_threads};
use crate::cli::option_args::{self, OptionArgs};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Render {
    /// Scene file (TOML).
    scene: PathBuf,
    /// View to render; repeat for several. Default: all four.
    #[arg(long = "view", value_enum, value_parser = choice::<View>())]
    views: Vec<View>,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
    /// What each view's EXR holds: none, colour (R, G, B, A), lean (R, G, B, Z, N and the
    /// ids) or all (every AOV).
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::All)]
    exr: ExrContent,
    /// The size, samples and memory bound, from the option table.
    #[command(flatten)]
    options: OptionArgs<option_args::Render>,
    /// Worker threads in [1, 1024] (default: all cores). Images are identical for any value.
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
}

impl Render {
    pub fn run(self) -> Result<()> {
        check_paths(
            &[Input::file("SCENE", &self.scene)],
            &[Output::folder("--out", &self.out)],
        )?;
        let views = if self.views.is_empty() {
            View::ALL.to_vec()
        } else {
            self.views.clone()
        };
        let spec = self.options.spec()?;
        with_threads(self.threads, || {
            render_views(&self.scene, &views, &self.out, &spec, self.exr)
        })?
    }
}

/// Renders `views` of the scene into `out` (created if needed).
fn render_views(
    scene_path: &Path,
    views: &[View],
    out: &Path,
    spec: &RunSpec,
    exr: ExrContent,
) -> Result<()> {
    let options = &spec.options;
    let scene = load_scene(scene_path)?;
    // Check every camera before the first (possibly long) render.
    let cameras = views
        .iter()
        .map(|v| {
            resized(
                v.camera(&scene),
                options.width,
                options.height,
                "option `width`/option `height`",
            )
        })
        .collect::<Result<Vec<_>>>()?;
    check_memory(&render_estimate(&cameras), spec.max_memory_gib)?;
    let context = RenderContext::new(scene)?;
    // Written whole or not at all: a failure leaves `out` as it was.
    let staged = StagedDir::new(out)?;
    let settings = RenderSettings {
        spp: options.spp,
        progress: true,
    };
    let mut rendered = Vec::new();
    for (view, camera) in views.iter().zip(&cameras) {
        let (frame, stats) = context.render(
            RenderJob::new(camera, view.bit())
                .settings(settings)
                .label(view.name()),
        );
        write_frame(&frame, staged.path(), view.name(), exr)?;
        rendered.push(format!(
            "{} {}×{} in {:.2} s",
            view.name(),
            camera.width,
            camera.height,
            stats.seconds
        ));
    }
    staged.commit()?;
    seethru::util::progress::summary(format!(
        "rendered {} ({} each) → {}",
        rendered.join(", "),
        exr.files(),
        out.display()
    ));
    Ok(())
}
