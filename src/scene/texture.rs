//! Image textures: linear RGB texels, bilinear lookup, repeating; and the same lookup over
//! scalar tables (the sky's clouds).

use std::path::Path;

use anyhow::{Context, Result};
use glam::{Vec2, Vec3};

use crate::scene::limits::{MAX_PIXELS, MAX_RESOLUTION};
use crate::util::color::decode_srgb8;

/// A repeating grid of texels with bilinear lookup.
#[derive(Clone, Debug)]
pub struct Texels<T> {
    /// Texels per row, in [1, MAX_RESOLUTION].
    pub width: u32,
    /// Rows, in [1, MAX_RESOLUTION].
    pub height: u32,
    /// Row-major, row 0 at the top.
    pub texels: Vec<T>,
}

/// An image texture: linear RGB texels.
pub type Texture = Texels<Vec3>;

/// What a texel can be: a value with linear interpolation.
pub trait Texel: Copy {
    /// `self` at `t` = 0 to `other` at `t` = 1.
    fn lerp(self, other: Self, t: f32) -> Self;
}

impl Texel for Vec3 {
    fn lerp(self, other: Vec3, t: f32) -> Vec3 {
        Vec3::lerp(self, other, t)
    }
}

/// Glam's `Vec3::lerp` on one channel, operation for operation: a scalar table samples to
/// the bits an RGB texture of equal channels gives.
impl Texel for f32 {
    fn lerp(self, other: f32, t: f32) -> f32 {
        self * (1.0 - t) + other * t
    }
}

impl Texture {
    /// Loads an sRGB PNG of at most [`MAX_RESOLUTION`] pixels per side.
    pub fn load(path: &Path) -> Result<Texture> {
        crate::util::input_file::note_input(path);
        let open = || -> Result<_> { Ok(image::ImageReader::open(path)?.with_guessed_format()?) };
        decode_with(open).with_context(|| format!("cannot load texture {}", path.display()))
    }

    /// Decodes an sRGB PNG held in memory (a glTF's embedded image), within the same limits.
    pub fn decode(bytes: &[u8]) -> Result<Texture> {
        if !bytes.starts_with(b"\x89PNG") {
            let start: String = bytes
                .iter()
                .take(4)
                .map(|b| format!("{b:02x}"))
                .collect::<Vec<_>>()
                .join(" ");
            anyhow::bail!(
                "only PNG images are read, and this one starts with the bytes {start}, not a PNG's 89 50 4e 47: convert it to PNG"
            );
        }
        let open = || -> Result<_> {
            Ok(image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format()?)
        };
        decode_with(open)
    }
}

/// Decodes the image `open` gives (twice: the size is checked before the pixels are read)
/// into linear texels.
fn decode_with<R: std::io::BufRead + std::io::Seek>(
    open: impl Fn() -> Result<image::ImageReader<R>>,
) -> Result<Texture> {
    // The image crate's errors repeat their text as their source ("Invalid PNG
    // signature.: Invalid PNG signature."): shown once, as text.
    let text = |e: image::ImageError| anyhow::anyhow!("{e}");
    // The size first: the crate's "Image size exceeds limit" names neither.
    let (width, height) = open()?.into_dimensions().map_err(text)?;
    if width > MAX_RESOLUTION
        || height > MAX_RESOLUTION
        || u64::from(width) * u64::from(height) > MAX_PIXELS
    {
        anyhow::bail!(
            "the image is {width}×{height} px; a texture is at most {MAX_RESOLUTION} px a side and {MAX_RESOLUTION}×{} px in all",
            MAX_PIXELS / u64::from(MAX_RESOLUTION)
        );
    }
    let mut reader = open()?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_RESOLUTION);
    limits.max_image_height = Some(MAX_RESOLUTION);
    limits.max_alloc = Some(4 * MAX_PIXELS);
    reader.limits(limits);
    let img = reader.decode().map_err(text)?.to_rgb8();
    Ok(Texture {
        width: img.width(),
        height: img.height(),
        // By table (das's street: 4–9 ms of its start with a `powf` per channel, then 1.5–3).
        texels: img
            .pixels()
            .map(|p| Vec3::from(p.0.map(decode_srgb8)))
            .collect(),
    })
}

