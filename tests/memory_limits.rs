//! `ratio`, `bench` and `reproduce` estimate their memory before they render, as `run` and
//! `sequence` do: the estimate bounds what the process really uses, grows with what it
//! counts, and a limit below it refuses the command before anything is written.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::{das, repo_path, seethru};
use seethru::analysis::examples::paper_occlusion;
use seethru::measure::ratio::ratio_estimate;
use seethru::measure::ratio_setup::{Compensation, Setup};
use seethru::paper::reproduce::reproduce_estimate;
use seethru::scene::Scene;
use seethru::system::memory::bench_estimate;

/// The paper's occlusion case as `seethru ratio` arguments, and as a setup.
const OCCLUSION: [&str; 11] = [
    "ratio",
    "occlusion",
    "--L",
    "5",
    "--b1",
    "-0.35",
    "--d2",
    "6.3",
    "--d1",
    "2.5",
    "--bh=1.75",
];

fn occlusion() -> Setup {
    Setup::Occlusion(paper_occlusion())
}

/// Memory of a process that is not the render's: the binary, its libraries, the allocator's
/// arenas, the scene (das has 13 012 triangles) and reproduce's figures, which the estimates
/// leave out. The peak of `seethru ratio … --width 8`, which renders next to nothing, is 14 MB.
const PROCESS_BYTES: u64 = 48 << 20;

