//! Animated PNG (APNG) from RGB8 frames, through the `png` crate (the `image` crate decodes
//! APNG but does not encode it; `png` is already the encoder under `image`'s PNG support).
//! Viewers without APNG support show the first frame.

use std::path::Path;

use anyhow::{Result, bail};

use crate::io::atomic::write_atomically;

/// Writes `frames` (each `width × height` RGB8, row-major) as an APNG that loops forever,
/// each frame shown for `1 / fps` seconds.
pub fn write_apng(
    path: &Path,
    width: u32,
    height: u32,
    frames: &[Vec<u8>],
    fps: f64,
) -> Result<()> {
    if frames.is_empty() {
        bail!("an animation needs at least one frame");
    }
    let size = width as usize * height as usize * 3;
    if let Some(i) = frames.iter().position(|f| f.len() != size) {
        bail!(
            "animation frame {i} has {} bytes, expected {size}",
            frames[i].len()
        );
    }
    // The delay as a fraction num/den of a second, den ≤ 65535.
    let den: u16 = 1000;
    let num = ((1000.0 / fps).round() as u16).max(1);
    write_atomically(path, |file| {
        let mut encoder = png::Encoder::new(file, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_animated(frames.len() as u32, 0)?;
        encoder.set_frame_delay(num, den)?;
        let mut writer = encoder.write_header()?;
        for frame in frames {
            writer.write_image_data(frame)?;
        }
        writer.finish()?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_apng_reads_back_frame_by_frame() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let frames: Vec<Vec<u8>> = (0..3u8).map(|k| vec![k * 40; 4 * 2 * 3]).collect();
        write_apng(&path, 4, 2, &frames, 25.0).unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let control = reader.info().animation_control.unwrap();
        assert_eq!(control.num_frames, 3);
        let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
        for k in 0..3u8 {
            reader.next_frame(&mut buffer).unwrap();
            assert!(buffer.iter().all(|&b| b == k * 40));
            assert_eq!(reader.info().frame_control.unwrap().delay_num, 40);
        }
    }
}
