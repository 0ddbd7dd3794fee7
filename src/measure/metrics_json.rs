//! metrics.json: the statistics of the display pixels' measurements, over the whole display,
//! its border band and each side of it.

use serde_json::json;

use crate::analysis::physical::ARCMIN_PER_RAD;
use crate::measure::image_metrics::{DisplayImages, Flip, psnr_over};
use crate::measure::misregistration::{Measured, Missing};
use crate::scene::Scene;
use crate::util::quantile::nearest_rank;

/// Summary statistics of a set of values.
pub fn stats(values: &mut [f64]) -> serde_json::Value {
    if values.is_empty() {
        return json!({"count": 0});
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    let mean = values.iter().sum::<f64>() / n as f64;
    let p95 = nearest_rank(values, 0.95);
    json!({"count": n, "mean": mean, "p95": p95, "max": values[n - 1]})
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

/// The metrics JSON of the display pixels' `measured` geometry and `images` scores (both in
/// the pixels' order), in frames `frame_width` pixels wide of `scene`'s driver camera; `band`
/// is the border band's width in display pixels.
pub(crate) fn metrics_json(
    scene: &Scene,
    frame_width: usize,
    measured: &[Measured],
    images: &DisplayImages,
    band: u32,
    flip: Flip,
) -> serde_json::Value {
    let count = measured.len();
    let (srgb_t, srgb_s) = (&images.truth, &images.shown);
    let (ssim, flip_map, ppd) = (&images.ssim, &images.flip, images.ppd);
    let count_where =
        |keep: &dyn Fn(&Measured) -> bool| measured.iter().filter(|m| keep(m)).count();
    let out_of_view = count_where(&|m| m.missing == Some(Missing::OutOfView));
    let hidden = count_where(&|m| m.missing == Some(Missing::Hidden));
    let driver_pixel_arcmin =
        (2.0 * scene.driver.tan_half_x() / frame_width as f64).atan() * ARCMIN_PER_RAD;
    let region = |keep: &dyn Fn(&Measured) -> bool| {
        let pixels_in: Vec<usize> = (0..count).filter(|&k| keep(&measured[k])).collect();
        let pixels = pixels_in.len();
        let blank = pixels_in
            .iter()
            .filter(|&&k| measured[k].class.blank)
            .count();
        let mut values: Vec<f64> = pixels_in
            .iter()
            .map(|&k| measured[k].misregistration)
            .filter(|v| v.is_finite())
            .map(f64::from)
            .collect();
        let over = |map: &[f64]| mean(pixels_in.iter().map(|&k| map[k]));
        let colour_error = mean(pixels_in.iter().map(|&k| {
            (0..3)
                .map(|c| (srgb_t[k][c] as f64 - srgb_s[k][c] as f64).abs())
                .sum::<f64>()
                / 3.0
        }));
        json!({
            "pixels": pixels,
            "coverage": if pixels == 0 { f64::NAN } else { 1.0 - blank as f64 / pixels as f64 },
            "blank_pixels": blank,
            "misregistration_arcmin": stats(&mut values),
            "mean_abs_colour_error_8bit": colour_error,
            "psnr_db": psnr_over(srgb_t, srgb_s, &pixels_in),
            "ssim": over(ssim),
            "flip_mean": over(flip_map),
        })
    };
    let per_side: serde_json::Map<String, serde_json::Value> = ["left", "right", "top", "bottom"]
        .iter()
        .enumerate()
        .map(|(k, name)| (name.to_string(), region(&|m| m.sides[k])))
        .collect();
    let blank_count = count_where(&|m| m.class.blank);
    let mean_px = mean(
        measured
            .iter()
            .map(|m| m.misregistration)
            .filter(|v| v.is_finite())
            .map(f64::from),
    ) / driver_pixel_arcmin;
    let sky = |truth_sky: bool, shown_sky: bool| {
        count_where(&|m| {
            m.misregistration.is_finite()
                && m.class.truth_sky == truth_sky
                && m.class.shown_sky == shown_sky
        })
    };
    let mut json = json!({
        "display_pixels": count,
        "coverage": if count == 0 { f64::NAN } else { 1.0 - blank_count as f64 / count as f64 },
        "blank_pixels": blank_count,
        "sky_pixels_included": {
            "truth_only": sky(true, false),
            "seethru_only": sky(false, true),
            "both": sky(true, true),
        },
        "undefined_pixels": count_where(&|m| m.class.undefined),
        "driver_pixel_arcmin": driver_pixel_arcmin,
        "display": region(&|_| true),
        "misregistration_mean_driver_px": mean_px,
        "border_band_display_px": band,
        "border": region(&|m| m.sides.iter().any(|&s| s)),
        "border_per_side": per_side,
        "missing": {
            "fraction": if count == 0 { 0.0 } else { (out_of_view + hidden) as f64 / count as f64 },
            "outside_frontal_view": out_of_view,
            "hidden_from_frontal": hidden,
        },
        "flip_pixels_per_degree": ppd,
        "notes": "every display pixel counts. misregistration: angle at the eye between the direction seethru shows and the truth's (towards a world point, or a sky direction), over the covered pixels; coverage: fraction of the region's pixels that show the scene (blank pixels, outside the frontal view, have no misregistration and count in the image metrics as the black they show); undefined_pixels: neither a point nor a direction (0 for frames of this version). Colour metrics on 8-bit sRGB; SSIM on luminance with 7×7 windows inside the display mask; FLIP (NVIDIA, via nv-flip) with the driver's camera as observer, on the display's bounding box with everything outside the display mask set to the same grey in both images",
    });
    if flip == Flip::Skipped {
        json["flip_not_computed"] = json!(
            "FLIP was not computed (a sequence without option `flip`): every flip_mean is null"
        );
    }
    json
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_one_to_a_hundred() {
        let mut values: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        let s = stats(&mut values);
        assert_eq!(s["count"], 100);
        assert_eq!(s["mean"], 50.5);
        // The 95th percentile: the smallest value with 95 % of the values at or below it.
        assert_eq!(s["p95"], 95.0);
        assert_eq!(s["max"], 100.0);
        assert_eq!(stats(&mut [7.0])["p95"], 7.0);
        assert_eq!(stats(&mut [])["count"], 0);
    }
}
