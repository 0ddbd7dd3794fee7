//! sRGB transfer functions and 8-bit encoding.

use glam::Vec3;

pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

pub fn srgb_to_linear3(c: [f64; 3]) -> Vec3 {
    Vec3::new(
        srgb_to_linear(c[0] as f32),
        srgb_to_linear(c[1] as f32),
        srgb_to_linear(c[2] as f32),
    )
}

/// Linear RGB to 8-bit sRGB, clamped to [0, 1]; NaN becomes 0.
pub fn encode_srgb8(c: Vec3) -> [u8; 3] {
    let q = |v: f32| {
        let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        (linear_to_srgb(v) * 255.0 + 0.5) as u8
    };
    [q(c.x), q(c.y), q(c.z)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transfer_functions_invert_each_other() {
        for i in 0..=100 {
            let c = i as f32 / 100.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5);
        }
        // Every 8-bit value survives decoding and re-encoding.
        for v in 0..=255u8 {
            let linear = srgb_to_linear(v as f32 / 255.0);
            assert_eq!(encode_srgb8(Vec3::splat(linear)), [v; 3]);
        }
        assert_eq!(encode_srgb8(Vec3::new(-1.0, 2.0, f32::NAN)), [0, 255, 0]);
    }
}
