//! CPU time per ray of `bench`'s ray batches and shaded `truth` frame, on one worker thread
//! or more: `cargo run --example ray_cpu_time --release -- scenes/das.toml 7 1 1 1280 720`
//! (scene, repeats, `--grow` factor, threads, image width and height; all but the scene
//! optional).
//!
//! `bench` reports wall time, which on a shared machine measures the other processes as much
//! as the tracer. This reads the CPU time the kernel charged to this process's threads
//! (`/proc/self/task/*/schedstat`, nanoseconds on a CPU), so time spent waiting for a core is
//! left out; caches shared with other processes still count. Prints the median of the
//! repeats per row, in nanoseconds per ray (per pixel for the frame), after one untimed run;
//! beside it the wall time per ray times the threads, so that on several threads the gap
//! between the two is the time a worker waited (idle or out of work) rather than traced.

use std::path::Path;

use anyhow::{Context, Result, bail};
use seethru::render::frame::Frame;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::simd::Isa;
use seethru::render::throughput::{
    camera_batch, cosine_batch, shadow_batch, trace_any, trace_any_per_ray, trace_closest,
    trace_closest_per_ray,
};
use seethru::render::views::View;
use seethru::scene::Scene;
use seethru::scene::grow::grow;
use seethru::util::cpu_time::threads_cpu_ns;

fn number<T: std::str::FromStr>(
    arg: Option<&String>,
    name: &str,
    default: T,
    range: &str,
) -> Result<T> {
    match arg {
        None => Ok(default),
        Some(s) => s
            .parse()
            .ok()
            .with_context(|| format!("{name} '{s}' is not a number in {range}")),
    }
}

/// CPU nanoseconds of every thread of this process so far.
fn cpu_ns() -> Result<u64> {
    threads_cpu_ns().context("no per-thread CPU times here (/proc/self/task/*/schedstat)")
}

fn main() {
    if let Err(e) = measure() {
        eprintln!("error: {e:#}");
        std::process::exit(2);
    }
}

fn measure() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(scene) = args.first() else {
        bail!(
            "usage: ray_cpu_time SCENE [REPEATS in [1, 1000]] [GROW in [1, 1000]] \
             [THREADS in [1, 1024]] [WIDTH HEIGHT in [1, 16384]]"
        );
    };
    let repeats: usize = number(args.get(1), "REPEATS", 7, "[1, 1000]")?;
    let factor: f64 = number(args.get(2), "GROW", 1.0, "[1, 1000]")?;
    if !(1..=1000).contains(&repeats) {
        bail!("REPEATS {repeats} is outside [1, 1000]");
    }
    if !(1.0..=1000.0).contains(&factor) {
        bail!("GROW {factor} is outside [1, 1000]");
    }
    let threads: usize = number(args.get(3), "THREADS", 1, "[1, 1024]")?;
    let width: u32 = number(args.get(4), "WIDTH", 1280, "[1, 16384]")?;
    let height: u32 = number(args.get(5), "HEIGHT", 720, "[1, 16384]")?;
    if !(1..=1024).contains(&threads) {
        bail!("THREADS {threads} is outside [1, 1024]");
    }
    if !(1..=16384).contains(&width) || !(1..=16384).contains(&height) {
        bail!("WIDTH HEIGHT {width} {height} are outside [1, 16384]");
    }
    if let Some(extra) = args.get(6) {
        bail!("unexpected argument '{extra}' after HEIGHT");
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_global()?;
    let ctx = RenderContext::new(grow(&Scene::load(Path::new(scene))?, factor)?)?;
    let isa = Isa::best();
    let camera = View::Truth
        .camera(&ctx.scene)
        .with_resolution(width, height);
    let primary = camera_batch(&camera, View::Truth.bit());
    let mut hits = vec![None; primary.rays.len()];
    trace_closest(&ctx.accel, &primary, isa, &mut hits);
    let shadow = shadow_batch(&ctx.world, &primary, &hits, ctx.sky.sun_direction);
    let incoherent = cosine_batch(&ctx.world, &primary, &hits);
    let (mut blocked, mut other_hits, mut other_blocked) = (
        vec![false; shadow.rays.len()],
        vec![None; incoherent.rays.len()],
        vec![false; incoherent.rays.len()],
    );
    let mut frame = Frame::new(camera.width, camera.height);
    println!(
        "isa {}, {threads} thread(s), {width}×{height}, {repeats} repeats; ns per ray, median: \
         CPU, and wall × threads",
        isa.name()
    );
    let row = |name: &str, rays: usize, job: &mut dyn FnMut()| -> Result<()> {
        job();
        let (mut cpu, mut wall) = (Vec::with_capacity(repeats), Vec::with_capacity(repeats));
        for _ in 0..repeats {
            let (start, clock) = (cpu_ns()?, std::time::Instant::now());
            job();
            let seconds = clock.elapsed().as_secs_f64();
            cpu.push((cpu_ns()? - start) as f64 / rays as f64);
            wall.push(seconds * 1e9 * threads as f64 / rays as f64);
        }
        cpu.sort_by(f64::total_cmp);
        wall.sort_by(f64::total_cmp);
        println!(
            "{name:<24} {rays:>8} rays {:9.3} {:9.3}",
            cpu[repeats / 2],
            wall[repeats / 2]
        );
        Ok(())
    };
    row("primary (packets)", primary.rays.len(), &mut || {
        trace_closest(&ctx.accel, &primary, isa, &mut hits)
    })?;
    row("shadow (packets)", shadow.rays.len(), &mut || {
        trace_any(&ctx.accel, &shadow, isa, &mut blocked)
    })?;
    row("primary, per ray", primary.rays.len(), &mut || {
        trace_closest_per_ray(&ctx.accel, &primary, &mut hits)
    })?;
    row("incoherent closest", incoherent.rays.len(), &mut || {
        trace_closest_per_ray(&ctx.accel, &incoherent, &mut other_hits)
    })?;
    row("incoherent any hit", incoherent.rays.len(), &mut || {
        trace_any_per_ray(&ctx.accel, &incoherent, &mut other_blocked)
    })?;
    row("truth frame (per pixel)", primary.rays.len(), &mut || {
        ctx.render_into(
            RenderJob::new(&camera, View::Truth.bit()).label("truth"),
            &mut frame,
        );
    })?;
    Ok(())
}