/// The peak resident memory of `seethru args`, bytes: `VmHWM` of /proc, read until it exits
/// (a high-water mark, so a late read loses nothing but the last few milliseconds).
fn peak_bytes(args: &[&str]) -> u64 {
    let mut child = Command::new(env!("CARGO_BIN_EXE_seethru"))
        .args(args)
        .current_dir(repo_path(""))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let status = Path::new("/proc")
        .join(child.id().to_string())
        .join("status");
    let mut peak = 0;
    loop {
        let hwm = std::fs::read_to_string(&status).ok().and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("VmHWM:"))?.to_owned();
            line.split_whitespace().nth(1)?.parse::<u64>().ok()
        });
        peak = peak.max(hwm.unwrap_or(0) * 1024);
        if let Some(exit) = child.try_wait().unwrap() {
            assert!(exit.success(), "seethru {args:?} failed");
            return peak;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[test]
#[cfg(target_os = "linux")]
fn estimates_bound_the_memory_each_command_uses() {
    let scratch = tempfile::tempdir().unwrap();
    let out = scratch.path().join("report");
    for width in [1280u32, 2560] {
        let estimate = ratio_estimate(&occlusion(), width, &Compensation::default()).unwrap();
        let w = width.to_string();
        let peak = peak_bytes(&[&OCCLUSION[..], &["--width", &w]].concat());
        assert!(
            peak <= estimate.bytes + PROCESS_BYTES,
            "ratio --width {width}: peak {peak} B above the estimate {} B",
            estimate.bytes
        );
    }
    let estimate =
        reproduce_estimate(&Scene::load(&repo_path("scenes/das.toml")).unwrap(), true).unwrap();
    let peak = peak_bytes(&["reproduce", "--quick", "--out", out.to_str().unwrap()]);
    assert!(
        peak <= estimate.bytes + PROCESS_BYTES,
        "reproduce --quick: peak {peak} B above the estimate {} B",
        estimate.bytes
    );
}

#[test]
fn estimates_grow_with_what_they_count() {
    // The ratio renders width × (width·aspect) pixels: twice the width, four times the bytes.
    let at = |w| {
        ratio_estimate(&occlusion(), w, &Compensation::default())
            .unwrap()
            .bytes as f64
    };
    let growth = at(2560) / at(1280);
    assert!((growth - 4.0).abs() < 0.1, "{growth}");
    // bench: its batches scale with the batch's pixels, the scene part with --grow.
    let scene = das();
    let bench = |w, h, grow| bench_estimate(&scene, w, h, grow, false).unwrap().bytes;
    let per_pixel = (bench(2000, 1000, 1.0) - bench(1000, 1000, 1.0)) as f64 / 1e6;
    let frame = seethru::render::frame::Frame::BYTES_PER_PIXEL as f64;
    assert!(per_pixel > frame + 64.0, "{per_pixel} bytes per pixel");
    let per_grow = (bench(64, 64, 101.0) - bench(64, 64, 1.0)) as f64 / 100.0;
    assert!(
        (per_grow / 13_012.0 - 640.0).abs() < 1.0,
        "{per_grow} bytes per unit of --grow"
    );
    // reproduce: the full size renders 1280-wide driver views where --quick renders 256.
    let das_path = repo_path("scenes/das.toml");
    let full = reproduce_estimate(&Scene::load(&das_path).unwrap(), false)
        .unwrap()
        .bytes;
    let quick = reproduce_estimate(&Scene::load(&das_path).unwrap(), true)
        .unwrap()
        .bytes;
    // Every case's width grows at least 4× (the ratio cases 480 → 1920): 16× the pixels.
    assert!(full > 8 * quick, "{full} against {quick}");
}

#[test]
fn the_bench_estimate_counts_its_batches_at_their_size() {
    use seethru::render::integrator::RenderContext;
    use seethru::render::throughput::{
        BatchRay, camera_batch, cosine_batch, shadow_batch, trace_closest_per_ray,
    };
    use seethru::render::views::View;
    // The buffers `bench` holds, built as it builds them on das's truth view.
    let ctx = RenderContext::new(das()).unwrap();
    let (w, h) = (160, 90);
    let camera = View::Truth.camera(&ctx.scene).with_resolution(w, h);
    let primary = camera_batch(&camera, View::Truth.bit());
    let mut hits = vec![None; primary.rays.len()];
    trace_closest_per_ray(&ctx.accel, &primary, &mut hits);
    let world = &ctx.world;
    let shadow = shadow_batch(world, &primary, &hits, ctx.sky.sun_direction);
    let incoherent = cosine_batch(world, &primary, &hits);
    let rays = primary.rays.len() + shadow.rays.len() + incoherent.rays.len();
    // Packet and per-ray primary hits, incoherent hits; two shadow flags, incoherent flags.
    let held = rays * size_of::<BatchRay>()
        + (2 * primary.rays.len() + incoherent.rays.len())
            * size_of::<Option<seethru::render::accel::Hit>>()
        + 2 * shadow.rays.len()
        + incoherent.rays.len();
    let pixels = (w * h) as f64;
    let held = held as f64 / pixels;
    let scene = das();
    let bench = |w, h| bench_estimate(&scene, w, h, 1.0, false).unwrap().bytes;
    let frame = seethru::render::frame::Frame::BYTES_PER_PIXEL as f64;
    let counted = (bench(2000, 1000) - bench(1000, 1000)) as f64 / 1e6 - frame;
    // An upper bound (a shadow or incoherent ray at every pixel), and not a loose one: das's
    // view has sky and unlit pixels, which hold no such ray.
    assert!(
        counted >= held,
        "{counted} bytes per pixel counted, {held} held"
    );
    assert!(
        counted < 1.5 * held,
        "{counted} bytes per pixel counted, {held} held"
    );
}

#[test]
fn a_limit_below_the_estimate_refuses_before_anything_is_written() {
    let scratch = tempfile::tempdir().unwrap();
    let out = scratch.path().join("report");
    let out = out.to_str().unwrap();
    let ratio = [&OCCLUSION[..], &["--width", "4096", "--max-memory", "1"]].concat();
    let sequence = [
        "sequence",
        "scenes/das.toml",
        "--out",
        out,
        "--width",
        "64",
        "--height",
        "36",
        "--duration",
        "0.2",
        "--max-memory",
        "0.001",
    ];
    let cases: [(&[&str], &str); 5] = [
        (&ratio, "4096×1024 driver views"),
        (
            &[
                "bench",
                "scenes/das.toml",
                "--width",
                "4096",
                "--height",
                "4096",
                "--max-memory",
                "1",
            ],
            "4096×4096 rays and hits",
        ),
        (
            &[
                "bench",
                "scenes/das.toml",
                "--width",
                "8",
                "--height",
                "8",
                "--grow",
                "1000",
                "--max-memory",
                "4",
            ],
            "a scene of about 13012000 triangles",
        ),
        (
            &["reproduce", "--out", out, "--max-memory", "0.2"],
            "a car case: three 1280×720 driver views",
        ),
        // A need far below 1 GiB is still stated in figures that exceed the limit.
        (&sequence, "three 64×36 driver views"),
    ];
    for (args, counted) in cases {
        let (ok, stdout, err) = seethru(args);
        assert!(!ok && stdout.is_empty(), "{args:?}: {stdout}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("error: this needs about ")
                && err.contains(counted)
                && err.contains("more than --max-memory"),
            "{args:?}: {err}"
        );
        let gib_after = |prefix: &str| -> f64 {
            let rest = &err[err.find(prefix).unwrap() + prefix.len()..];
            rest.split(' ').next().unwrap().parse().unwrap()
        };
        let (needed, limit) = (gib_after("needs about "), gib_after("--max-memory "));
        assert!(needed > limit, "{args:?}: {err}");
    }
    assert!(!Path::new(out).exists());
    // The default limit (8 GiB) lets the default sizes through: the estimate is no wall.
    let (ok, _, err) = seethru(&[&OCCLUSION[..], &["--width", "640"]].concat());
    assert!(ok, "{err}");
}
