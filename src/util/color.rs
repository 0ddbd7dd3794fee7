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

/// Linear RGB to 8-bit sRGB by the transfer function, clamped to [0, 1]; NaN becomes 0: the
/// definition of [`encode_srgb8`], and its twin in tests (a `powf` per channel).
pub fn encode_srgb8_by_transfer(c: Vec3) -> [u8; 3] {
    let q = |v: f32| {
        let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
        (linear_to_srgb(v) * 255.0 + 0.5) as u8
    };
    [q(c.x), q(c.y), q(c.z)]
}

/// Linear RGB to 8-bit sRGB, clamped to [0, 1]; NaN becomes 0 — the codes of
/// [`encode_srgb8_by_transfer`] for every f32 (`tests` compares them all in [0, 1]; beyond it
/// both clamp), by table: each channel is the count of the 255 code thresholds (the smallest
/// linear value that the transfer function encodes to each code 1…255, found once by
/// bisection over the f32 values) at or below it, counted from a second table indexed by the
/// value's top 16 bits — a lookup and a comparison or two instead of a `powf`.
pub fn encode_srgb8(c: Vec3) -> [u8; 3] {
    static THRESHOLDS: std::sync::OnceLock<[f32; 255]> = std::sync::OnceLock::new();
    let t = THRESHOLDS.get_or_init(|| {
        let code = |v: f32| encode_srgb8_by_transfer(Vec3::splat(v))[0];
        std::array::from_fn(|k| {
            // Smallest v in (0, 1] with code(v) > k, bisected on the bit patterns (positive
            // floats order as their bits).
            let (mut lo, mut hi) = (0u32, 1f32.to_bits());
            while hi - lo > 1 {
                let m = lo + (hi - lo) / 2;
                if usize::from(code(f32::from_bits(m))) > k {
                    hi = m;
                } else {
                    lo = m;
                }
            }
            f32::from_bits(hi)
        })
    });
    // The count of thresholds at or below the first f32 of each bucket of 2^16 bit patterns
    // in [0, 1]: where the count for a value in that bucket starts (one or two thresholds
    // further at most, the codes being ≥ 1/255 apart in sRGB).
    static STARTS: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    let starts = STARTS.get_or_init(|| {
        (0..=1f32.to_bits() >> 16)
            .map(|b| t.partition_point(|&x| x <= f32::from_bits(b << 16)) as u8)
            .collect()
    });
    let q = |v: f32| {
        // NaN and v ≤ 0: no threshold is ≤ it, code 0, as encode_srgb8; v ≥ 1: all 255.
        if v.is_nan() || v <= 0.0 {
            return 0;
        }
        if v >= 1.0 {
            return 255;
        }
        let mut code = starts[(v.to_bits() >> 16) as usize] as usize;
        while code < t.len() && t[code] <= v {
            code += 1;
        }
        code as u8
    };
    [q(c.x), q(c.y), q(c.z)]
}

/// Rec. 709 luma of 8-bit sRGB code values, [0, 255]: what SSIM compares.
pub fn luma(c: [u8; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every f32 in [0, 1] (a billion values, seconds in release on two threads), the
    /// values beyond it and the specials.
    #[test]
    fn the_table_encodes_every_value_as_the_transfer_function() {
        use rayon::prelude::*;
        let differ = |v: f32| {
            let c = Vec3::new(v, -v, v * 0.5);
            encode_srgb8(c) != encode_srgb8_by_transfer(c)
        };
        for v in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 2.0, 1e30] {
            assert!(!differ(v), "{v:e}");
        }
        let first = (0..=1f32.to_bits() + 4096)
            .into_par_iter()
            .find_first(|&bits| differ(f32::from_bits(bits)));
        assert_eq!(first.map(f32::from_bits), None);
    }

    #[test]
    fn transfer_functions_invert_each_other() {
        for i in 0..=100 {
            let c = i as f32 / 100.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5);
        }
        // Every 8-bit value survives decoding and re-encoding.
        for v in 0..=255u8 {
            let linear = srgb_to_linear(v as f32 / 255.0);
            assert_eq!(encode_srgb8_by_transfer(Vec3::splat(linear)), [v; 3]);
        }
        assert_eq!(
            encode_srgb8_by_transfer(Vec3::new(-1.0, 2.0, f32::NAN)),
            [0, 255, 0]
        );
    }

    /// Rec. 709's weights: each primary's share of white, white itself 255.
    #[test]
    fn luma_weighs_the_primaries_as_rec_709() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        assert!(close(luma([255, 0, 0]), 0.2126 * 255.0));
        assert!(close(luma([0, 255, 0]), 0.7152 * 255.0));
        assert!(close(luma([0, 0, 255]), 0.0722 * 255.0));
        assert!(close(luma([255, 255, 255]), 255.0));
        assert!(close(
            luma([10, 20, 30]),
            0.2126 * 10.0 + 0.7152 * 20.0 + 0.0722 * 30.0
        ));
    }
}
