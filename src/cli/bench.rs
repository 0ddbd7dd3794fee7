//! `seethru bench`: BVH build time, trace-only ray throughput (coherent and incoherent,
//! closest and any hit), shaded frame times and peak memory on a scene.

use crate::cli::load_scene;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use seethru::io::output_paths::{Input, check_paths};
use seethru::render::accel::Accel;
use seethru::render::frame::Frame;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::check_resolution;
use seethru::render::simd::Isa;
use seethru::render::throughput::{
    Batch, camera_batch, cosine_batch, shadow_batch, trace_any, trace_any_per_ray, trace_closest,
    trace_closest_per_ray,
};
use seethru::render::views::View;
use seethru::scene::grow::grow;
use seethru::util::cpu_time::threads_cpu_ns;
use seethru::util::memory::peak_rss_bytes;
use serde_json::json;

use seethru::system::memory::{bench_estimate, check_memory};

use clap::ValueEnum;

use crate::cli::args::{MemoryLimit, choice, integer, pixels, real, threads, with_threads};

/// The widest packet kernels the tracer may use, for `--isa`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kernels {
    /// AVX-512: 16 lanes per walk.
    Avx512,
    /// AVX2: 8 lanes per walk.
    Avx2,
    /// The target's baseline (SSE2 on x86-64): 4 lanes per walk.
    Portable,
}

impl Kernels {
    fn isa(self) -> Isa {
        match self {
            Kernels::Avx512 => Isa::Avx512,
            Kernels::Avx2 => Isa::Avx2,
            Kernels::Portable => Isa::Portable,
        }
    }
}

/// A part of the benchmark, for `--parts`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Part {
    /// The hierarchy's build, the ray throughputs and the shaded frames: the tracer.
    Trace,
    /// The compensation methods' display maps, at two fixed frontal sizes.
    Methods,
    /// The system loop of `sequence` at 640×360.
    Sequence,
    /// `seethru run SCENE` as a user calls it, with each `--exr` choice.
    Run,
}

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Bench {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Image width of the ray batches and frames, pixels in [1, 16384].
    #[arg(long, default_value_t = 1280, value_parser = pixels)]
    width: u32,
    /// Image height, pixels in [1, 16384].
    #[arg(long, default_value_t = 720, value_parser = pixels)]
    height: u32,
    /// Timed repeats of every measurement, in [1, 1000] (min, median and max are reported).
    #[arg(long, default_value_t = 5, value_parser = integer::<usize>(1, 1000))]
    repeat: usize,
    /// Worker threads in [1, 1024] (default: all cores).
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
    /// Grow the scene procedurally to about this many times its triangles (parked cars,
    /// trees, buildings), in [1, 1000], to see how the cost scales with scene size.
    #[arg(long, default_value_t = 1.0, value_parser = real(1.0, 1000.0))]
    grow: f64,
    /// Trace the scene's instanced meshes flattened (every placement its own triangles in
    /// one hierarchy): the same images, to time the two-level hierarchy against the flat one.
    #[arg(long)]
    flatten: bool,
    /// Parts to time, comma-separated (the JSON leaves the others out): `trace` alone times
    /// the tracer on a big scene in seconds rather than minutes.
    #[arg(
        long,
        value_delimiter = ',',
        value_parser = choice::<Part>(),
        default_value = "trace,methods,sequence,run"
    )]
    parts: Vec<Part>,
    /// The packet kernels every part uses, to time narrower ones than this CPU's widest
    /// (the images are the same; default: the widest this CPU runs). One this CPU lacks is
    /// an error.
    #[arg(long, value_parser = choice::<Kernels>())]
    isa: Option<Kernels>,
    /// Print only the JSON line.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    memory: MemoryLimit,
}

