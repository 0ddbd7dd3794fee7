//! One run measured as every front end measures it: `seethru run`, `score` and `compare`,
//! and `seethru.run`/`score`/`compare` in Python call this, so that metrics.json, the hole
//! mask and hazards.json come from one place.

use anyhow::Result;
use glam::DVec3;
use serde_json::Value;

use crate::geometry::camera::Camera;
use crate::measure::hazard::run_hazards_json;
use crate::measure::holes::attach_view_holes;
use crate::measure::metrics::{MetricMaps, measure};
use crate::measure::metrics_json::Metrics;
use crate::render::frame_over::FrameView;
use crate::render::integrator::RenderContext;
use crate::system::options::RunOptions;
use crate::system::pipeline::{RunResult, driver_camera};

/// How a run is measured: the options that shape its numbers, not the system's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasureSettings {
    /// Width of the border band of the mismatch metrics, display pixels in [1, 1000].
    pub band: u32,
    /// A hidden hazard pixel counts as shown within this misregistration, arcmin.
    pub hazard_bound_arcmin: f64,
}

impl Default for MeasureSettings {
    fn default() -> Self {
        MeasureSettings {
            band: 5,
            hazard_bound_arcmin: crate::measure::hazard::HAZARD_BOUND_ARCMIN,
        }
    }
}

/// A run's measurement.
pub struct MeasuredRun {
    /// Per driver-view pixel: misregistration, missing, … (the heatmaps' values).
    pub maps: MetricMaps,
    /// metrics.json's content.
    pub metrics: Metrics,
    /// The driver-view pixels that show a hole of the display (`--method depth`), if any.
    pub holes: Option<Vec<bool>>,
    /// hazards.json's content.
    pub hazards: Value,
}

/// The driver views a run is measured on, [truth, occluded, seethru], with the display's
/// holes: what [`measure_views`] reads, available to `seethru run` before its other views
/// are written.
pub struct DriverViews<'a> {
    pub views: [FrameView<'a>; 3],
    pub display_holes: Option<&'a [bool]>,
    /// run.json's `external_method` (a scored outside method), if any.
    pub external_method: Option<&'a Value>,
}

/// metrics.json and the hole mask of the driver views `views`, seen from `eye` (world,
/// metres), the holes filled as `options` says.
pub fn measure_views(
    ctx: &RenderContext,
    options: &RunOptions,
    eye: DVec3,
    views: &DriverViews<'_>,
    band: u32,
) -> (MetricMaps, Metrics, Option<Vec<bool>>) {
    let [truth, occluded, seethru] = views.views;
    let (maps, mut metrics) = measure(ctx, &ctx.scene, eye, [truth, seethru, occluded], band);
    let holes = attach_view_holes(
        &mut metrics,
        &maps,
        views.display_holes,
        views.views,
        &ctx.scene.obstacle,
        options.scene_model.fill,
    );
    if let Some(external) = views.external_method {
        metrics.external_method = Some(external.clone());
        if !external["display_from"]
            .as_str()
            .is_some_and(|s| s.contains("map"))
        {
            metrics.misregistration_needs_a_map = Some(
                "the display image alone carries no geometry: misregistration is undefined on every display pixel (counted in undefined_pixels); give option `map` for it",
            );
        }
    }
    (maps, metrics, holes)
}

/// The eye a run's driver views were rendered from (world, metres).
pub fn view_eye(ctx: &RenderContext, options: &RunOptions) -> DVec3 {
    options.eyes.view_camera(&ctx.scene.driver).position()
}

/// hazards.json of a measured run: its driver camera is `options`'.
pub fn hazards_of(
    ctx: &RenderContext,
    options: &RunOptions,
    result: &RunResult,
    maps: &MetricMaps,
    hazard_bound_arcmin: f64,
) -> Result<Value> {
    let driver: Camera = driver_camera(&ctx.scene, options)?;
    Ok(run_hazards_json(
        ctx,
        &driver,
        result,
        maps,
        hazard_bound_arcmin,
    ))
}

/// `result`, a run of `options` in `ctx`, measured whole.
pub fn measure_run(
    ctx: &RenderContext,
    options: &RunOptions,
    result: &RunResult,
    settings: MeasureSettings,
) -> Result<MeasuredRun> {
    let [truth, seethru, occluded] = result.measured_views();
    let views = DriverViews {
        views: [truth, occluded, seethru],
        display_holes: result.holes.as_deref(),
        external_method: result.report.get("external_method"),
    };
    let (maps, metrics, holes) =
        measure_views(ctx, options, view_eye(ctx, options), &views, settings.band);
    let hazards = hazards_of(ctx, options, result, &maps, settings.hazard_bound_arcmin)?;
    Ok(MeasuredRun {
        maps,
        metrics,
        holes,
        hazards,
    })
}
