//! What each effect of time costs on das at 50 km/h and 20°/s, and what it costs to render:
//! `cargo run --example time_budget --release -- OUT [WIDTH] [SECONDS]` (defaults 320 px,
//! 0.5 s). docs/guide/time.md shows its table and plot.
//!
//! The sequence is das driving at 50 km/h and turning at 20°/s, the frontal image 50 ms old
//! at its 60 Hz refresh, sampled 4 times per refresh (so a rolling scan-out is seen mid-way):
//! once with today's cameras (a global shutter, an instant exposure, a display that shows a
//! refresh at once), then with each effect alone, then with all of them. It prints each
//! variant's mean misregistration over the frames from the second refresh on, and writes `time_budget.png` (each
//! frame's mean misregistration over time) with its CSV into OUT.
//!
//! Then it times das's frontal frame (1280×720, 4 samples) on a moving vehicle: a global
//! instant shutter, a rolling one, and an exposure at S = 4 and 16 samples against S
//! instant frames of one sample.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use seethru::geometry::shutter::{RowOrder, Scanout, Shutter};
use seethru::io::plot::{Figure, Series};
use seethru::measure::image_metrics::Flip;
use seethru::measure::sequence::{Measuring, run_sequence};
use seethru::render::in_time::render_by_instant;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::RenderSettings;
use seethru::scene::Scene;
use seethru::scene::world::view_bit;
use seethru::system::options::RunOptions;
use seethru::system::sequence::head_motion::HeadMotion;
use seethru::system::sequence::predict::Prediction;
use seethru::system::sequence::system_loop::SequenceOptions;
use seethru::system::sequence::timeline::Timeline;

const SPEED: f64 = 50.0 / 3.6;
const YAW_RATE_DEG: f64 = 20.0;
const READOUT: f64 = 0.030;
const EXPOSURE: f64 = 0.010;

/// The variants: a name, and the changes to das's cameras and display.
fn variants() -> Vec<(&'static str, Shutter, Scanout)> {
    let rolling = Shutter {
        readout_s: READOUT,
        exposure_s: 0.0,
        row_order: RowOrder::TopToBottom,
    };
    let exposed = Shutter {
        exposure_s: EXPOSURE,
        ..Shutter::INSTANT
    };
    let scanned = Scanout {
        rolling: true,
        persistence_s: None,
    };
    vec![
        ("latency only", Shutter::INSTANT, Scanout::default()),
        ("+ rolling readout 30 ms", rolling, Scanout::default()),
        ("+ exposure 10 ms", exposed, Scanout::default()),
        ("+ rolling scan-out", Shutter::INSTANT, scanned),
        (
            "all",
            Shutter {
                exposure_s: EXPOSURE,
                ..rolling
            },
            scanned,
        ),
    ]
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = PathBuf::from(
        args.first()
            .context("usage: time_budget OUT [WIDTH] [SECONDS]")?,
    );
    let width: u32 = args.get(1).map_or(Ok(320), |a| a.parse())?;
    let seconds: f64 = args.get(2).map_or(Ok(0.5), |a| a.parse())?;
    std::fs::create_dir_all(&out)?;
    let das = Scene::load(std::path::Path::new("scenes/das.toml"))?;
    let mut series = Vec::new();
    println!(
        "| effect on das, 50 km/h, 20°/s, 50 ms latency | mean misregistration | change | frontal render per refresh |"
    );
    println!("|---|---|---|---|");
    let mut baseline = None;
    for (name, shutter, scanout) in variants() {
        let mut scene = das.clone();
        scene.frontal.shutter = shutter;
        scene.obstacle.scanout = scanout;
        let options = SequenceOptions {
            run: RunOptions {
                spp: 4,
                width: Some(width),
                ..RunOptions::default()
            },
            timeline: Timeline {
                duration: seconds,
                fps: 240.0,
                display_hz: 60.0,
                latency_camera: 0.05,
                latency_tracking: 0.0,
            },
            speed: SPEED,
            yaw_rate: YAW_RATE_DEG.to_radians(),
            head: HeadMotion::Still,
            predict: Prediction::None,
            reproject: false,
            byo: Default::default(),
        };
        let how = Measuring {
            metrics: true,
            full_frames: false,
            band: 5,
            progress: false,
            flip: Flip::Skipped,
        };
        let run = run_sequence(&scene, options, how, &mut |_| Ok(()))?;
        // From the second refresh on: in the first, a rolling scan-out has no image before it
        // to show below its scan line (those rows are dark).
        let points: Vec<(f64, f64)> = run
            .records
            .iter()
            .filter(|r| r.times.refresh > 0)
            .filter_map(|r| r.metrics.map(|m| (r.times.display, m.mean_arcmin)))
            .collect();
        let mean = points.iter().map(|p| p.1).sum::<f64>() / points.len() as f64;
        let change = baseline.map_or(String::from("—"), |b: f64| format!("{:+.1}′", mean - b));
        baseline.get_or_insert(mean);
        let refreshes = (seconds * 60.0).ceil();
        let per_refresh = run.system.frontal / refreshes * 1e3;
        println!("| {name} | {mean:.1}′ | {change} | {per_refresh:.1} ms |");
        series.push(Series::new(name.to_string(), points));
    }
    let top = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(0.0, f64::max);
    Figure {
        title: "das at 50 km/h and 20°/s: the display's misregistration over time".into(),
        x_label: "time (s)".into(),
        y_label: "mean misregistration (arcmin)".into(),
        x_range: (0.0, seconds),
        y_range: (0.0, top * 1.15),
        series,
        bounds: Vec::new(),
        marks: Vec::new(),
        legend: plotters::prelude::SeriesLabelPosition::LowerRight,
    }
    .with_legend_clear_of_data()
    .write(&out, "time_budget")?;
    println!("\nwrote {}", out.join("time_budget.png").display());
    time_renders(&das)
}