impl Bench {
    pub fn run(self) -> Result<()> {
        check_paths(&[Input::file("SCENE", &self.scene)], &[])?;
        check_resolution(self.width, self.height)?;
        if !(1..=1000).contains(&self.repeat) {
            anyhow::bail!("--repeat {} is out of range [1, 1000]", self.repeat);
        }
        let estimate = bench_estimate(
            &load_scene(&self.scene)?,
            self.width,
            self.height,
            self.grow,
            self.flatten,
        )?;
        check_memory(&estimate, self.memory.max_memory)?;
        if let Some(kernels) = self.isa {
            let name = kernels
                .to_possible_value()
                .map(|v| v.get_name().to_string());
            kernels
                .isa()
                .limit_to()
                .map_err(|why| anyhow::anyhow!("--isa {}: {why}", name.unwrap_or_default()))?;
        }
        with_threads(self.threads, || bench(&self).map(|_| ()))?
    }
}

/// Minimum, median and maximum of some measurements.
#[derive(Clone, Copy, Debug)]
struct Spread {
    min: f64,
    median: f64,
    max: f64,
}

impl Spread {
    fn of(values: &[f64]) -> Spread {
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        Spread {
            min: v[0],
            median: v[v.len() / 2],
            max: v[v.len() - 1],
        }
    }

    fn json(&self) -> serde_json::Value {
        json!({"min": self.min, "median": self.median, "max": self.max})
    }
}

impl std::fmt::Display for Spread {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:7.2} / {:7.2} / {:7.2}",
            self.min, self.median, self.max
        )
    }
}

/// Seconds of each of `repeat` runs of `job`, after one untimed warm-up run.
fn timed(repeat: usize, mut job: impl FnMut()) -> Vec<f64> {
    job();
    seconds_of_each(repeat, job)
}

/// Seconds of each of `repeat` runs of `job`.
fn seconds_of_each(repeat: usize, mut job: impl FnMut()) -> Vec<f64> {
    (0..repeat)
        .map(|_| {
            let start = Instant::now();
            job();
            start.elapsed().as_secs_f64()
        })
        .collect()
}

/// [`timed`], and how busy the repeats kept the `threads` workers: the process's CPU time over
/// the wall time × `threads` (`None` where the system does not say). About 1 where they never
/// wait (the thread that waits on them adds a per cent or so); one minus it is the share of
/// their time they waited, out of work or for a core.
///
/// The threads' clocks move at the scheduler's ticks and switches (a few ms), and a small
/// frame's repeats take under a millisecond: the share is taken over the repeats and, while
/// they add up to less than [`BUSY_WALL_S`], more runs of the job (a busy machine read 0
/// over three 160×90 frames).
fn timed_busy(repeat: usize, threads: usize, mut job: impl FnMut()) -> (Vec<f64>, Option<f64>) {
    job();
    let before = threads_cpu_ns();
    let seconds = seconds_of_each(repeat, &mut job);
    let mut wall_s: f64 = seconds.iter().sum();
    while wall_s < BUSY_WALL_S {
        wall_s += seconds_of_each(1, &mut job)[0];
    }
    let cpu_s = before
        .zip(threads_cpu_ns())
        .map(|(a, b)| b.saturating_sub(a) as f64 * 1e-9);
    (seconds, cpu_s.map(|cpu| cpu / (wall_s * threads as f64)))
}

/// The least wall time, seconds, over which [`timed_busy`] takes the workers' busy share.
const BUSY_WALL_S: f64 = 0.1;

/// Million rays per second of each run.
fn mrays(rays: usize, seconds: &[f64]) -> Vec<f64> {
    seconds.iter().map(|s| rays as f64 / s / 1e6).collect()
}

