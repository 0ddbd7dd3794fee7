//! The metrics on disk: `metrics.json`, the misregistration map as EXR and as a heatmap with
//! a colour bar, and the missing-pixel mask.

use std::path::Path;

use anyhow::Result;
use exr::prelude::{AnyChannel, FlatSamples};

use crate::io::atomic::write_text;
use crate::io::frame_files::{write_exr_channels, write_png};
use crate::io::plot::register_font;
use crate::measure::metrics::MetricMaps;
use crate::render::frame::Frame;
use crate::util::color::encode_srgb8;

/// The heatmap's colour for t in [0, 1] (colorous' Turbo: dark blue → green → yellow → dark
/// red, perceptually ordered and readable by most colour-blind readers); NaN as 0.
pub fn heat_color(t: f32) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    colorous::TURBO.eval_continuous(f64::from(t)).as_array()
}

/// The misregistration heatmap beside a colour bar in arc-minutes, clipped at the 99th
/// percentile of the display's values (labelled on the bar); outside the display, the truth
/// in dimmed grey for context.
pub fn heatmap_rgb(maps: &MetricMaps, truth: &Frame) -> Result<(u32, u32, Vec<u8>)> {
    use plotters::prelude::*;
    let (w, h) = (maps.width, maps.height);
    let values: Vec<f32> = maps
        .misregistration
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    let top = {
        let mut v = values.clone();
        v.sort_by(f32::total_cmp);
        v.get((v.len() as f32 * 0.99) as usize)
            .copied()
            .unwrap_or(1.0)
            .max(1.0)
    };
    let (cw, ch) = (w + 170, h.max(160));
    let mut buffer = vec![255u8; (cw * ch * 3) as usize];
    {
        register_font()?;
        let err = |e: DrawingAreaErrorKind<_>| anyhow::anyhow!("{e}");
        let root = BitMapBackend::with_buffer(&mut buffer, (cw, ch)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let c = if maps.blank[i] {
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
                };
                root.draw_pixel((x as i32, y as i32), &RGBColor(c[0], c[1], c[2]))
                    .map_err(err)?;
            }
        }
        let (x0, y0, bar_h) = (w as i32 + 20, 30i32, ch as i32 - 85);
        for k in 0..bar_h {
            let c = heat_color(1.0 - k as f32 / bar_h as f32);
            root.draw(&Rectangle::new(
                [(x0, y0 + k), (x0 + 22, y0 + k + 1)],
                RGBColor(c[0], c[1], c[2]).filled(),
            ))
            .map_err(err)?;
        }
        let style = ("sans-serif", 14).into_font().color(&BLACK);
        for (frac, label) in [
            (0.0, format!("≥ {top:.1}′ (p99)")),
            (0.5, format!("{:.1}′", top / 2.0)),
            (1.0, "0′".to_string()),
        ] {
            root.draw(&Text::new(
                label,
                (x0 + 28, y0 + (frac * bar_h as f64) as i32 - 7),
                style.clone(),
            ))
            .map_err(err)?;
        }
        // The scale is clipped at the 99th percentile of the display's values, so that a few
        // extreme pixels do not wash out the rest; the label says so.
        root.draw(&Text::new(
            "arcmin, clipped at p99",
            (x0 - 4, 8),
            style.clone(),
        ))
        .map_err(err)?;
        root.draw(&Rectangle::new(
            [(x0, ch as i32 - 30), (x0 + 22, ch as i32 - 18)],
            RGBColor(255, 0, 255).filled(),
        ))
        .map_err(err)?;
        root.draw(&Text::new(
            "no direction",
            (x0 + 28, ch as i32 - 32),
            style.clone(),
        ))
        .map_err(err)?;
        root.draw(&Rectangle::new(
            [(x0, ch as i32 - 14), (x0 + 22, ch as i32 - 2)],
            BLACK.filled(),
        ))
        .map_err(err)?;
        root.draw(&Text::new("blank", (x0 + 28, ch as i32 - 16), style))
            .map_err(err)?;
        root.present().map_err(err)?;
    }
    Ok((cw, ch, buffer))
}

/// Writes `metrics.json`, `misregistration.exr` (`Y`: misregistration, arcmin, NaN outside the
/// display and on blank pixels;
/// `missing.mask`: 1 where missing — `Y` so that grey-image readers open it),
/// `misregistration.png` (heatmap with colour bar) and `missing.png` into `dir`.
pub fn write_metrics(
    dir: &Path,
    maps: &MetricMaps,
    truth: &Frame,
    json: &serde_json::Value,
) -> Result<()> {
    write_text(
        &dir.join("metrics.json"),
        &serde_json::to_string_pretty(json)?,
    )?;
    let channels = vec![
        AnyChannel::new("Y", FlatSamples::F32(maps.misregistration.clone())),
        AnyChannel::new(
            "missing.mask",
            FlatSamples::F32(maps.missing.iter().map(|&m| m as u8 as f32).collect()),
        ),
    ];
    write_exr_channels(
        &dir.join("misregistration.exr"),
        maps.width,
        maps.height,
        channels,
    )?;
    let (w, h, rgb) = heatmap_rgb(maps, truth)?;
    write_png(&dir.join("misregistration.png"), w, h, rgb)?;
    write_mask_png(&dir.join("missing.png"), maps, &maps.missing)
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
