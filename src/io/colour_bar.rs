//! An image beside a labelled colour bar: every heatmap seethru writes says what its colours
//! mean (the scale's ends, its unit, how it was chosen) and what the special colours are.

use anyhow::Result;

use crate::io::plot::register_font;

/// The scale of a heatmap: colour `colours(t)` for t in [0, 1] stands for
/// `bottom + t (top − bottom)`.
pub struct ColourBar {
    pub colours: fn(f32) -> [u8; 3],
    pub bottom: f64,
    pub top: f64,
    /// Appended to each number on the bar (`′` for arc-minutes, empty for FLIP).
    pub unit: &'static str,
    /// One line above the bar: what the values are and how the scale was chosen.
    pub title: String,
    /// Colours that are not on the scale (blank pixels, no value), with their meaning.
    pub legend: Vec<([u8; 3], String)>,
    /// Whether values above `top` were clipped to it (the top label then reads `≥`).
    pub clipped: bool,
}

/// Width of the bar's column beside the image, pixels.
pub const BAR_COLUMN: u32 = 170;

/// `rgb` (`width`×`height`, 8-bit RGB) with `bar` to its right: the result's size and pixels.
pub fn with_colour_bar(
    width: u32,
    height: u32,
    rgb: &[u8],
    bar: &ColourBar,
) -> Result<(u32, u32, Vec<u8>)> {
    use plotters::prelude::*;
    if rgb.len() != width as usize * height as usize * 3 {
        anyhow::bail!(
            "a heatmap of {width}×{height} pixels was given {} bytes",
            rgb.len()
        );
    }
    let legend_h = 16 * bar.legend.len() as u32;
    let (cw, ch) = (width + BAR_COLUMN, height.max(130 + legend_h));
    let mut buffer = vec![255u8; (cw * ch * 3) as usize];
    for y in 0..height as usize {
        let from = y * width as usize * 3;
        let to = y * cw as usize * 3;
        buffer[to..to + width as usize * 3].copy_from_slice(&rgb[from..from + width as usize * 3]);
    }
    {
        register_font()?;
        let err = |e: DrawingAreaErrorKind<_>| anyhow::anyhow!("{e}");
        let root = BitMapBackend::with_buffer(&mut buffer, (cw, ch)).into_drawing_area();
        let (x0, y0) = (width as i32 + 20, 30i32);
        let bar_h = ch as i32 - 55 - legend_h as i32;
        for k in 0..bar_h {
            let c = (bar.colours)(1.0 - k as f32 / bar_h as f32);
            root.draw(&Rectangle::new(
                [(x0, y0 + k), (x0 + 22, y0 + k + 1)],
                RGBColor(c[0], c[1], c[2]).filled(),
            ))
            .map_err(err)?;
        }
        let style = ("sans-serif", 14).into_font().color(&BLACK);
        let label = |v: f64| {
            let digits = if (bar.top - bar.bottom).abs() < 1.0 {
                3
            } else {
                1
            };
            format!("{v:.digits$}{}", bar.unit)
        };
        let top = if bar.clipped {
            format!("≥ {}", label(bar.top))
        } else {
            label(bar.top)
        };
        for (frac, text) in [
            (0.0, top),
            (0.5, label((bar.top + bar.bottom) / 2.0)),
            (1.0, label(bar.bottom)),
        ] {
            root.draw(&Text::new(
                text,
                (x0 + 28, y0 + (frac * bar_h as f64) as i32 - 7),
                style.clone(),
            ))
            .map_err(err)?;
        }
        root.draw(&Text::new(bar.title.clone(), (x0 - 14, 8), style.clone()))
            .map_err(err)?;
        for (k, (c, text)) in bar.legend.iter().enumerate() {
            let y = ch as i32 - 16 * (bar.legend.len() - k) as i32;
            root.draw(&Rectangle::new(
                [(x0, y), (x0 + 22, y + 12)],
                RGBColor(c[0], c[1], c[2]).filled(),
            ))
            .map_err(err)?;
            root.draw(&Text::new(text.clone(), (x0 + 28, y - 2), style.clone()))
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    Ok((cw, ch, buffer))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bar_runs_from_the_top_colour_down_to_the_bottom_colour() {
        let bar = ColourBar {
            colours: |t| [(t * 255.0) as u8, 0, 0],
            bottom: 0.0,
            top: 1.0,
            unit: "",
            title: "t".into(),
            legend: vec![([0, 255, 0], "none".into())],
            clipped: false,
        };
        let (w, h, rgb) = with_colour_bar(10, 200, &[7u8; 10 * 200 * 3], &bar).unwrap();
        assert_eq!(w, 10 + BAR_COLUMN);
        let at = |x: u32, y: u32| {
            let o = ((y * w + x) * 3) as usize;
            [rgb[o], rgb[o + 1], rgb[o + 2]]
        };
        // The image is kept as it was; the bar's first row is the top colour, its last the
        // bottom's.
        assert_eq!(at(3, 100), [7, 7, 7]);
        let bar_x = 10 + 20 + 5;
        assert_eq!(at(bar_x, 30), [255, 0, 0]);
        let last = 30 + (h as i32 - 55 - 16) as u32 - 1;
        assert!(at(bar_x, last)[0] < 5, "{:?}", at(bar_x, last));
    }
}
