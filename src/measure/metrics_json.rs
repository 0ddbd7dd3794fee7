//! metrics.json: the statistics of the display pixels' measurements, over the whole display,
//! its border band and each side of it, as typed records ([`Metrics`]): a reader names a
//! field, not a JSON path, so a wrong name does not compile instead of reading as NaN. The
//! file is the record serialized with its keys sorted (serde_json's map order), one shape
//! whatever the display: a statistic with no value is `null`, never absent.

use serde::Serialize;
use serde_json::Value;

use crate::analysis::physical::ARCMIN_PER_RAD;
use crate::measure::image_metrics::{DisplayImages, Flip, psnr_over};
use crate::measure::misregistration::{Measured, Missing};
use crate::scene::Scene;
use crate::util::quantile::nearest_rank;

/// Summary statistics of a set of values; with none, `mean`, `p95` and `max` are NaN (`null`
/// in the file).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Stats {
    pub count: usize,
    pub mean: f64,
    /// The smallest value with 95 % of the values at or below it.
    pub p95: f64,
    pub max: f64,
}

impl Stats {
    /// The statistics of `values` (sorted in place).
    pub fn of(values: &mut [f64]) -> Stats {
        if values.is_empty() {
            return Stats {
                count: 0,
                mean: f64::NAN,
                p95: f64::NAN,
                max: f64::NAN,
            };
        }
        values.sort_by(f64::total_cmp);
        let n = values.len();
        Stats {
            count: n,
            mean: values.iter().sum::<f64>() / n as f64,
            p95: nearest_rank(values, 0.95),
            max: values[n - 1],
        }
    }
}

/// The metrics over one region of the display (all of it, its border band, one side).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Region {
    /// Display pixels in the region.
    pub pixels: usize,
    /// Fraction of them that show the scene, [0, 1]; NaN for an empty region.
    pub coverage: f64,
    pub blank_pixels: usize,
    /// Over the covered pixels, arc-minutes.
    pub misregistration_arcmin: Stats,
    /// Mean over the region's pixels and the three channels, 8-bit sRGB levels.
    pub mean_abs_colour_error_8bit: f64,
    pub psnr_db: f64,
    pub ssim: f64,
    /// NaN where FLIP was not computed.
    pub flip_mean: f64,
}

/// The border band's regions by side.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PerSide {
    pub left: Region,
    pub right: Region,
    pub top: Region,
    pub bottom: Region,
}

/// Covered display pixels by where the sky is.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SkyPixels {
    pub truth_only: usize,
    pub seethru_only: usize,
    pub both: usize,
}

/// Display pixels whose truth point (or sky direction) the frontal camera cannot see.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MissingPixels {
    /// Of the display's pixels, [0, 1] (0 for no display pixel).
    pub fraction: f64,
    pub outside_frontal_view: usize,
    pub hidden_from_frontal: usize,
}

/// metrics.json.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Metrics {
    /// Driver-view pixels that show the display.
    pub display_pixels: usize,
    /// Fraction of them that show the scene, [0, 1]; NaN with none.
    pub coverage: f64,
    pub blank_pixels: usize,
    pub sky_pixels_included: SkyPixels,
    /// Neither a point nor a direction (0 for frames of this version).
    pub undefined_pixels: usize,
    /// The driver camera's pixel pitch at the centre, arc-minutes.
    pub driver_pixel_arcmin: f64,
    pub display: Region,
    /// The display's mean misregistration in driver-view pixels.
    pub misregistration_mean_driver_px: f64,
    pub border_band_display_px: u32,
    pub border: Region,
    pub border_per_side: PerSide,
    pub missing: MissingPixels,
    /// The driver camera's pixels per degree at which FLIP is taken.
    pub flip_pixels_per_degree: f32,
    pub notes: &'static str,
    /// Why every `flip_mean` is null, when FLIP was not computed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flip_not_computed: Option<&'static str>,
    /// The display's holes (`--method depth`): measure/holes.rs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holes: Option<Value>,
    /// A scored outside method's record (run.json's `external_method`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub external_method: Option<Value>,
    /// Why misregistration is undefined for an outside method's image without a map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub misregistration_needs_a_map: Option<&'static str>,
    /// The display's light against the world's, in a scene lit in physical units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub luminance: Option<crate::measure::luminance::LuminanceMetrics>,
}

