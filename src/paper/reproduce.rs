//! `seethru reproduce`: the paper's §5 end to end — the das scene with the car close and far,
//! each at θ_F = 30° and 63.5° with d2 → ∞; the occlusion and foreshortening cases; the
//! figures — as `report.md`, a self-contained `report.html` and `report.json`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde_json::json;

use crate::analysis::examples::{paper_foreshortening, paper_occlusion};
use crate::io::atomic::write_text;
use crate::io::frame_files::write_png;
use crate::measure::maps::heatmap_rgb;
use crate::measure::metrics::MetricMaps;
use crate::measure::metrics::measure;
use crate::measure::ratio::{RatioResult, measure_ratio_with_frames, ratio_estimate};
use crate::measure::ratio_setup::{Compensation, Setup};
use crate::paper::report::{CaseResult, EqualCoverage, Sizes, render_report};
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::scene::Scene;
use crate::system::memory::{MemoryEstimate, largest, metric_maps_bytes, run_estimate};
use crate::system::options::{Outside, RunOptions};
use crate::system::pipeline::run;
use crate::util::color::encode_srgb8;
use crate::util::progress::Progress;

fn frame_png(frame: &Frame, path: &Path) -> Result<()> {
    let rgb = frame.color.iter().flat_map(|&c| encode_srgb8(c)).collect();
    write_png(path, frame.width, frame.height, rgb)
}

/// The das scene with the car `distance` metres beyond the obstacle, a display of width
/// `display_width` and the frontal half angle `theta_deg`.
pub fn das_case(base: &Scene, distance: f64, display_width: f64, theta_deg: f64) -> Result<Scene> {
    let mut scene = base.clone();
    let obstacle_z = scene.obstacle.world_from_obstacle.translation.z;
    let car = scene
        .objects
        .iter_mut()
        .find(|o| o.name == "car")
        .context("the scene has no object named `car`")?;
    car.world_from_object.translation.z = obstacle_z - distance;
    let car_x = car.world_from_object.translation.x;
    // Keep the ball clear of a close car.
    if let Some(ball) = scene.objects.iter_mut().find(|o| o.name == "ball")
        && (ball.world_from_object.translation.z - (obstacle_z - distance)).abs() < 3.0
    {
        ball.world_from_object.translation.x = car_x + 2.6;
    }
    let scale = display_width / scene.obstacle.width;
    scene.obstacle.width = display_width;
    scene.obstacle.display_resolution[0] =
        (scene.obstacle.display_resolution[0] as f64 * scale).round() as u32;
    scene.frontal.half_angle_x = theta_deg.to_radians();
    Ok(scene)
}

/// The car's two distances beyond the obstacle (§5.2 Figs. 4 and 5), metres.
const CARS: [(&str, f64); 2] = [("close", 4.0), ("far", 15.0)];
/// The frontal camera's two half angles θ_F of each car case, degrees.
const THETAS_DEG: [f64; 2] = [30.0, 63.5];

/// The render sizes of a reproduction: CI-sized with `quick`.
fn sizes(quick: bool) -> Sizes {
    if quick {
        Sizes {
            driver: 256,
            frontal: 480,
            ratio: 480,
            spp: 1,
        }
    } else {
        Sizes {
            driver: 1280,
            frontal: 1920,
            ratio: 1920,
            spp: 4,
        }
    }
}

/// The run of each car case.
fn case_options(sizes: &Sizes) -> RunOptions {
    RunOptions {
        width: Some(sizes.driver),
        frontal_width: Some(sizes.frontal),
        back_width: Some(64),
        spp: sizes.spp,
        outside: Outside::Black,
        ..RunOptions::default()
    }
}

/// §5.2 Figs. 6 and 7: the occlusion and foreshortening cases with the paper's parameters
/// (name, folder, setup).
fn ratio_setups() -> [(&'static str, &'static str, Setup); 2] {
    [
        (
            "occlusion (L=5, b1=−0.35, d2=6.3, d1=2.5, b_h=1.75)",
            "occlusion",
            Setup::Occlusion(paper_occlusion()),
        ),
        (
            "foreshortening (l=5, b1=−1.5, d2=1.3, d1=2, b_h=0.7, γ=90°)",
            "foreshortening",
            Setup::Foreshortening(paper_foreshortening()),
        ),
    ]
}

/// Memory a reproduction of scene `base` needs: its largest case, one after another, with
/// the metric maps of the car's two θ_F cases kept for their comparison.
pub fn reproduce_estimate(base: &Scene, quick: bool) -> Result<MemoryEstimate> {
    let sizes = sizes(quick);
    let options = case_options(&sizes);
    let mut estimates = Vec::new();
    for (_, distance) in CARS {
        for theta in THETAS_DEG {
            let scene = das_case(base, distance, 1.0, theta)?;
            let mut estimate = run_estimate(&scene, &options)?;
            let driver = options.sized_driver(scene.driver)?;
            let kept = THETAS_DEG.len() as u64
                * metric_maps_bytes(driver.width as u64 * driver.height as u64);
            estimate.bytes += kept;
            estimate.what = format!(
                "a car case: {}, and the metric maps it compares",
                estimate.what
            );
            estimates.push(estimate);
        }
    }
    for (name, _, setup) in ratio_setups() {
        let mut estimate = ratio_estimate(&setup, sizes.ratio, &Compensation::default())?;
        estimate.what = format!("the {name} case: {}", estimate.what);
        estimates.push(estimate);
    }
    Ok(largest(estimates))
}

