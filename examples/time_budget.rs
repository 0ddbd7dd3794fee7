//! What rendering in time costs: das's frontal frame (1280×720, 4 samples) on the vehicle
//! driving at 50 km/h and turning at 20°/s, with a global instant shutter, a rolling one (in
//! one pass, and with the world placed band by band), and an exposure at S = 4 and 16
//! samples against S instant frames of one sample; each the median of 5 renders.
//! `cargo run --example time_budget --release`; docs/guide/time.md shows its table. What each
//! effect costs in misregistration is `seethru sequence --budget` (the same page).

use std::time::Instant;

use anyhow::Result;
use seethru::geometry::shutter::Shutter;
use seethru::render::in_time::render_by_instant;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::RenderSettings;
use seethru::scene::Scene;
use seethru::scene::world::view_bit;
use seethru::system::options::RunOptions;

const READOUT: f64 = 0.030;
const EXPOSURE: f64 = 0.010;

fn main() -> Result<()> {
    let das = Scene::load(std::path::Path::new("scenes/das.toml"))?;
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
    let motion = RunOptions {
        speed_kmh: 50.0,
        yaw_rate_deg_s: 20.0,
        ..RunOptions::default()
    }
    .vehicle_motion(das)?;
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
    println!("| das frontal frame, 1280×720, moving | seconds | ratio |");
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
