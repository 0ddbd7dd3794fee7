//! `seethru bench`'s sequence figures: frames per second of the see-through system's loop
//! (frontal render at capture time, head estimate, compensation, `seethru` view) and of the
//! loop with the truth and the metrics, at 640×360, 1 spp, on the bench's threads.

use anyhow::Result;
use seethru::measure::image_metrics::Flip;
use seethru::measure::sequence::{Measuring, SequenceRun, run_sequence};
use seethru::scene::Scene;
use seethru::system::options::{HeadSource, Outside, RunOptions};
use seethru::system::sequence::head_motion::HeadMotion;
use seethru::system::sequence::predict::Prediction;
use seethru::system::sequence::system_loop::SequenceOptions;
use seethru::system::sequence::timeline::Timeline;
use serde_json::json;

/// Frames of each timed sequence (half a second at 60 fps).
const FRAMES: f64 = 30.0;

fn sequence(scene: &Scene, head: HeadSource, metrics: bool) -> Result<SequenceRun> {
    let options = SequenceOptions {
        run: RunOptions {
            head,
            width: Some(640),
            height: Some(360),
            frontal_width: Some(640),
            back_width: Some(320),
            spp: 1,
            outside: Outside::Black,
            speed_kmh: 50.0,
            ..RunOptions::default()
        },
        timeline: Timeline {
            duration: FRAMES / 60.0,
            fps: 60.0,
            display_hz: 60.0,
            latency_camera: 0.05,
            latency_tracking: 0.01,
        },
        head: HeadMotion::Lean {
            distance: 0.1,
            duration: 0.3,
            start: 0.1,
        },
        predict: Prediction::ConstantVelocity,
        reproject: false,
        byo: Default::default(),
    };
    let how = Measuring {
        metrics,
        full_frames: false,
        band: 5,
        progress: false,
        flip: Flip::Skipped,
    };
    run_sequence(scene, options, how, &mut |_| Ok(()))
}

/// The report lines and the JSON of the sequence benchmark.
pub fn bench_sequence(scene: &Scene) -> Result<(Vec<String>, serde_json::Value)> {
    let mut lines = vec![
        "sequence     640×360, 1 spp, 30 frames at 50 km/h, lean, 50 ms latency; wall frames/s over the loop's stages (setup excluded)".to_string(),
    ];
    let mut out = serde_json::Map::new();
    for (key, label, head, metrics) in [
        (
            "system_oracle",
            "system loop (oracle head)",
            HeadSource::Oracle,
            false,
        ),
        (
            "system_estimated",
            "system loop (back 320×240)",
            HeadSource::Estimated,
            false,
        ),
        (
            "with_truth_and_metrics",
            "+ truth and metrics",
            HeadSource::Oracle,
            true,
        ),
    ] {
        let run = match sequence(scene, head, metrics) {
            Ok(run) => run,
            // A scene whose face the tracker cannot find (no head, or eyes too small for the
            // back camera) has no estimated-head loop to time: said, not a failed benchmark.
            Err(e) if head == HeadSource::Estimated => {
                let why = seethru::util::option_words::as_flags(&format!("{e:#}"));
                lines.push(format!("  {label:<28} not measured: {why}"));
                out.insert(key.into(), json!({ "not_measured": why }));
                continue;
            }
            Err(e) => return Err(e),
        };
        // The loop's wall time, frame by frame (setup excluded); the stages are parts of it.
        let seconds = run.stepping_seconds;
        let fps = run.records.len() as f64 / seconds;
        let other = seconds - (run.system.total() + run.truth_seconds + run.metrics_seconds);
        lines.push(format!(
            "  {label:<28} {fps:6.1} frames/s  (frontal {:.1} ms, head {:.1} ms, compensation {:.1} ms, seethru {:.1} ms, moving part {:.1} ms, truth {:.1} ms, metrics {:.1} ms, other {:.1} ms per frame)",
            run.system.frontal / FRAMES * 1e3,
            run.system.head / FRAMES * 1e3,
            run.system.compensation / FRAMES * 1e3,
            run.system.seethru / FRAMES * 1e3,
            run.system.moving / FRAMES * 1e3,
            run.truth_seconds / FRAMES * 1e3,
            run.metrics_seconds / FRAMES * 1e3,
            other / FRAMES * 1e3,
        ));
        out.insert(
            key.into(),
            json!({"frames_per_s": fps, "loop_s": seconds, "stages_s": run.system, "truth_s": run.truth_seconds, "metrics_s": run.metrics_seconds, "other_s": other}),
        );
    }
    Ok((lines, serde_json::Value::Object(out)))
}