/// Seconds of the median of 5 renders of `job` on `ctx`.
fn median_seconds(ctx: &RenderContext, job: RenderJob) -> f64 {
    let mut times: Vec<f64> = (0..5)
        .map(|_| {
            let start = Instant::now();
            let _ = ctx.render(job);
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[2]
}

fn time_renders(das: &Scene) -> Result<()> {
    let ctx = RenderContext::new(das.clone())?;
    let base = ctx.scene.frontal;
    let motion = seethru::scene::motion::VehicleMotion {
        speed: SPEED,
        yaw_rate: YAW_RATE_DEG.to_radians(),
        forward: glam::DVec3::NEG_Z,
        pivot: das.eye(),
    };
    let pose_at = move |dt: f64| motion.world_from_rig(dt) * base.world_from_camera;
    let settings = |spp| RenderSettings {
        spp,
        progress: false,
    };
    let frame = |shutter: Shutter, spp: u32| {
        let camera = seethru::geometry::camera::Camera { shutter, ..base };
        median_seconds(
            &ctx,
            RenderJob::new(&camera, view_bit::FRONTAL)
                .settings(settings(spp))
                .moving(&pose_at),
        )
    };
    let rolling = Shutter {
        readout_s: READOUT,
        ..Shutter::INSTANT
    };
    let exposed = Shutter {
        exposure_s: EXPOSURE,
        ..Shutter::INSTANT
    };
    println!("\n| das frontal frame, 1280×720, moving | seconds | ratio |");
    println!("|---|---|---|");
    let global = frame(Shutter::INSTANT, 4);
    println!("| global shutter, 4 samples | {global:.3} | 1 |");
    let roll = frame(rolling, 4);
    println!(
        "| rolling shutter, 4 samples | {roll:.3} | {:.2} × global |",
        roll / global
    );
    // The world placed band by band (as where a moving object is seen), here all alike.
    let band_by_band = {
        let camera = seethru::geometry::camera::Camera {
            shutter: rolling,
            ..base
        };
        let job = RenderJob::new(&camera, view_bit::FRONTAL)
            .settings(settings(4))
            .moving(&pose_at);
        let mut times = Vec::new();
        for _ in 0..5 {
            let mut out = seethru::render::frame::Frame::new(base.width, base.height);
            let start = Instant::now();
            render_by_instant(
                &mut |_| ctx.with_scene(ctx.scene.clone()),
                0.0,
                job,
                &mut out,
            )?;
            times.push(start.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        times[2]
    };
    println!(
        "| rolling shutter, 4 samples, world placed per band | {band_by_band:.3} | {:.2} × global |",
        band_by_band / global
    );
    let single = frame(Shutter::INSTANT, 1);
    for s in [4, 16] {
        let blurred = frame(exposed, s);
        println!(
            "| exposure, S = {s} samples | {blurred:.3} | {:.2} × S single-instant frames |",
            blurred / (f64::from(s) * single)
        );
    }
    Ok(())
}
