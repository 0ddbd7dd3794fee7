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

/// An 8-bit sRGB code in linear light: [`srgb_to_linear`] of `code / 255`, bit for bit, from a
/// table of the 256 codes made once, not a `powf` per channel (a texture's texels, a display
/// image's pixels).
pub fn decode_srgb8(code: u8) -> f32 {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|code| srgb_to_linear(code as f32 / 255.0)))
        [usize::from(code)]
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
/// both clamp), by table: a channel's code is the count of the 255 code thresholds (the
/// smallest linear value that the transfer function encodes to each code 1…255, found once by
/// bisection over the f32 values) at or below it, read from a second table indexed by the
/// value's top 16 bits and one comparison — a bucket of 2^16 f32 values holds one threshold at
/// most, the codes being ≥ 1/255 apart in sRGB — instead of a `powf`.
pub fn encode_srgb8(c: Vec3) -> [u8; 3] {
    let table = Srgb8Table::get();
    [table.code(c.x), table.code(c.y), table.code(c.z)]
}

/// [`encode_srgb8`]'s tables.
struct Srgb8Table {
    /// The thresholds of codes 1…255, then +∞ (no code 256).
    thresholds: [f32; 256],
    /// For each bucket of 2^16 bit patterns in [0, 1]: the count of thresholds at or below its
    /// first value.
    starts: Vec<u8>,
}

impl Srgb8Table {
    fn get() -> &'static Srgb8Table {
        static TABLE: std::sync::OnceLock<Srgb8Table> = std::sync::OnceLock::new();
        TABLE.get_or_init(|| {
            let code = |v: f32| encode_srgb8_by_transfer(Vec3::splat(v))[0];
            let mut thresholds = [f32::INFINITY; 256];
            for (k, t) in thresholds[..255].iter_mut().enumerate() {
                // Smallest v in (0, 1] with code(v) > k, bisected on the bit patterns
                // (positive floats order as their bits).
                let (mut lo, mut hi) = (0u32, 1f32.to_bits());
                while hi - lo > 1 {
                    let m = lo + (hi - lo) / 2;
                    if usize::from(code(f32::from_bits(m))) > k {
                        hi = m;
                    } else {
                        lo = m;
                    }
                }
                *t = f32::from_bits(hi);
            }
            let starts = (0..=1f32.to_bits() >> 16)
                .map(|b| thresholds.partition_point(|&x| x <= f32::from_bits(b << 16)) as u8)
                .collect();
            Srgb8Table { thresholds, starts }
        })
    }

    fn code(&self, v: f32) -> u8 {
        let bits = v.to_bits();
        // v ≥ 1 (to +∞): 255; NaN and every v ≤ 0 (the negatives' bits being above +∞'s,
        // and +0's 0): code 0, as the thresholds are all above 0.
        if bits >= 1f32.to_bits() {
            return if bits <= f32::INFINITY.to_bits() {
                255
            } else {
                0
            };
        }
        let start = usize::from(self.starts[(bits >> 16) as usize]);
        (start + usize::from(self.thresholds[start] <= v)) as u8
    }
}

/// The luminance Y of linear Rec. 709 / sRGB primaries (ITU-R BT.709): what "cd/m²" means of
/// an RGB radiance, and the weight of a code's channels where the head detector compares
/// brightness.
pub fn luminance(rgb: Vec3) -> f32 {
    0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z
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
        // Every 8-bit value survives decoding and re-encoding; the table decodes as the
        // function does.
        for v in 0..=255u8 {
            let linear = srgb_to_linear(v as f32 / 255.0);
            assert_eq!(encode_srgb8_by_transfer(Vec3::splat(linear)), [v; 3]);
            assert_eq!(decode_srgb8(v).to_bits(), linear.to_bits(), "code {v}");
        }
        assert_eq!(
            encode_srgb8_by_transfer(Vec3::new(-1.0, 2.0, f32::NAN)),
            [0, 255, 0]
        );
    }

    /// Rec. 709's weights: each primary's share of white, white itself 255.
    #[test]
    fn luminance_weighs_the_primaries_as_rec_709() {
        assert_eq!(luminance(Vec3::X), 0.2126);
        assert_eq!(luminance(Vec3::Y), 0.7152);
        assert_eq!(luminance(Vec3::Z), 0.0722);
        assert!((luminance(Vec3::splat(3.0)) - 3.0).abs() < 1e-6);
    }

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
