//! The metrics on disk: `metrics.json`, the misregistration map as EXR and as a heatmap with
//! a colour bar, and the missing-pixel mask.

use std::path::Path;

use anyhow::Result;
use exr::prelude::{AnyChannel, FlatSamples};

use crate::io::atomic::write_text;
use crate::io::colour_bar::{ColourBar, with_colour_bar};
use crate::io::frame_files::{write_exr_channels, write_png};
use crate::measure::metrics::MetricMaps;
use crate::render::frame::Frame;
use crate::util::color::encode_srgb8;

/// The heatmap's colour for t in [0, 1] (colorous' Turbo: dark blue → green → yellow → dark
/// red, perceptually ordered and readable by most colour-blind readers); NaN as 0.
pub fn heat_color(t: f32) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    colorous::TURBO.eval_continuous(f64::from(t)).as_array()
}

/// The scale of a misregistration heatmap: its top, arc-minutes, and whether it was fixed
/// (`--heatmap-max`) or is the 99th percentile of the display's values.
pub fn heat_top(maps: &MetricMaps, fixed: Option<f32>) -> (f32, String) {
    if let Some(top) = fixed {
        return (top, "arcmin, fixed (--heatmap-max)".into());
    }
    let top = p99_top(maps.misregistration.iter().copied());
    // Clipped at the 99th percentile of the display's values, so that a few extreme pixels
    // do not wash out the rest; the label says so.
    (top, "arcmin, clipped at p99".into())
}

/// The 99th percentile of the finite `values`, arc-minutes, at least 1 (1 when there are
/// none): the top of a heatmap's scale unless `--heatmap-max` fixes it.
pub fn p99_top(values: impl Iterator<Item = f32>) -> f32 {
    let mut values: Vec<f32> = values.filter(|v| v.is_finite()).collect();
    values.sort_by(f32::total_cmp);
    values
        .get((values.len() as f32 * 0.99) as usize)
        .copied()
        .unwrap_or(1.0)
        .max(1.0)
}

/// The misregistration heatmap beside a colour bar in arc-minutes, its top `fixed` when
/// given (`--heatmap-max`), else the 99th percentile of the display's values (labelled on the
/// bar); outside the display, the truth in dimmed grey for context.
pub fn heatmap_rgb(
    maps: &MetricMaps,
    truth: &Frame,
    fixed: Option<f32>,
) -> Result<(u32, u32, Vec<u8>)> {
    let (top, title) = heat_top(maps, fixed);
    let rgb: Vec<u8> = (0..maps.misregistration.len())
        .flat_map(|i| {
            if maps.blank[i] {
                [0, 0, 0]
            } else if maps.display[i] {
                if maps.misregistration[i].is_finite() {
                    heat_color(maps.misregistration[i] / top)
                } else {
                    [255, 0, 255]
                }
            } else {
                let g = (encode_srgb8(truth.color[i])
                    .iter()
                    .map(|&v| v as u32)
                    .sum::<u32>()
                    / 6) as u8;
                [g, g, g]
            }
        })
        .collect();
    let bar = ColourBar {
        colours: heat_color,
        bottom: 0.0,
        top: top as f64,
        unit: "′",
        title,
        legend: vec![
            ([255, 0, 255], "no direction".into()),
            ([0, 0, 0], "blank".into()),
        ],
        clipped: true,
    };
    with_colour_bar(maps.width, maps.height, &rgb, &bar)
}

/// Writes `metrics.json` (`metrics`: the record's JSON, in the front end's words),
/// `misregistration.exr` (`Y`: misregistration, arcmin, NaN outside the display and on blank
/// pixels; `missing.mask`: 1 where missing; `display.mask`: 1 where the driver sees the
/// display — `Y` so that grey-image readers open it),
/// `misregistration.png` (heatmap with colour bar) and `missing.png` into `dir`.
pub fn write_metrics(
    dir: &Path,
    maps: &MetricMaps,
    truth: &Frame,
    metrics: &serde_json::Value,
) -> Result<()> {
    write_metrics_scaled(dir, maps, truth, metrics, None)
}

