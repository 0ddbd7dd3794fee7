//! `seethru run`: the see-through system end to end on a scene, with every view, run.json and
//! the metrics written to a directory.

use crate::cli::with_flags;
use seethru::util::option_words::as_flags;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Mutex, OnceLock};

use anyhow::Result;
use seethru::io::atomic::write_text;
use seethru::io::frame_files::{ExrContent, write_frame_keeping, write_frame_like};
use seethru::io::output_paths::{Input, Output, check_paths};
use seethru::io::staged::StagedDir;
use seethru::measure::headline::{read_results, summary_text};
use seethru::measure::holes::write_hole_mask;
use seethru::measure::maps::write_metrics_scaled;
use seethru::measure::measured_run::{DriverViews, hazards_of, measure_views, view_eye};
use seethru::measure::viewer::{RunPixels, write_run_view};
use seethru::render::frame_over::FrameView;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::scene::lens_keys::read_calibration_file;
use seethru::system::memory::{both_eyes_estimate, check_memory, run_estimate};
use seethru::system::options::RunOptions;
use seethru::system::pipeline::{Given, RunResult, RunViews, check_display_seen, run_staged};
use seethru::system::reads::hazard_bound_reads;

use crate::cli::args::{choice, positive, refuse_ignored, threads, with_threads};
use crate::cli::option_args::{self, OptionArgs};

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub struct Run {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
    /// A TOML file with a [calibration] table (as in a scene file) that replaces the scene's:
    /// the compensation's own copy of the cameras.
    #[arg(long, value_name = "FILE")]
    calibration: Option<PathBuf>,
    /// The run's options: the option table's (`seethru::measure::option_table`).
    #[command(flatten)]
    options: OptionArgs<option_args::Run>,
    /// What each view's EXR holds: none; colour (R, G, B, A); lean (R, G, B, Z, N and the
    /// ids: every AOV that no other channel gives); all (lean with A, P and camera_z.Z: what
    /// `seethru measure` reads back).
    #[arg(long, value_enum, value_parser = choice::<ExrContent>(), default_value_t = ExrContent::Lean)]
    exr: ExrContent,
    /// Top of misregistration.png's scale, arc-minutes in [1e-6, 10000], so that heatmaps of
    /// runs compare (default: the 99th percentile of the display's values, labelled).
    #[arg(long = "heatmap-max", value_name = "ARCMIN", value_parser = positive(1e4))]
    heatmap_max: Option<f64>,
    /// Worker threads in [1, 1024] (default: all cores). Images are identical for any value.
    #[arg(long, value_parser = threads)]
    threads: Option<usize>,
}

impl Run {
    pub fn run(self) -> Result<()> {
        let mut inputs = vec![Input::file("SCENE", &self.scene)];
        inputs.extend(
            self.calibration
                .as_deref()
                .map(|c| Input::file("--calibration", c)),
        );
        check_paths(&inputs, &[Output::folder("--out", &self.out)])?;
        let spec = self.options.spec()?;
        let options = RunOptions {
            progress: true,
            ..spec.options
        };
        let both = spec.both_eyes;
        let (scene, out, max_memory) = (&self.scene, &self.out, spec.max_memory_gib);
        let writes = RunWrites {
            band: spec.measure.band,
            exr: self.exr,
            hazard_bound_arcmin: spec.measure.hazard_bound_arcmin,
            heatmap_max_arcmin: self.heatmap_max.map(|v| v as f32),
            timings: true,
        };
        let calibration = self.calibration.as_deref();
        with_threads(self.threads, || {
            run_command(scene, calibration, out, &options, writes, max_memory, both)
        })?
    }
}

/// What one run writes beside its views, and how: the flags that shape the files, not the
/// system.
#[derive(Clone, Copy)]
pub(crate) struct RunWrites {
    /// Border band of the mismatch metrics, display pixels in [1, 1000].
    pub band: u32,
    /// Which EXRs each view gets.
    pub exr: ExrContent,
    /// Hazard visibility's bound, arc-minutes.
    pub hazard_bound_arcmin: f64,
    /// Top of misregistration.png's scale, arc-minutes (`None`: the p99, labelled).
    pub heatmap_max_arcmin: Option<f32>,
    /// Whether run.json keeps the timings and the peak memory (a dataset's samples leave them
    /// out: its files are the same bytes however often they are made).
    pub timings: bool,
}

/// `seethru run`: renders the six views into `out` with `run.json` and the metrics.
fn run_command(
    scene_path: &Path,
    calibration: Option<&Path>,
    out: &Path,
    options: &RunOptions,
    writes: RunWrites,
    max_memory: f64,
    both: bool,
) -> Result<()> {
    let mut scene = Scene::load(scene_path)?;
    refuse_ignored(&[hazard_bound_reads(&scene)])?;
    if let Some(path) = calibration {
        scene.calibration = read_calibration_file(path, &scene.frontal, &scene.back)?;
    }
    let estimate = match both {
        true => both_eyes_estimate(&scene, options)?,
        false => run_estimate(&scene, options)?,
    };
    check_memory(&estimate, max_memory)?;
    let ctx = RenderContext::new(scene)?;
    // Written whole or not at all: a failure leaves `out` as it was.
    let staged = StagedDir::new(out)?;
    let summary = if both {
        crate::cli::run_eyes::run_both(&ctx, staged.path(), out, options, |options, dir| {
            write_run(&ctx, dir, options, writes)
        })?
    } else {
        write_run(&ctx, staged.path(), options, writes)?;
        let files = writes.exr.files();
        let (kind, metrics) = read_results(staged.path())?;
        format!(
            "{}; wrote the six views ({files}), run.json, the metrics and view.html to {}",
            summary_text(kind, &metrics),
            out.display()
        )
    };
    staged.commit()?;
    seethru::util::progress::summary(summary);
    Ok(())
}

