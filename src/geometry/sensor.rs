//! A camera as a sensor after EMVA 1288 (release 4.0, the linear model): the radiance a pixel
//! sees becomes photo-electrons through the lens's f-number, the pixel's area, the exposure
//! time and the quantum efficiency; shot noise (Poisson), dark current and read noise are
//! added; the charge is clipped at the full well and quantised by an ADC of `adc_bits` bits
//! with the system gain K. The camera delivers the codes back in linear light, the scene's
//! white at 1.0 (what a camera's image is everywhere else in seethru), after subtracting the
//! mean dark signal (a black-level correction).
//!
//! The lens follows the camera equation for a distant object on the axis: the sensor's
//! illuminance is π L / (4 N²) for a radiance L (transmittance 1, the cos⁴ fall-off left out).
//! Light is counted as photons of 555 nm: 1 lx·s on 1 µm² is [`PHOTONS_PER_LUX_S_UM2`].

use crate::util::sampling::{hash_u32, unit_float};

/// Photons of 555 nm in 1 lx·s on 1 µm²: (1/683 W/m²) / (h c / 555 nm) × 10⁻¹².
pub const PHOTONS_PER_LUX_S_UM2: f64 = 4091.0;

/// The sensor of a frontal or back camera (`sensor = "emva"`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    /// The lens's f-number N, [0.5, 64].
    pub f_number: f64,
    /// Pixel pitch, µm, [0.1, 100] (the pixel's area is its square).
    pub pixel_um: f64,
    /// Quantum efficiency η, electrons per photon, (0, 1].
    pub quantum_efficiency: f64,
    /// Full-well capacity, electrons, [1, 1e7].
    pub full_well_e: f64,
    /// Read (temporal dark) noise σ_d, electrons rms, [0, 1e4].
    pub read_noise_e: f64,
    /// Dark current, electrons per second, [0, 1e7].
    pub dark_current_e_s: f64,
    /// Bits of the ADC, [1, 16].
    pub adc_bits: u32,
    /// System gain K, codes (DN) per electron, (0, 1e4]: default the full well at the top
    /// code.
    pub gain_dn_per_e: f64,
    /// Seed of the noise: the same seed, the same noise in every pixel.
    pub noise_seed: u32,
    /// Exposure time, s, > 0 (the camera's `exposure_ms`).
    pub exposure_s: f64,
    /// The luminance of a linear 1.0 the sensor is given, cd/m² (the scene's white).
    pub white_cd_m2: f64,
}

impl Sensor {
    /// Mean photo-electrons of a pixel that sees the radiance `l_cd_m2` (one channel's, in
    /// cd/m²): η · A · t · π L / (4 N²) · [`PHOTONS_PER_LUX_S_UM2`].
    pub fn mean_electrons(&self, l_cd_m2: f64) -> f64 {
        let illuminance_lux =
            std::f64::consts::PI * l_cd_m2 / (4.0 * self.f_number * self.f_number);
        let area_um2 = self.pixel_um * self.pixel_um;
        self.quantum_efficiency
            * illuminance_lux
            * self.exposure_s
            * area_um2
            * PHOTONS_PER_LUX_S_UM2
    }

    /// Mean dark electrons of a pixel over the exposure.
    pub fn dark_electrons(&self) -> f64 {
        self.dark_current_e_s * self.exposure_s
    }

    /// The largest code.
    pub fn max_dn(&self) -> f64 {
        f64::from((1u32 << self.adc_bits) - 1)
    }

    /// The code of one channel of one pixel that sees `value` (a linear image value: 1.0 is
    /// the white), with its noise drawn from (`pixel`, `channel`) of the seeded stream.
    pub fn dn(&self, value: f32, pixel: u32, channel: u32) -> f64 {
        let signal = self.mean_electrons(f64::from(value.max(0.0)) * self.white_cd_m2);
        let mean = signal + self.dark_electrons();
        let mut draws = Draws {
            key: hash_u32(self.noise_seed ^ hash_u32(pixel.wrapping_mul(3).wrapping_add(channel))),
            n: 0,
        };
        let electrons = poisson(mean, &mut draws) + self.read_noise_e * draws.normal();
        let charge = electrons.clamp(0.0, self.full_well_e);
        (self.gain_dn_per_e * charge)
            .round()
            .clamp(0.0, self.max_dn())
    }

