//! `seethru bench`: BVH build time, rays per second and frame times on a scene.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use seethru::render::accel::BvhKind;
use seethru::render::integrator::RenderContext;
use seethru::render::settings::{RenderSettings, check_resolution};
use seethru::render::views::View;
use seethru::scene::Scene;
use serde_json::json;

use crate::cli::args::with_threads;

#[derive(clap::Args)]
pub struct Bench {
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
}

impl Bench {
    pub fn run(self) -> Result<()> {
        check_resolution(self.width, self.height)?;
        with_threads(self.threads, || bench(&self).map(|_| ()))?
    }
}

/// Runs the benchmark, prints a human-readable report and ends with one JSON line.
fn bench(options: &Bench) -> Result<serde_json::Value> {
    let scene_path: &Path = &options.scene;
    let load = Instant::now();
    let scene = Scene::load(scene_path)?;
    let context = RenderContext::new(scene, options.bvh)?;
    let load_s = load.elapsed().as_secs_f64();
    let prims = context.world.primitive_count();
    println!(
        "scene        {} ({prims} primitives, loaded in {load_s:.3} s)",
        scene_path.display()
    );
    println!(
        "bvh          {:?} built in {:.1} ms",
        options.bvh,
        context.accel.build_time.as_secs_f64() * 1e3
    );
    println!("threads      {}", rayon::current_num_threads());
    let mut views = serde_json::Map::new();
    let (mut total_rays, mut total_s) = (0u64, 0.0);
    for view in [View::Truth, View::Frontal] {
        let camera = view
            .camera(&context.scene)
            .with_resolution(options.width, options.height);
        let runs: Vec<_> = (0..options.repeat.max(1))
            .map(|_| {
                context
                    .render(&camera, view.bit(), RenderSettings::default(), view.name())
                    .1
            })
            .collect();
        let best = runs
            .iter()
            .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
            .copied()
            .unwrap_or_default();
        let rays = best.primary_rays + best.shadow_rays;
        total_rays += rays;
        total_s += best.seconds;
        println!(
            "{:<12} {}×{}: frame {:7.1} ms  primary {:6.2} Mrays/s  primary+shadow {:6.2} Mrays/s ({} + {} rays)",
            view.name(),
            options.width,
            options.height,
            best.seconds * 1e3,
            best.primary_rays as f64 / best.seconds / 1e6,
            rays as f64 / best.seconds / 1e6,
            best.primary_rays,
            best.shadow_rays,
        );
        views.insert(
            view.name().into(),
            json!({
                "frame_ms": best.seconds * 1e3,
                "frame_ms_all_runs": runs.iter().map(|r| r.seconds * 1e3).collect::<Vec<_>>(),
                "primary_rays": best.primary_rays,
                "shadow_rays": best.shadow_rays,
                "primary_rays_per_s": best.primary_rays as f64 / best.seconds,
                "rays_per_s": rays as f64 / best.seconds,
            }),
        );
    }
    println!(
        "overall      {:.2} Mrays/s primary+shadow",
        total_rays as f64 / total_s / 1e6
    );
    let report = json!({
        "scene": scene_path.display().to_string(),
        "primitives": prims,
        "bvh": format!("{:?}", options.bvh).to_lowercase(),
        "bvh_build_ms": context.accel.build_time.as_secs_f64() * 1e3,
        "threads": rayon::current_num_threads(),
        "width": options.width,
        "height": options.height,
        "views": views,
        "rays_per_s": total_rays as f64 / total_s,
    });
    println!("{report}");
    Ok(report)
}