impl<T: Texel> Texels<T> {
    /// Bilinear lookup at `uv` (u right, v down, repeating with period 1).
    pub fn sample(&self, uv: Vec2) -> T {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        if !x.is_finite() || !y.is_finite() {
            return self.texels[0];
        }
        let (x0, y0) = (floor(x), floor(y));
        let (fx, fy) = (x - x0, y - y0);
        // The two columns and rows, wrapped once each (integer division is slow).
        let wrap = |v: f32, n: u32| {
            let a = (v as i64).rem_euclid(n as i64) as usize;
            (a, if a + 1 == n as usize { 0 } else { a + 1 })
        };
        let ((c0, c1), (r0, r1)) = (wrap(x0, self.width), wrap(y0, self.height));
        let row = self.width as usize;
        let texel = |c: usize, r: usize| self.texels[r * row + c];
        let top = texel(c0, r0).lerp(texel(c1, r0), fx);
        let bottom = texel(c0, r1).lerp(texel(c1, r1), fx);
        top.lerp(bottom, fy)
    }
}

/// `f32::floor` without a libm call (the x86-64 baseline has no rounding instruction);
/// beyond 2^23 every float is an integer already.
fn floor(x: f32) -> f32 {
    if x.abs() >= 8_388_608.0 {
        return x;
    }
    let t = x as i32 as f32;
    if t > x { t - 1.0 } else { t }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_lookup_interpolates_and_repeats() {
        let t = Texture {
            width: 2,
            height: 1,
            texels: vec![Vec3::ZERO, Vec3::ONE],
        };
        assert_eq!(t.sample(Vec2::new(0.25, 0.5)), Vec3::ZERO);
        assert_eq!(t.sample(Vec2::new(0.75, 0.5)), Vec3::ONE);
        assert!(
            t.sample(Vec2::new(0.5, 0.5))
                .abs_diff_eq(Vec3::splat(0.5), 1e-6)
        );
        assert!(t.sample(Vec2::new(1.75, 3.5)).abs_diff_eq(Vec3::ONE, 1e-6));
        // Texel centres one period on and back, where the column wraps to the first exactly.
        for u in [1.25, -0.75, 100.25, -99.75] {
            assert_eq!(t.sample(Vec2::new(u, 0.5)), Vec3::ZERO, "u = {u}");
            assert_eq!(
                t.sample(Vec2::new(u + 0.5, 0.5)),
                Vec3::ONE,
                "u = {u} + 0.5"
            );
        }
    }

    /// The sky's scalar cloud table must sample to the bits the RGB texture it replaced gave.
    #[test]
    fn scalar_table_samples_as_its_rgb_twin() {
        let (width, height) = (7, 5);
        let values: Vec<f32> = (0..width * height)
            .map(|i| ((i * 37 % 23) as f32 / 23.0).powf(1.7))
            .collect();
        let scalar = Texels {
            width,
            height,
            texels: values.clone(),
        };
        let rgb = Texture {
            width,
            height,
            texels: values.iter().map(|&v| Vec3::splat(v)).collect(),
        };
        let mut between = 0;
        for i in 0..2000 {
            let uv = Vec2::new(
                (i as f32 * 0.618_034).fract() * 9.0 - 4.0,
                (i as f32 * 0.414_213_6).fract() * 300.0 - 150.0,
            );
            let s = scalar.sample(uv);
            assert_eq!(s.to_bits(), rgb.sample(uv).x.to_bits(), "uv {uv}");
            between += usize::from(!values.contains(&s));
        }
        assert!(between > 1900, "only {between} lookups fell between texels");
    }

    /// A loaded texture's texels are the transfer function of each channel's code, bit for
    /// bit, whatever table the loader decodes through: every code in every channel, in an
    /// order that a table indexed by the wrong channel or off by one would not reproduce.
    #[test]
    fn loaded_texels_are_the_transfer_function_of_every_code() {
        use crate::util::color::srgb_to_linear;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("codes.png");
        let codes = |i: u32| [i as u8, (255 - i) as u8, (i * 7 % 256) as u8];
        let image = image::RgbImage::from_fn(256, 1, |x, _| image::Rgb(codes(x)));
        image.save(&path).unwrap();
        let texture = Texture::load(&path).unwrap();
        assert_eq!((texture.width, texture.height), (256, 1));
        for (x, texel) in texture.texels.iter().enumerate() {
            for (channel, code) in codes(x as u32).into_iter().enumerate() {
                let direct = srgb_to_linear(code as f32 / 255.0);
                assert_eq!(
                    texel[channel].to_bits(),
                    direct.to_bits(),
                    "code {code} in channel {channel} of texel {x}"
                );
            }
        }
    }
}