    /// What the camera delivers for a code: back in linear light, the mean dark signal
    /// subtracted, the white at 1.0.
    pub fn delivered(&self, dn: f64) -> f32 {
        let white = self.gain_dn_per_e * self.mean_electrons(self.white_cd_m2);
        ((dn - self.gain_dn_per_e * self.dark_electrons()) / white) as f32
    }
}

/// A stream of uniform numbers in (0, 1) from a key: the n-th is a hash of (key, n).
struct Draws {
    key: u32,
    n: u32,
}

impl Draws {
    fn uniform(&mut self) -> f64 {
        self.n += 1;
        // In (0, 1): never 0, so that logarithms stay finite.
        (f64::from(unit_float(hash_u32(self.key ^ hash_u32(self.n)))) + 0.5 / 16_777_216.0)
            .min(1.0 - 1e-9)
    }

    /// A standard normal (Box–Muller).
    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A Poisson draw of mean `mean`: exact (Knuth's product of uniforms) below 30, a rounded
/// normal of the same mean and variance above (its skew, 1/√mean, is then below 0.2).
fn poisson(mean: f64, draws: &mut Draws) -> f64 {
    if mean <= 0.0 {
        return 0.0;
    }
    if mean < 30.0 {
        let limit = (-mean).exp();
        let (mut k, mut product) = (0.0, draws.uniform());
        while product > limit {
            k += 1.0;
            product *= draws.uniform();
        }
        return k;
    }
    (mean + mean.sqrt() * draws.normal()).round().max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sensor() -> Sensor {
        Sensor {
            f_number: 2.0,
            pixel_um: 3.0,
            quantum_efficiency: 0.6,
            full_well_e: 20_000.0,
            read_noise_e: 4.0,
            dark_current_e_s: 50.0,
            adc_bits: 12,
            gain_dn_per_e: 4095.0 / 20_000.0,
            noise_seed: 7,
            exposure_s: 0.001,
            white_cd_m2: 1000.0,
        }
    }

    #[test]
    fn poisson_draws_have_the_mean_and_the_variance_of_their_mean() {
        // Below and above the switch to the normal.
        for mean in [0.3, 4.0, 29.0, 31.0, 500.0] {
            let n = 200_000;
            let values: Vec<f64> = (0..n)
                .map(|i| {
                    poisson(
                        mean,
                        &mut Draws {
                            key: hash_u32(i),
                            n: 0,
                        },
                    )
                })
                .collect();
            let m = values.iter().sum::<f64>() / n as f64;
            let var = values.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1) as f64;
            assert!(
                (m - mean).abs() < 4.0 * (mean / n as f64).sqrt() + 0.01 * mean,
                "{mean}: {m}"
            );
            assert!((var / mean - 1.0).abs() < 0.02, "{mean}: variance {var}");
        }
    }

    #[test]
    fn the_mean_code_follows_the_exposure_equation_and_the_full_well_clips() {
        let s = sensor();
        // 0.5 of the white: 500 cd/m² → π·500/16 lx · 1 ms · 9 µm² · 4091 · 0.6 (2 169 e⁻).
        let electrons = std::f64::consts::PI * 500.0 / 16.0 * 0.001 * 9.0 * 4091.0 * 0.6;
        assert!((s.mean_electrons(500.0) - electrons).abs() < 1e-9 * electrons);
        let n = 50_000;
        let mean_dn = (0..n).map(|i| s.dn(0.5, i, 0)).sum::<f64>() / f64::from(n);
        let expected = s.gain_dn_per_e * (electrons + s.dark_electrons());
        assert!(
            (mean_dn - expected).abs() < 0.01 * expected,
            "{mean_dn} vs {expected}"
        );
        // Delivered back in linear light: 0.5 on average.
        let delivered = (0..n)
            .map(|i| f64::from(s.delivered(s.dn(0.5, i, 1))))
            .sum::<f64>()
            / f64::from(n);
        assert!((delivered - 0.5).abs() < 0.005, "{delivered}");
        // Far above the full well: the top code at K · full well, every time.
        assert!((0..100).all(|i| s.dn(1e4, i, 2) == (s.gain_dn_per_e * s.full_well_e).round()));
    }
}
