//! Command line: parses arguments and dispatches to the library.
#![forbid(unsafe_code)]

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use seethru::accel::BvhKind;
use seethru::bench::{BenchOptions, bench};
use seethru::commands::{RenderOptions, export_scene, render_views};
use seethru::options::{check_resolution, with_threads};
use seethru::views::View;

#[derive(Parser)]
#[command(
    name = "seethru",
    version,
    about = "Simulates video see-through displays for driver assistance and measures how well they work"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render views of a scene: colour PNG, id PNG and an EXR with every AOV per view.
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// View to render; repeat for several. Default: all four.
        #[arg(long = "view", value_enum)]
        views: Vec<View>,
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// Image width in pixels (default: the camera's; height follows the aspect ratio if not given).
        #[arg(long)]
        width: Option<u32>,
        /// Image height in pixels.
        #[arg(long)]
        height: Option<u32>,
        /// Samples per pixel (anti-aliasing of the colour; AOVs are at pixel centres).
        #[arg(long, default_value_t = 4)]
        spp: u32,
        /// Worker threads (default: all cores). Images are identical for any value.
        #[arg(long)]
        threads: Option<usize>,
        #[arg(long, value_enum, default_value_t = BvhKind::Cwbvh)]
        bvh: BvhKind,
    },
    /// Write the scene's triangles (.obj or .glb) and its cameras (<name>.cameras.json).
    Export {
        scene: PathBuf,
        /// Output file, .obj or .glb.
        #[arg(long)]
        out: PathBuf,
    },
    /// Benchmark: BVH build time, rays per second, frame times; ends with one JSON line.
    Bench {
        scene: PathBuf,
        #[arg(long, default_value_t = 1280)]
        width: u32,
        #[arg(long, default_value_t = 720)]
        height: u32,
        /// Renders per view; the fastest counts.
        #[arg(long, default_value_t = 3)]
        repeat: usize,
        #[arg(long)]
        threads: Option<usize>,
        #[arg(long, value_enum, default_value_t = BvhKind::Cwbvh)]
        bvh: BvhKind,
    },
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Render {
            scene,
            views,
            out,
            width,
            height,
            spp,
            threads,
            bvh,
        } => {
            let views = if views.is_empty() {
                View::ALL.to_vec()
            } else {
                views
            };
            let options = RenderOptions {
                width,
                height,
                spp,
                bvh,
                progress: true,
            };
            with_threads(threads, || render_views(&scene, &views, &out, &options))?
        }
        Command::Export { scene, out } => export_scene(&scene, &out),
        Command::Bench {
            scene,
            width,
            height,
            repeat,
            threads,
            bvh,
        } => {
            check_resolution(width, height)?;
            let options = BenchOptions {
                width,
                height,
                repeat,
                bvh,
            };
            with_threads(threads, || bench(&scene, &options).map(|_| ()))?
        }
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
