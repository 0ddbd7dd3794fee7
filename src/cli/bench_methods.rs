//! `bench`'s cost per frame of each compensation method: making the display image from a
//! rendered frontal frame (the planar crop is a resample; `depth` a search per display
//! pixel; `depth-tof` also ray casts its sensor), at two frontal resolutions.

use std::time::Instant;

use anyhow::Result;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::RenderSettings;
use seethru::render::views::View;
use seethru::system::compensation::{ModelPlane, compute_crop};
use seethru::system::depth_sensor::SensorKind;
use seethru::system::display::{Filter, resample};
use seethru::system::options::{Method, RunOptions};
use seethru::system::scene_model::scene_model_display;
use serde_json::json;

/// Frontal resolutions the methods are timed at.
const SIZES: [[u32; 2]; 2] = [[640, 360], [1280, 720]];

/// Milliseconds (min / median / max over `repeat` runs after a warm-up) of each method at
/// each of [`SIZES`]; prints a line per method unless `quiet`.
pub fn method_costs(ctx: &RenderContext, repeat: usize, quiet: bool) -> Result<serde_json::Value> {
    let say = |line: String| {
        if !quiet {
            println!("{line}");
        }
    };
    say("methods      display image from the frontal frame, ms min / median / max".into());
    let mut out = serde_json::Map::new();
    for [w, h] in SIZES {
        let ctx = {
            let mut scene = ctx.scene.clone();
            scene.frontal = scene.frontal.with_resolution(w, h);
            ctx.with_scene(scene)?
        };
        let scene = &ctx.scene;
        let settings = RenderSettings {
            spp: 1,
            progress: false,
        };
        let (frontal, _) = ctx.render(
            RenderJob::new(&scene.frontal, View::Frontal.bit())
                .settings(settings)
                .label("frontal"),
        );
        let eye = scene.eye();
        let size = scene.obstacle.display_resolution;
        let crop = compute_crop(
            eye,
            &scene.obstacle,
            &scene.frontal,
            ModelPlane::Infinity,
            size,
        )?;
        // Each method by name; `None` is the planar crop and resample.
        let jobs: [(&str, Option<(Method, SensorKind)>); 5] = [
            ("planar", None),
            ("ground", Some((Method::Ground, SensorKind::Ideal))),
            ("plane-fit", Some((Method::PlaneFit, SensorKind::Ideal))),
            ("depth-ideal", Some((Method::Depth, SensorKind::Ideal))),
            ("depth-tof", Some((Method::Depth, SensorKind::Tof))),
        ];
        let run = |job: Option<(Method, SensorKind)>| -> Result<()> {
            let Some((method, kind)) = job else {
                resample(&frontal, &crop, size, Filter::Bilinear);
                return Ok(());
            };
            let mut options = RunOptions {
                method,
                ..RunOptions::default()
            };
            options.scene_model.sensor.kind = kind;
            scene_model_display(&ctx, scene, eye, &frontal, &crop, &options, &scene.frontal)
                .map(|_| ())
        };
        let mut at_size = serde_json::Map::new();
        for (name, job) in jobs {
            if run(job).is_err() {
                // A scene without a road has no `ground`; the others need no more than it.
                continue;
            }
            let mut ms: Vec<f64> = (0..repeat)
                .map(|_| {
                    let start = Instant::now();
                    let _ = run(job);
                    start.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            ms.sort_by(f64::total_cmp);
            let (min, median, max) = (ms[0], ms[ms.len() / 2], ms[ms.len() - 1]);
            say(format!(
                "  {name:<12} frontal {w}×{h}  {min:7.2} / {median:7.2} / {max:7.2}"
            ));
            at_size.insert(
                name.into(),
                json!({"min": min, "median": median, "max": max}),
            );
        }
        out.insert(format!("{w}x{h}"), serde_json::Value::Object(at_size));
    }
    Ok(json!({"display_resolution": ctx.scene.obstacle.display_resolution, "ms": out}))
}
