//! Hazard visibility: does the driver see the road user the pillar hides? For every object
//! marked `hazard = true`, among its truth pixels that lie where the driver sees the display
//! (hidden by the pillar), the fraction that the see-through view shows as that same object
//! within a misregistration bound, and how far the shown object's centroid is from where it
//! truly is.

use serde_json::json;

use crate::measure::metrics::MetricMaps;
use crate::render::frame::Frame;
use crate::scene::Scene;

/// Default bound of `--hazard-bound-arcmin`: a pixel counts as showing the hazard when the
/// shown point is within this angle of the true one, arc-minutes.
pub const DEFAULT_BOUND_ARCMIN: f64 = 30.0;

/// One hazard object in one frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct HazardFrame {
    pub name: String,
    /// Object id (scene object index + 1).
    pub id: u32,
    /// Its pixels in the truth view.
    pub truth_pixels: u64,
    /// Of those, the pixels where the driver sees the display instead (hidden by the pillar).
    pub hidden_pixels: u64,
    /// Of the hidden pixels, those the see-through view shows as this object within the bound.
    pub shown_pixels: u64,
    /// shown / hidden, [0, 1]; NaN when nothing of it is hidden (then it is not counted).
    pub visibility: f64,
    /// Angle between the centroid of its hidden truth pixels and the centroid of the display
    /// pixels that show it (any misregistration), arc-minutes, at the view's central pixel
    /// pitch; NaN when either set is empty.
    pub centroid_error_arcmin: f64,
}

/// The hazards of one frame: `truth` and `seethru` are the driver views, `maps` the metric
/// maps of the same frame (display mask, misregistration), `arcmin_per_px` the view's angle
/// per pixel at its centre.
pub fn hazard_frame(
    scene: &Scene,
    truth: &Frame,
    seethru: &Frame,
    maps: &MetricMaps,
    bound_arcmin: f64,
    arcmin_per_px: f64,
) -> Vec<HazardFrame> {
    let w = truth.width as usize;
    let mut out = Vec::new();
    for (index, object) in scene.objects.iter().enumerate() {
        if !object.hazard {
            continue;
        }
        let id = index as u32 + 1;
        let (mut truth_pixels, mut hidden, mut shown) = (0u64, 0u64, 0u64);
        let (mut hidden_sum, mut shown_sum, mut shown_any) = ([0.0f64; 2], [0.0f64; 2], 0u64);
        for i in 0..truth.object_id.len() {
            let at = [(i % w) as f64 + 0.5, (i / w) as f64 + 0.5];
            if maps.display[i] && seethru.object_id[i] == id {
                shown_any += 1;
                shown_sum = [shown_sum[0] + at[0], shown_sum[1] + at[1]];
            }
            if truth.object_id[i] != id {
                continue;
            }
            truth_pixels += 1;
            if !maps.display[i] {
                continue;
            }
            hidden += 1;
            hidden_sum = [hidden_sum[0] + at[0], hidden_sum[1] + at[1]];
            let error = maps.misregistration[i] as f64;
            if seethru.object_id[i] == id && error <= bound_arcmin {
                shown += 1;
            }
        }
        let centroid_error_arcmin = if hidden > 0 && shown_any > 0 {
            let (h, s) = (hidden as f64, shown_any as f64);
            let dx = hidden_sum[0] / h - shown_sum[0] / s;
            let dy = hidden_sum[1] / h - shown_sum[1] / s;
            dx.hypot(dy) * arcmin_per_px
        } else {
            f64::NAN
        };
        out.push(HazardFrame {
            name: object.name.clone(),
            id,
            truth_pixels,
            hidden_pixels: hidden,
            shown_pixels: shown,
            visibility: if hidden > 0 {
                shown as f64 / hidden as f64
            } else {
                f64::NAN
            },
            centroid_error_arcmin,
        });
    }
    out
}

/// The `hazards` block of metrics.json.
pub fn hazards_json(hazards: &[HazardFrame], bound_arcmin: f64) -> serde_json::Value {
    json!({
        "bound_arcmin": bound_arcmin,
        "definition": "per object with hazard = true: of its truth pixels where the driver sees the display (hidden by the pillar), the fraction the seethru view shows as the same object id within bound_arcmin of misregistration; visibility is null (NaN) when nothing of it is hidden",
        "objects": hazards.iter().map(|h| json!({
            "name": h.name,
            "id": h.id,
            "truth_pixels": h.truth_pixels,
            "hidden_pixels": h.hidden_pixels,
            "shown_pixels": h.shown_pixels,
            "visibility": h.visibility.is_finite().then_some(h.visibility),
            "centroid_error_arcmin": h.centroid_error_arcmin.is_finite().then_some(h.centroid_error_arcmin),
        })).collect::<Vec<_>>(),
    })
}