/// Runs the benchmark, prints a report (unless `--json`) and ends with one JSON line.
fn bench(options: &Bench) -> Result<serde_json::Value> {
    let say = |line: String| {
        if !options.json {
            println!("{line}");
        }
    };
    let load = Instant::now();
    // `run` read the scene once already and printed its warnings.
    let scene = grow(&seethru::scene::Scene::load(&options.scene)?, options.grow)?;
    let mut ctx = RenderContext::new(scene)?;
    if options.flatten {
        ctx = ctx.flattened()?;
    }
    let load_s = load.elapsed().as_secs_f64();
    let world = &ctx.world;
    let placements: usize = world
        .instanced
        .iter()
        .map(|s| s.world_from_object.len())
        .sum();
    say(format!(
        "scene        {} (grown {}×{}): {} triangles, {} instanced ({placements} placements), {} ellipsoids; loaded and built in {load_s:.3} s",
        options.scene.display(),
        options.grow,
        if options.flatten { ", flattened" } else { "" },
        world.triangles.len(),
        world.instanced_count(),
        world.ellipsoids.len()
    ));
    let threads = rayon::current_num_threads();
    let isa = Isa::best();
    let mut report = json!({
        "scene": options.scene.display().to_string(),
        "grow": options.grow,
        "triangles": world.triangles.len(),
        "instanced_triangles": world.instanced_count(),
        "placements": placements,
        "flattened": options.flatten,
        "ellipsoids": world.ellipsoids.len(),
        "bvh_bytes": ctx.accel.bytes(),
        "threads": threads,
        "isa": isa.name(),
        "repeat": options.repeat,
        "width": options.width,
        "height": options.height,
    });
    let mut add = |key: &str, value: serde_json::Value| report[key] = value;
    if options.parts.contains(&Part::Trace) {
        let (lines, trace) = bench_trace(options, &ctx, threads, isa)?;
        lines.into_iter().for_each(say);
        for (key, value) in trace {
            add(&key, value);
        }
    }
    if options.parts.contains(&Part::Methods) {
        add(
            "methods",
            crate::cli::bench_methods::method_costs(&ctx, options.repeat, options.json)?,
        );
    }
    if options.parts.contains(&Part::Sequence) {
        let (lines, sequence) = crate::cli::bench_sequence::bench_sequence(&ctx.scene)?;
        lines.into_iter().for_each(say);
        add("sequence", sequence);
    }
    if options.parts.contains(&Part::Run) {
        let (lines, run) = crate::cli::bench_run::bench_run(&options.scene, options.repeat)?;
        lines.into_iter().for_each(say);
        add("run", run);
    }
    let peak = peak_rss_bytes();
    say(format!(
        "peak RSS     {}",
        peak.map_or("unknown".into(), |b| format!("{:.0} MB", b as f64 / 1e6))
    ));
    add("peak_rss_bytes", json!(peak));
    println!("{report}");
    Ok(report)
}

