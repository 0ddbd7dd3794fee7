//! `compare --methods map:NAME=FILE`: outside methods' display maps beside the built-in
//! methods, on the capture that `compare`'s own settings make (a map made for another capture
//! is refused by its fingerprint), scored and measured as `score` and `run` do.

use anyhow::Result;
use serde_json::json;

use crate::measure::compare::{Compared, strip};
use crate::measure::measured_run::{MeasureSettings, MeasuredRun, measure_run};
use crate::render::integrator::RenderContext;
use crate::system::capture::{DisplayMap, capture, score};
use crate::system::options::RunOptions;

/// One row per `(name, map)`, at the capture of `base`; the border band is `band` display
/// pixels, the hazards' bound `hazard_bound_arcmin`.
pub fn compare_maps(
    ctx: &RenderContext,
    maps: &[(String, DisplayMap)],
    base: &RunOptions,
    band: u32,
    hazard_bound_arcmin: f64,
) -> Result<Vec<Compared>> {
    if maps.is_empty() {
        return Ok(Vec::new());
    }
    let mut options = base.clone();
    options.progress = false;
    let captured = capture(ctx, &options, false)?;
    let mut out = Vec::new();
    for (name, map) in maps {
        let scored = score(ctx, &options, &captured, Some(map), None).map_err(|e| {
            anyhow::anyhow!(
                "map:{name}: {e:#} (capture with compare's option `width`, option `height`, option `frontal_width`, option `back_width`, option `spp`, option `head` and option `seed`)"
            )
        })?;
        let result = &scored.run;
        let settings = MeasureSettings {
            band,
            hazard_bound_arcmin,
        };
        let MeasuredRun {
            maps,
            metrics,
            hazards,
            ..
        } = measure_run(ctx, &options, result, settings)?;
        let display = &metrics.display;
        let misregistration = &display.misregistration_arcmin;
        let row = json!({
            "hazards": hazards,
            "method": format!("map:{name}"),
            "misregistration_mean_arcmin": misregistration.mean,
            "misregistration_p95_arcmin": misregistration.p95,
            "border_mean_arcmin": metrics.border.misregistration_arcmin.mean,
            "coverage": metrics.coverage,
            "holes_fraction": 0.0,
            "psnr_db": display.psnr_db,
            "ssim": display.ssim,
            "flip_mean": display.flip_mean,
            "ms_per_frame": null,
            "d2_m": null,
            "scene_model": null,
            "reason": null,
            "external_method": result.report["external_method"],
            "metrics": metrics.to_json(),
        });
        out.push(Compared {
            name: format!("map_{name}"),
            row,
            strip: Some(strip(&maps, &result.truth, &result.seethru, None)),
        });
    }
    Ok(out)
}
