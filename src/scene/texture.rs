//! Image textures: linear RGB texels, bilinear lookup, repeating.

use std::path::Path;

use anyhow::{Context, Result};
use glam::{Vec2, Vec3};

use crate::scene::limits::{MAX_PIXELS, MAX_RESOLUTION};
use crate::util::color::srgb_to_linear;

#[derive(Clone, Debug)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    /// Row-major, row 0 at the top, linear RGB.
    pub texels: Vec<Vec3>,
}

impl Texture {
    /// Loads an sRGB PNG of at most [`MAX_RESOLUTION`] pixels per side.
    pub fn load(path: &Path) -> Result<Texture> {
        let decode = || -> Result<image::DynamicImage> {
            let mut reader = image::ImageReader::open(path)?.with_guessed_format()?;
            let mut limits = image::Limits::default();
            limits.max_image_width = Some(MAX_RESOLUTION);
            limits.max_image_height = Some(MAX_RESOLUTION);
            limits.max_alloc = Some(4 * MAX_PIXELS);
            reader.limits(limits);
            Ok(reader.decode()?)
        };
        let img = decode()
            .with_context(|| format!("cannot load texture {}", path.display()))?
            .to_rgb8();
        Ok(Texture {
            width: img.width(),
            height: img.height(),
            texels: img
                .pixels()
                .map(|p| {
                    Vec3::new(
                        srgb_to_linear(p[0] as f32 / 255.0),
                        srgb_to_linear(p[1] as f32 / 255.0),
                        srgb_to_linear(p[2] as f32 / 255.0),
                    )
                })
                .collect(),
        })
    }

    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.rem_euclid(self.height as i64) as usize;
        self.texels[y * self.width as usize + x]
    }

    /// Bilinear lookup at `uv` (u right, v down, repeating with period 1).
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        if !x.is_finite() || !y.is_finite() {
            return self.texels[0];
        }
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }
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
    }
}