/// The tracer's part: the hierarchy's build, the ray batches and the shaded frames; its
/// report lines and JSON entries.
fn bench_trace(
    options: &Bench,
    ctx: &RenderContext,
    threads: usize,
    isa: Isa,
) -> Result<(Vec<String>, serde_json::Map<String, serde_json::Value>)> {
    let mut lines = Vec::new();
    let mut say = |line: String| lines.push(line);
    let world = &ctx.world;
    let builds: Vec<f64> = (0..options.repeat)
        .map(|_| Accel::build(world).map(|a| a.build_time.as_secs_f64() * 1e3))
        .collect::<Result<_>>()?;
    let build = Spread::of(&builds);
    say(format!(
        "bvh          build {build} ms (min / median / max), {:.1} MB",
        ctx.accel.bytes() as f64 / 1e6
    ));
    say(format!(
        "threads      {threads}; packets of 16 rays on {} ({} lanes)",
        isa.name(),
        isa.lanes()
    ));

    let camera = View::Truth
        .camera(&ctx.scene)
        .with_resolution(options.width, options.height);
    let primary = camera_batch(&camera, View::Truth.bit());
    let mut hits = vec![None; primary.rays.len()];
    let primary_s = timed(options.repeat, || {
        trace_closest(&ctx.accel, &primary, isa, &mut hits)
    });
    let mut single_hits = vec![None; primary.rays.len()];
    let primary_single_s = timed(options.repeat, || {
        trace_closest_per_ray(&ctx.accel, &primary, &mut single_hits)
    });
    if hits != single_hits {
        anyhow::bail!("internal error: the packet and per-ray traversals found different hits");
    }
    let shadow = shadow_batch(world, &primary, &hits, ctx.sky.sun_direction);
    let mut blocked = vec![false; shadow.rays.len()];
    let shadow_s = timed(options.repeat, || {
        trace_any(&ctx.accel, &shadow, isa, &mut blocked)
    });
    let mut single_blocked = vec![false; shadow.rays.len()];
    let shadow_single_s = timed(options.repeat, || {
        trace_any_per_ray(&ctx.accel, &shadow, &mut single_blocked)
    });
    if blocked != single_blocked {
        anyhow::bail!("internal error: the packet and per-ray traversals found different shadows");
    }
    let any_hit = |batch: &Batch| {
        let mut blocked = vec![false; batch.rays.len()];
        timed(options.repeat, || {
            trace_any_per_ray(&ctx.accel, batch, &mut blocked)
        })
    };
    let incoherent = cosine_batch(world, &primary, &hits);
    let mut incoherent_hits = vec![None; incoherent.rays.len()];
    let incoherent_closest_s = timed(options.repeat, || {
        trace_closest_per_ray(&ctx.accel, &incoherent, &mut incoherent_hits)
    });
    let incoherent_any_s = any_hit(&incoherent);
    let sum = |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(a, b)| a + b).collect() };
    let both = sum(&primary_s, &shadow_s);
    let both_single = sum(&primary_single_s, &shadow_single_s);
    let rows = [
        (
            "primary",
            "primary closest hit",
            primary.rays.len(),
            primary_s,
        ),
        (
            "shadow",
            "shadow any hit (sun)",
            shadow.rays.len(),
            shadow_s,
        ),
        (
            "primary_shadow",
            "primary + shadow",
            primary.rays.len() + shadow.rays.len(),
            both,
        ),
        (
            "primary_per_ray",
            "primary, per ray",
            primary.rays.len(),
            primary_single_s,
        ),
        (
            "primary_shadow_per_ray",
            "primary + shadow, per ray",
            primary.rays.len() + shadow.rays.len(),
            both_single,
        ),
        (
            "incoherent_closest",
            "incoherent closest hit",
            incoherent.rays.len(),
            incoherent_closest_s,
        ),
        (
            "incoherent_any",
            "incoherent any hit",
            incoherent.rays.len(),
            incoherent_any_s,
        ),
    ];
    say(format!(
        "rays         {}×{} from the driver's eye (`truth`); M rays/s min / median / max",
        options.width, options.height
    ));
    let mut rays_json = serde_json::Map::new();
    for (key, label, n, seconds) in rows {
        let spread = Spread::of(&mrays(n, &seconds));
        say(format!("  {label:<24} {n:>8} rays  {spread}"));
        rays_json.insert(key.into(), json!({"rays": n, "mrays_per_s": spread.json()}));
    }
    say(
        "  (incoherent: one cosine-distributed direction about the normal at each primary hit)"
            .into(),
    );

    say("frame        shaded, 1 spp (primary + shadow + shading); ms min / median / max; workers' CPU time / (wall × threads)".into());
    let mut frames = serde_json::Map::new();
    for view in [View::Truth, View::Frontal] {
        let camera = view
            .camera(&ctx.scene)
            .with_resolution(options.width, options.height);
        // One frame buffer for every repeat, as a sequence of renders keeps it: the first
        // touch of 50 MB of new pages is the kernel's work, not the renderer's.
        let mut frame = Frame::new(camera.width, camera.height);
        let (seconds, busy) = timed_busy(options.repeat, threads, || {
            ctx.render_into(
                RenderJob::new(&camera, view.bit()).label(view.name()),
                &mut frame,
            );
        });
        let ms: Vec<f64> = seconds.iter().map(|s| s * 1e3).collect();
        let spread = Spread::of(&ms);
        say(format!(
            "  {:<24} {}×{}  {spread}   workers busy {}",
            view.name(),
            options.width,
            options.height,
            busy.map_or("unknown".into(), |b| format!("{:.0} %", b * 100.0))
        ));
        frames.insert(
            view.name().into(),
            json!({"ms": spread.json(), "workers_busy": busy}),
        );
    }
    let mut out = serde_json::Map::new();
    out.insert("bvh_build_ms".into(), build.json());
    out.insert("rays".into(), rays_json.into());
    out.insert("frame".into(), frames.into());
    Ok((lines, out))
}