/// `f`, typed as taking one scope's handle (a closure's own would take any scope's).
fn in_scope<'s, F: Fn(&rayon::Scope<'s>) + Sync + Send + Copy>(f: F) -> F {
    f
}

/// One run into `out` (inside the staging folder): every view, the metrics and run.json;
/// `band`: the border band's width and the heatmap's fixed top, if any.
pub(crate) fn write_run(
    ctx: &RenderContext,
    out: &Path,
    options: &RunOptions,
    writes: RunWrites,
) -> Result<RunResult> {
    let RunWrites {
        band,
        exr,
        hazard_bound_arcmin: hazard_bound,
        heatmap_max_arcmin: heatmap_max,
        timings,
    } = writes;
    let views = RunViews::default();
    // The first error of the writes running beside the run.
    let failed: Mutex<Option<anyhow::Error>> = Mutex::new(None);
    let note = |written: Result<()>| {
        if let Err(e) = written {
            failed
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .get_or_insert(e);
        }
    };
    // Each view is written (PNGs and EXR, mostly single-threaded work) as soon as it is made,
    // beside the renders that follow and the metrics, so that both threads stay busy to the
    // end; the files are the same whatever the order. `out` and its folders are created by
    // the writes (io::atomic), under the lock the interrupt handler takes: never after its
    // clean-up.
    let (views_ref, note) = (&views, &note);
    // `occluded` and `seethru` are `truth` outside the obstacle's footprint: their EXRs take
    // truth's compressed blocks there, so they are written after truth's file, by whichever
    // comes last of that file and the `seethru` view.
    let truth_zipped = OnceLock::new();
    let waiting = AtomicU8::new(2);
    let (truth_zipped, waiting) = (&truth_zipped, &waiting);
    let driver_views = in_scope(move |s| {
        if waiting.fetch_sub(1, Ordering::AcqRel) == 1 {
            let like = truth_zipped.get().and_then(Option::as_ref);
            for name in ["occluded", "seethru"] {
                let frame = views_ref.get(name).expect("set before its file is written");
                s.spawn(move |_| note(write_frame_like(frame, out, name, exr, like)));
            }
        }
    });
    let measured = rayon::scope(|s| -> Result<_> {
        let ready = |name: &'static str| match name {
            "truth" => {
                let frame = views_ref.truth.get().expect("just set");
                s.spawn(move |s| {
                    match write_frame_keeping(frame, out, name, exr) {
                        Ok(zipped) => {
                            let _ = truth_zipped.set(zipped);
                        }
                        Err(e) => note(Err(e)),
                    }
                    driver_views(s);
                });
            }
            "occluded" => {}
            "seethru" => driver_views(s),
            _ => {
                let frame = views_ref.get(name).expect("just set");
                s.spawn(move |_| note(write_frame_like(frame, out, name, exr, None)));
            }
        };
        let rest = run_staged(ctx, options, Given::default(), views_ref, &ready)?;
        let [truth, occluded, seethru] = ["truth", "occluded", "seethru"]
            .map(|name| views_ref.get(name).expect("a finished run set every view"));
        check_display_seen(ctx, occluded)?;
        let views = DriverViews {
            views: [truth, occluded, seethru],
            display_holes: rest.holes.as_deref(),
            external_method: None,
        };
        let (maps, metrics, holes) =
            measure_views(ctx, options, view_eye(ctx, options), &views, band);
        if let Some(holes) = &holes {
            write_hole_mask(&out.join("holes.png"), &maps, holes)?;
        }
        write_metrics_scaled(
            out,
            &maps,
            truth.whole(),
            &with_flags(&metrics.to_json()),
            heatmap_max,
        )?;
        Ok((rest, maps))
    });
    if let Some(e) = failed.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    let (rest, maps) = measured?;
    let result = rest.with_views(views);
    let min = options.min_head_confidence;
    if let Some(d) = result
        .detection
        .filter(|d| !d.confidence.is_confident_at(min))
    {
        eprintln!("warning: {}", as_flags(&d.confidence.warning_at("", min)));
    }
    let hazards = hazards_of(ctx, options, &result, &maps, hazard_bound)?;
    // Beside metrics.json (which `measure` recomputes from the frames alone).
    write_text(
        &out.join("hazards.json"),
        &serde_json::to_string_pretty(&hazards)?,
    )?;
    let mut report = with_flags(&result.report);
    if let Some(top) = heatmap_max {
        report["options"]["heatmap_max_arcmin"] = serde_json::json!(top);
    }
    if !timings && let Some(fields) = report.as_object_mut() {
        fields.remove("timings_s");
        fields.remove("peak_rss_bytes");
    }
    write_text(
        &out.join("run.json"),
        &serde_json::to_string_pretty(&report)?,
    )?;
    // Last, as it reads run.json and metrics.json: the viewer.
    let pixels = RunPixels::of_run(&maps, &result.truth, FrameView::from(&result.seethru));
    write_run_view(out, out, &pixels)?;
    let seen = &result.report["display_seen"];
    if let Some(share) = seen["share"].as_f64()
        && share < seethru::system::obstruction::SLIVER_SHARE
    {
        eprintln!(
            "warning: the driver sees only {} of the display's {} pixels ({:.1} %): the display covers a sliver of the driver's view (check the driver's position and look_at, and the obstacle's facing)",
            seen["seen_by_driver"],
            seen["display_pixels"],
            100.0 * share
        );
    }
    Ok(result)
}
