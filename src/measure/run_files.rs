//! One run's files: every view (PNG, EXR as asked), the metrics, hazards.json, run.json
//! and view.html, written into a folder as the renders finish. `seethru run` writes them into
//! its staging folder; a dataset into each sample's (from the command line or Python alike,
//! so a dataset begun by one is finished by the other to the same bytes).

use std::path::Path;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Mutex, OnceLock};

use anyhow::Result;

use crate::io::atomic::write_text;
use crate::io::frame_files::{ExrContent, write_frame_keeping, write_frame_like};
use crate::measure::holes::write_hole_mask;
use crate::measure::maps::write_metrics_scaled;
use crate::measure::measured_run::{DriverViews, hazards_of, measure_views, view_eye};
use crate::measure::viewer::{RunPixels, write_run_view};
use crate::render::frame_over::FrameView;
use crate::render::integrator::RenderContext;
use crate::system::options::RunOptions;
use crate::system::pipeline::{Given, RunResult, RunViews, check_display_seen, run_staged};
use crate::util::option_words::{flag_of, spell_json};

/// What one run writes beside its views, and how: the flags that shape the files, not the
/// system.
#[derive(Clone, Copy)]
pub struct RunWrites {
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

/// A finished run and what its user should hear of it.
pub struct WrittenRun {
    pub result: RunResult,
    /// Warnings in the library's words ("option `name`"; each front end spells them), one
    /// line each without the `warning:`: a doubtful head estimate, a display seen as a sliver.
    pub warnings: Vec<String>,
}

/// `value` in the files' words: a run's files name options as the command line does,
/// whichever front end writes them (one file format: a dataset begun in Python is finished
/// by `seethru dataset` to the same bytes).
pub fn in_file_words(value: &serde_json::Value) -> serde_json::Value {
    let mut value = value.clone();
    spell_json(&mut value, &flag_of);
    value
}

/// `f`, typed as taking one scope's handle (a closure's own would take any scope's).
fn in_scope<'s, F: Fn(&rayon::Scope<'s>) + Sync + Send + Copy>(f: F) -> F {
    f
}

/// One run into `out` (a staging folder: the caller moves it into place once this returns):
/// every view, the metrics, hazards.json, run.json and view.html.
pub fn write_run(
    ctx: &RenderContext,
    out: &Path,
    options: &RunOptions,
    writes: RunWrites,
) -> Result<WrittenRun> {
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
            &in_file_words(&metrics.to_json()),
            heatmap_max,
        )?;
        Ok((rest, maps))
    });
    if let Some(e) = failed.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    let (rest, maps) = measured?;
    let result = rest.with_views(views);
    let mut warnings = Vec::new();
    let min = options.min_head_confidence;
    if let Some(d) = result
        .detection
        .filter(|d| !d.confidence.is_confident_at(min))
    {
        warnings.push(d.confidence.warning_at("", min));
    }
    let hazards = hazards_of(ctx, options, &result, &maps, hazard_bound)?;
    // Beside metrics.json (which `measure` recomputes from the frames alone).
    write_text(
        &out.join("hazards.json"),
        &serde_json::to_string_pretty(&hazards)?,
    )?;
    let mut report = in_file_words(&result.report);
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
        && share < crate::system::obstruction::SLIVER_SHARE
    {
        warnings.push(format!(
            "the driver sees only {} of the display's {} pixels ({:.1} %): the display covers a sliver of the driver's view (check the driver's position and look_at, and the obstacle's facing)",
            seen["seen_by_driver"],
            seen["display_pixels"],
            100.0 * share
        ));
    }
    Ok(WrittenRun { result, warnings })
}
