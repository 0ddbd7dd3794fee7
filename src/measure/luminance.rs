//! The display's light against the world's, in a scene lit in physical units: per display
//! pixel the luminance the driver sees on the display over the luminance the truth has there
//! (in stops, log2), over the whole display and its border band (where the display meets the
//! world around it: the photometric seam), and the share of those pixels where the
//! difference is a step a driver would see.
//!
//! The visibility threshold is a Weber contrast |Y_seethru − Y_truth| / Y_truth of
//! [`WEBER_THRESHOLD`]: Blackwell (1946, "Contrast thresholds of the human eye", JOSA 36:624)
//! measured about 0.01–0.02 for large targets seen for seconds at daylight adaptation. It
//! rises at dusk and night (mesopic and scotopic adaptation), so at low luminance this share
//! counts too many steps as visible: the value is a photopic bound, stated in the output.

use serde::Serialize;

use crate::render::frame_over::FrameView;
use crate::scene::Photometry;
use crate::util::color::luminance;

/// Weber contrast a driver sees as a step (photopic, large targets; see the module's note).
pub const WEBER_THRESHOLD: f64 = 0.02;

const THRESHOLD_SOURCE: &str = "Weber contrast |Y_seethru - Y_truth| / Y_truth above 0.02: Blackwell (1946), JOSA 36:624, large targets at daylight adaptation; higher thresholds at dusk and night make this an upper bound there";

/// metrics.json's `luminance` (a scene lit in physical units only).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LuminanceMetrics {
    /// The scene's white (a linear 1.0), cd/m².
    pub white_cd_m2: f64,
    /// Over every display pixel.
    pub display: LuminanceRegion,
    /// Over the display's border band (metrics.json's `border`): the photometric seam.
    pub border: LuminanceRegion,
    pub weber_threshold: f64,
    pub threshold_source: &'static str,
}

/// The luminance of one region of the display against the truth's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LuminanceRegion {
    /// Pixels with both luminances positive, over which the rest is taken.
    pub pixels: usize,
    /// Pixels left out: the truth or the display black there (no ratio).
    pub pixels_left_out: usize,
    /// Mean luminance of the truth and of what the display gives off, cd/m².
    pub truth_mean_cd_m2: f64,
    pub seethru_mean_cd_m2: f64,
    /// log2(Y_seethru / Y_truth), stops: 0 where the display matches the world, −3 where it
    /// gives an eighth of its light.
    pub ratio_log2: RatioStats,
    /// Fraction of the pixels whose Weber contrast to the truth is above the threshold.
    pub visible_share: f64,
}

/// The luminance metrics of `seethru` against `truth` over the display pixels `on_display`
/// (frame indices), `border[k]` saying whether pixel `k` of them is in the border band.
pub fn luminance_metrics(
    photometry: &Photometry,
    truth: FrameView<'_>,
    seethru: FrameView<'_>,
    on_display: &[usize],
    border: &[bool],
) -> LuminanceMetrics {
    let white = photometry.white_cd_m2;
    let at = |frame: FrameView<'_>, i: usize| -> f64 {
        f64::from(luminance(frame.get(|f| &f.color, i))) * white
    };
    let pairs: Vec<(f64, f64)> = on_display
        .iter()
        .map(|&i| (at(truth, i), at(seethru, i)))
        .collect();
    let region = |keep: &dyn Fn(usize) -> bool| {
        let chosen: Vec<(f64, f64)> = (0..pairs.len())
            .filter(|&k| keep(k))
            .map(|k| pairs[k])
            .collect();
        LuminanceRegion::of(&chosen)
    };
    LuminanceMetrics {
        white_cd_m2: white,
        display: region(&|_| true),
        border: region(&|k| border[k]),
        weber_threshold: WEBER_THRESHOLD,
        threshold_source: THRESHOLD_SOURCE,
    }
}

/// The statistics of a region's log2 ratios (NaN without any).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RatioStats {
    pub count: usize,
    pub mean: f64,
    /// The smallest value with half of the values at or below it.
    pub median: f64,
    /// The smallest value with 95 % of the values at or below it.
    pub p95: f64,
    pub min: f64,
    pub max: f64,
}

impl RatioStats {
    /// The statistics of `values` (sorted in place).
    fn of(values: &mut [f64]) -> RatioStats {
        values.sort_by(f64::total_cmp);
        let n = values.len();
        let at = |q: f64| match n {
            0 => f64::NAN,
            _ => crate::util::quantile::nearest_rank(values, q),
        };
        RatioStats {
            count: n,
            mean: match n {
                0 => f64::NAN,
                _ => values.iter().sum::<f64>() / n as f64,
            },
            median: at(0.5),
            p95: at(0.95),
            min: values.first().copied().unwrap_or(f64::NAN),
            max: values.last().copied().unwrap_or(f64::NAN),
        }
    }
}

impl LuminanceRegion {
    /// The statistics of (truth, seethru) luminance pairs, cd/m².
    pub fn of(pairs: &[(f64, f64)]) -> LuminanceRegion {
        let kept: Vec<(f64, f64)> = (pairs.iter().copied())
            .filter(|&(t, s)| t > 0.0 && s > 0.0)
            .collect();
        let n = kept.len();
        let mean = |pick: fn(&(f64, f64)) -> f64| match n {
            0 => f64::NAN,
            _ => kept.iter().map(pick).sum::<f64>() / n as f64,
        };
        let mut ratios: Vec<f64> = kept.iter().map(|(t, s)| (s / t).log2()).collect();
        let visible = (kept.iter())
            .filter(|(t, s)| (s - t).abs() / t > WEBER_THRESHOLD)
            .count();
        let ratio_log2 = RatioStats::of(&mut ratios);
        LuminanceRegion {
            pixels: n,
            pixels_left_out: pairs.len() - n,
            truth_mean_cd_m2: mean(|p| p.0),
            seethru_mean_cd_m2: mean(|p| p.1),
            ratio_log2,
            visible_share: match n {
                0 => f64::NAN,
                _ => visible as f64 / n as f64,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_region_counts_what_it_leaves_out_and_the_steps_above_the_threshold() {
        // 1 % and 3 % brighter than the truth (below and above the 2 % threshold), the same,
        // and two pixels without a ratio (a black truth, a black display).
        let pairs = [
            (100.0, 101.0),
            (100.0, 103.0),
            (50.0, 50.0),
            (0.0, 5.0),
            (10.0, 0.0),
        ];
        let r = LuminanceRegion::of(&pairs);
        assert_eq!((r.pixels, r.pixels_left_out), (3, 2));
        assert_eq!(r.visible_share, 1.0 / 3.0);
        assert_eq!(r.truth_mean_cd_m2, 250.0 / 3.0);
        assert_eq!(r.seethru_mean_cd_m2, 254.0 / 3.0);
        assert_eq!(r.ratio_log2.median, 1.01f64.log2());
        assert_eq!(r.ratio_log2.min, 0.0);
        assert_eq!(r.ratio_log2.max, 1.03f64.log2());
        // A step just inside the threshold is not visible; one darker beyond it is.
        let r = LuminanceRegion::of(&[(100.0, 98.5), (100.0, 97.0)]);
        assert_eq!(r.visible_share, 0.5);
        let none = LuminanceRegion::of(&[(0.0, 0.0)]);
        assert!(none.visible_share.is_nan() && none.pixels_left_out == 1);
    }
}