/// [`write_metrics`] with the heatmap's scale fixed at `heat_max` arc-minutes when given.
pub fn write_metrics_scaled(
    dir: &Path,
    maps: &MetricMaps,
    truth: &Frame,
    metrics: &serde_json::Value,
    heat_max: Option<f32>,
) -> Result<()> {
    write_text(
        &dir.join("metrics.json"),
        &serde_json::to_string_pretty(metrics)?,
    )?;
    // The three images side by side (a run's last writes, while its other views may be
    // written already); the first error in this order.
    let exr = || {
        let channels = vec![
            AnyChannel::new("Y", FlatSamples::F32(maps.misregistration.clone())),
            AnyChannel::new(
                "missing.mask",
                FlatSamples::F32(maps.missing.iter().map(|&m| m as u8 as f32).collect()),
            ),
            AnyChannel::new(
                "display.mask",
                FlatSamples::F32(maps.display.iter().map(|&d| d as u8 as f32).collect()),
            ),
        ];
        write_exr_channels(
            &dir.join("misregistration.exr"),
            maps.width,
            maps.height,
            channels,
        )
    };
    let heatmap = || {
        let (w, h, rgb) = heatmap_rgb(maps, truth, heat_max)?;
        write_png(&dir.join("misregistration.png"), w, h, rgb)
    };
    let mask = || write_mask_png(&dir.join("missing.png"), maps, &maps.missing);
    let (exr, (heatmap, mask)) = rayon::join(exr, || rayon::join(heatmap, mask));
    exr.and(heatmap).and(mask)
}

/// A mask of driver-view pixels as a PNG: `marked` pixels magenta, the rest of the display
/// dark grey, outside the display black.
pub fn write_mask_png(path: &Path, maps: &MetricMaps, marked: &[bool]) -> Result<()> {
    let rgb = marked
        .iter()
        .zip(&maps.display)
        .flat_map(|(&m, &d)| {
            if m {
                [255, 0, 255]
            } else if d {
                [60, 60, 60]
            } else {
                [0, 0, 0]
            }
        })
        .collect();
    write_png(path, maps.width, maps.height, rgb)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// A 4×1 driver view: two display pixels (5′ and 20′), one blank, one outside the
    /// display (truth white); values 0..199 elsewhere set the p99.
    fn maps_of(misregistration: Vec<f32>) -> MetricMaps {
        let n = misregistration.len();
        let mut display = vec![true; n];
        display[3] = false;
        let mut blank = vec![false; n];
        blank[2] = true;
        MetricMaps::of_masks([n as u32, 1], misregistration, display, blank)
    }

    #[test]
    fn the_heatmap_scale_is_the_p99_or_the_fixed_top_and_says_which() {
        let maps = maps_of((0..200).map(|k| ((k * 67) % 200) as f32).collect());
        assert_eq!(
            heat_top(&maps, None),
            (198.0, "arcmin, clipped at p99".to_string())
        );
        assert_eq!(
            heat_top(&maps, Some(12.5)),
            (12.5, "arcmin, fixed (--heatmap-max)".to_string())
        );
    }

    /// Each pixel's colour: the display's by its value over the top, blank black, outside
    /// the truth's grey (a sixth of its sRGB sum).
    #[test]
    fn heatmap_pixels_are_coloured_by_value_over_the_top() {
        let maps = maps_of(vec![5.0, 20.0, f32::NAN, f32::NAN]);
        let mut truth = Frame::new(4, 1);
        truth.color = vec![Vec3::ONE; 4];
        for (fixed, top) in [(None, 20.0), (Some(40.0), 40.0)] {
            let (w, h, rgb) = heatmap_rgb(&maps, &truth, fixed).unwrap();
            assert!(w > 4 && h >= 1);
            let pixel = |x: usize| [rgb[3 * x], rgb[3 * x + 1], rgb[3 * x + 2]];
            assert_eq!(pixel(0), heat_color(5.0 / top), "{fixed:?}");
            assert_eq!(pixel(1), heat_color(20.0 / top), "{fixed:?}");
            assert_eq!(pixel(2), [0, 0, 0]);
            assert_eq!(pixel(3), [127, 127, 127]);
        }
        assert_ne!(heat_color(0.25), heat_color(0.5));
    }

    #[test]
    fn the_p99_top_skips_non_finite_values_and_is_at_least_one() {
        // 0, 1, …, 199 shuffled, with NaN and ∞ that must not count: the value at index
        // ⌊200 · 0.99⌋ = 198 of the sorted finite values.
        let values = (0..200).map(|k| ((k * 67) % 200) as f32).chain([
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ]);
        assert_eq!(p99_top(values), 198.0);
        assert_eq!(p99_top([0.1f32, 0.2].into_iter()), 1.0);
        assert_eq!(p99_top(std::iter::empty()), 1.0);
    }
}