/// Runs the reproduction into `out`; returns `report.json`'s content.
pub fn reproduce(scene_path: &Path, out: &Path, quick: bool) -> Result<serde_json::Value> {
    let base = Scene::load(scene_path)?;
    reproduce_named(&base, &scene_path.display().to_string(), out, quick)
}

/// As [`reproduce`] on scene `base`, read from the file the report names `scene_name` (the
/// built-in copy's temporary path would mean nothing to a reader).
pub fn reproduce_named(
    base: &Scene,
    scene_name: &str,
    out: &Path,
    quick: bool,
) -> Result<serde_json::Value> {
    let sizes = sizes(quick);
    let mut cases = Vec::new();
    let mut equal = Vec::new();
    // Four display cases, then the two ratio setups.
    let progress = Progress::new("reproduce", 6, true);
    // §5.2 Figs. 4 and 5: the car close and far, θ_F = 30° and 63.5°, D = 1 m, d2 → ∞.
    for (car_label, distance) in CARS {
        let mut compared: Vec<(String, MetricMaps)> = Vec::new();
        for theta in THETAS_DEG {
            let name = format!("car {car_label} (≈{distance} m), θ_F = {theta}°, D = 1 m");
            let dir = format!("car_{car_label}_theta{}", theta as u32);
            let scene = das_case(base, distance, 1.0, theta)?;
            let ctx = RenderContext::new(scene)?;
            let result = run(&ctx, &case_options(&sizes))?;
            let (maps, metrics) = measure(
                &ctx,
                &ctx.scene,
                ctx.scene.eye(),
                result.measured_views(),
                5,
            );
            frame_png(&result.truth, &out.join(&dir).join("truth.png"))?;
            frame_png(&result.seethru, &out.join(&dir).join("seethru.png"))?;
            let (w, h, rgb) = heatmap_rgb(&maps, &result.truth, None)?;
            write_png(&out.join(&dir).join("misregistration.png"), w, h, rgb)?;
            compared.push((format!("θ_F = {theta}°"), maps));
            progress.advance(1);
            cases.push(CaseResult {
                name,
                dir,
                metrics,
                run: result.report,
            });
        }
        equal.push(equal_coverage(
            &format!("car {car_label} (≈{distance} m)"),
            &compared,
        ));
    }
    let mut ratios: Vec<(String, String, RatioResult)> = Vec::new();
    for (name, dir, setup) in ratio_setups() {
        let (r, frames) = measure_ratio_with_frames(&setup, sizes.ratio, &Compensation::default())?;
        frame_png(&frames.truth, &out.join(dir).join("truth.png"))?;
        frame_png(&frames.seethru, &out.join(dir).join("seethru.png"))?;
        ratios.push((name.to_string(), dir.to_string(), r));
        progress.advance(1);
    }
    progress.finish();
    let figures = crate::paper::figures::write_all(&out.join("figures"))?;
    let report = json!({
        "quick": quick,
        "scene": scene_name,
        "cases": cases.iter().map(|c| json!({"name": c.name, "dir": c.dir, "metrics": c.metrics.to_json(), "run": c.run})).collect::<Vec<_>>(),
        "equal_coverage": equal,
        "ratios": ratios.iter().map(|(n, d, r)| json!({"name": n, "dir": d, "result": r})).collect::<Vec<_>>(),
        "figures": figures,
    });
    write_text(
        &out.join("report.json"),
        &serde_json::to_string_pretty(&report)?,
    )?;
    write_text(
        &out.join("report.md"),
        &render_report(out, &cases, &equal, &ratios, &figures, &sizes, false)?,
    )?;
    write_text(
        &out.join("report.html"),
        &render_report(out, &cases, &equal, &ratios, &figures, &sizes, true)?,
    )?;
    Ok(report)
}

/// The mean misregistration of each case over the display pixels that every case covers.
/// The cases must share the driver's view of the display (same eye, display and resolution).
fn equal_coverage(label: &str, cases: &[(String, MetricMaps)]) -> EqualCoverage {
    let display = &cases[0].1.display;
    let common: Vec<usize> = (0..display.len())
        .filter(|&i| display[i] && cases.iter().all(|(_, m)| m.display[i] && !m.blank[i]))
        .collect();
    let means = cases
        .iter()
        .map(|(name, m)| {
            let values = common.iter().map(|&i| m.misregistration[i] as f64);
            (name.clone(), values.sum::<f64>() / common.len() as f64)
        })
        .collect();
    EqualCoverage {
        label: label.to_string(),
        pixels: common.len(),
        coverage: common.len() as f64 / display.iter().filter(|&&d| d).count().max(1) as f64,
        means,
    }
}

/// The default scene path: `scenes/das.toml` of the working directory.
pub fn default_scene() -> PathBuf {
    PathBuf::from("scenes/das.toml")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn das_case_moves_the_car_and_resizes_the_display() {
        let base = Scene::load(Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/das.toml"
        )))
        .unwrap();
        let scene = das_case(&base, 15.0, 1.0, 63.5).unwrap();
        let car = scene.objects.iter().find(|o| o.name == "car").unwrap();
        let obstacle_z = scene.obstacle.world_from_obstacle.translation.z;
        assert!((car.world_from_object.translation.z - (obstacle_z - 15.0)).abs() < 1e-12);
        assert_eq!(scene.obstacle.width, 1.0);
        assert_eq!(scene.obstacle.display_resolution[0], 1000);
        assert!((scene.frontal.half_angle_x.to_degrees() - 63.5).abs() < 1e-12);
    }
}