impl Metrics {
    /// metrics.json's tree (keys sorted, NaN as `null`).
    pub fn to_json(&self) -> Value {
        serde_json::to_value(self).expect("metrics are plain numbers and strings")
    }
}

const NOTES: &str = "every display pixel counts. misregistration: angle at the eye between the direction seethru shows and the truth's (towards a world point, or a sky direction), over the covered pixels; coverage: fraction of the region's pixels that show the scene (blank pixels, outside the frontal view, have no misregistration and count in the image metrics as the black they show); undefined_pixels: neither a point nor a direction (0 for frames of this version). Colour metrics on 8-bit sRGB; SSIM on luminance with 7×7 windows inside the display mask; FLIP (NVIDIA, via nv-flip) with the driver's camera as observer, on the display's bounding box with everything outside the display mask set to the same grey in both images";

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

/// The metrics of the display pixels' `measured` geometry and `images` scores (both in the
/// pixels' order), in frames `frame_width` pixels wide of `scene`'s driver camera; `band` is
/// the border band's width in display pixels.
pub(crate) fn display_metrics(
    scene: &Scene,
    frame_width: usize,
    measured: &[Measured],
    images: &DisplayImages,
    band: u32,
    flip: Flip,
) -> Metrics {
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
        Region {
            pixels,
            coverage: if pixels == 0 {
                f64::NAN
            } else {
                1.0 - blank as f64 / pixels as f64
            },
            blank_pixels: blank,
            misregistration_arcmin: Stats::of(&mut values),
            mean_abs_colour_error_8bit: colour_error,
            psnr_db: psnr_over(srgb_t, srgb_s, &pixels_in),
            ssim: over(ssim),
            flip_mean: over(flip_map),
        }
    };
    let side = |k: usize| region(&|m| m.sides[k]);
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
    Metrics {
        display_pixels: count,
        coverage: if count == 0 {
            f64::NAN
        } else {
            1.0 - blank_count as f64 / count as f64
        },
        blank_pixels: blank_count,
        sky_pixels_included: SkyPixels {
            truth_only: sky(true, false),
            seethru_only: sky(false, true),
            both: sky(true, true),
        },
        undefined_pixels: count_where(&|m| m.class.undefined),
        driver_pixel_arcmin,
        display: region(&|_| true),
        misregistration_mean_driver_px: mean_px,
        border_band_display_px: band,
        border: region(&|m| m.sides.iter().any(|&s| s)),
        border_per_side: PerSide {
            left: side(0),
            right: side(1),
            top: side(2),
            bottom: side(3),
        },
        missing: MissingPixels {
            fraction: if count == 0 {
                0.0
            } else {
                (out_of_view + hidden) as f64 / count as f64
            },
            outside_frontal_view: out_of_view,
            hidden_from_frontal: hidden,
        },
        flip_pixels_per_degree: ppd,
        notes: NOTES,
        flip_not_computed: (flip == Flip::Skipped).then_some(
            "FLIP was not computed (a sequence without option `flip`): every flip_mean is null",
        ),
        holes: None,
        external_method: None,
        misregistration_needs_a_map: None,
        luminance: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_one_to_a_hundred() {
        let mut values: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        let s = Stats::of(&mut values);
        assert_eq!((s.count, s.mean, s.max), (100, 50.5, 100.0));
        // The 95th percentile: the smallest value with 95 % of the values at or below it.
        assert_eq!(s.p95, 95.0);
        assert_eq!(Stats::of(&mut [7.0]).p95, 7.0);
    }

    #[test]
    fn no_value_has_one_shape_with_nulls() {
        let none = serde_json::to_value(Stats::of(&mut [])).unwrap();
        assert_eq!(
            none,
            serde_json::json!({"count": 0, "mean": null, "p95": null, "max": null})
        );
        let one = serde_json::to_value(Stats::of(&mut [2.0])).unwrap();
        assert_eq!(
            one,
            serde_json::json!({"count": 1, "mean": 2.0, "p95": 2.0, "max": 2.0})
        );
    }
}
