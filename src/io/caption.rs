//! Captions on images: lines of text in the bundled font on a white strip, for images that
//! need to say what they show (a sequence preview's time, latency and misregistration).

use anyhow::{Result, anyhow};
use plotters::prelude::*;

use crate::io::plot::register_font;

/// Text height, pixels.
const FONT_PX: f64 = 14.0;
/// Height of one line of the strip, pixels.
const LINE_PX: u32 = 18;

/// The lines a caption of `parts` takes in `width` pixels: all parts on one line, joined by
/// wide spaces, where that fits; else one part per line.
pub fn caption_lines(parts: &[String], width: u32) -> Result<Vec<String>> {
    register_font()?;
    let one = parts.join("   ");
    let mut probe = [0u8; 3];
    let area = BitMapBackend::with_buffer(&mut probe, (1, 1)).into_drawing_area();
    let (w, _) = area
        .estimate_text_size(&one, &("sans-serif", FONT_PX).into_font().into())
        .map_err(|e| anyhow!("{e}"))?;
    Ok(if w + 8 <= width {
        vec![one]
    } else {
        parts.to_vec()
    })
}

/// Height of a strip holding `lines` lines, pixels.
pub fn strip_height(lines: usize) -> u32 {
    lines as u32 * LINE_PX + 4
}

/// A white RGB8 strip `width` wide, [`strip_height`] high, with `lines` in black from the left.
pub fn caption_strip(lines: &[String], width: u32) -> Result<Vec<u8>> {
    register_font()?;
    let height = strip_height(lines.len());
    let mut rgb = vec![255u8; (width * height * 3) as usize];
    {
        let area = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        let style = ("sans-serif", FONT_PX).into_font().color(&BLACK);
        for (k, line) in lines.iter().enumerate() {
            area.draw_text(line, &style, (4, 3 + (k as u32 * LINE_PX) as i32))
                .map_err(|e| anyhow!("{e}"))?;
        }
        area.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_caption_is_drawn_and_wraps_to_one_part_per_line_when_narrow() {
        let parts = vec!["t = 0.30 s".to_string(), "latency 100 ms".to_string()];
        assert_eq!(caption_lines(&parts, 900).unwrap().len(), 1);
        assert_eq!(caption_lines(&parts, 60).unwrap(), parts);
        let strip = caption_strip(&parts, 120).unwrap();
        assert_eq!(strip.len(), (120 * strip_height(2) * 3) as usize);
        let dark = strip.chunks(3).filter(|p| p[0] < 128).count();
        // Text, not a blank strip nor a filled one.
        assert!(dark > 20 && dark < strip.len() / 3 / 2, "{dark}");
        // Different text draws differently.
        assert_ne!(
            strip,
            caption_strip(&["t = 0.40 s".into(), parts[1].clone()], 120).unwrap()
        );
    }
}
