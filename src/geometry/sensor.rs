//! A camera as a sensor after EMVA 1288 (release 4.0, the linear model): the radiance a pixel
//! sees becomes photo-electrons through the lens's f-number, the pixel's area, the exposure
//! time and the quantum efficiency; shot noise (Poisson), dark current and read noise are
//! added; the charge is clipped at the full well and quantised by an ADC of `adc_bits` bits
//! with the system gain K. The camera delivers the codes back in linear light, the scene's
//! white at 1.0 (what a camera's image is everywhere else in seethru), after subtracting the
//! mean dark signal (a black-level correction).
//!
//! A camera with a tone curve ([`Coding`]) delivers what a real camera's output is: its
//! signal as a share of the ADC's full scale, through the curve (sRGB, BT.709, a 2.2 gamma or
//! linear), quantised to 8, 10 or 12 bits. seethru keeps that image in linear light, each
//! code decoded by the same curve and scaled back to the scene's white ([`Sensor::delivered`]),
//! so that every consumer reads it as any other camera image; the codes themselves are
//! [`Exposure::code`] of it, exactly. Automatic exposure ([`AutoExposure`]) sets the gain
//! that puts the metered signal at its target: the camera's codes, and so a display's light,
//! then follow the world's brightness no longer.
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
    /// Exposure time, s, > 0 (the camera's `exposure_ms`; with an automatic exposure, set
    /// for each frame by its metering, at most that).
    pub exposure_s: f64,
    /// The luminance of a linear 1.0 the sensor is given, cd/m² (the scene's white).
    pub white_cd_m2: f64,
    /// The tone curve and the bits of the delivered codes; `None`: linear light, unquantised
    /// beyond the ADC (`tone_curve = "none"`).
    pub coding: Option<Coding>,
    /// Automatic exposure; `None`: manual (the gain is K).
    pub auto_exposure: Option<AutoExposure>,
    /// The gain applied on top of K, [1, the automatic exposure's `max_gain`]: 1 for a manual
    /// exposure; for an automatic one, set with the exposure time for each frame by its
    /// metering (render/exposure.rs), `None` until then.
    pub exposure_gain: Option<f64>,
}

/// The camera's output curve: what it applies to its linear signal before quantising.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToneCurve {
    /// The codes linear in the signal.
    Linear,
    /// IEC 61966-2-1's sRGB curve.
    Srgb,
    /// ITU-R BT.709's (and BT.2020's) camera curve.
    Bt709,
    /// A pure power of 1/2.2.
    Gamma22,
}

impl ToneCurve {
    /// The scene-file names, in the order of [`ToneCurve::ALL`].
    pub const NAMES: [&'static str; 4] = ["linear", "srgb", "bt709", "gamma2.2"];
    pub const ALL: [ToneCurve; 4] = [
        ToneCurve::Linear,
        ToneCurve::Srgb,
        ToneCurve::Bt709,
        ToneCurve::Gamma22,
    ];

    pub fn from_name(name: &str) -> Option<ToneCurve> {
        let i = Self::NAMES.iter().position(|n| *n == name)?;
        Some(Self::ALL[i])
    }

    pub fn name(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|c| *c == self).expect("listed")]
    }

    /// The curve: a signal in [0, 1] (a share of full scale) to a code in [0, 1].
    pub fn encode(self, x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        match self {
            ToneCurve::Linear => x,
            ToneCurve::Srgb if x <= 0.003_130_8 => 12.92 * x,
            ToneCurve::Srgb => 1.055 * x.powf(1.0 / 2.4) - 0.055,
            ToneCurve::Bt709 if x < 0.018 => 4.5 * x,
            ToneCurve::Bt709 => 1.099 * x.powf(0.45) - 0.099,
            ToneCurve::Gamma22 => x.powf(1.0 / 2.2),
        }
    }

    /// Its inverse: a code in [0, 1] back to the signal.
    pub fn decode(self, code: f64) -> f64 {
        let v = code.clamp(0.0, 1.0);
        match self {
            ToneCurve::Linear => v,
            ToneCurve::Srgb if v <= 0.040_45 => v / 12.92,
            ToneCurve::Srgb => ((v + 0.055) / 1.055).powf(2.4),
            ToneCurve::Bt709 if v < 0.081 => v / 4.5,
            ToneCurve::Bt709 => ((v + 0.099) / 1.099).powf(1.0 / 0.45),
            ToneCurve::Gamma22 => v.powf(2.2),
        }
    }
}

/// How a camera codes its delivered image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Coding {
    pub curve: ToneCurve,
    /// Bits of a delivered code: 8, 10 or 12.
    pub bits: u32,
}

impl Coding {
    /// The top code, 2^bits − 1.
    pub fn top(self) -> f64 {
        f64::from((1u32 << self.bits) - 1)
    }
}

/// How the automatic exposure meters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Metering {
    /// Every zone alike.
    Average,
    /// Zones weighted by a Gaussian about the image's centre, σ a quarter of the width.
    Center,
}

/// Automatic exposure: it sets the exposure time (up to the shutter's, which sets the motion
/// blur) and then the gain, as an automotive camera does within its time limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AutoExposure {
    pub metering: Metering,
    /// The shortest exposure time, s, (0, max_exposure_s].
    pub min_exposure_s: f64,
    /// The longest exposure time, s: the shutter's `exposure_ms`.
    pub max_exposure_s: f64,
    /// The metered mean signal it aims at, as a share of the ADC's full scale, (0, 1).
    pub target: f64,
    /// Most gain on top of K, [1, 1e4]; the least is 1.
    pub max_gain: f64,
    /// How fast a sequence's exposure follows, stops per second, (0, 1e3]; a single frame's
    /// is the settled one.
    pub adaptation_ev_s: f64,
}

/// What a frame from a camera with a sensor records of its exposure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exposure {
    /// The exposure time, s.
    pub exposure_s: f64,
    /// The gain on top of K the frame was taken with, ≥ 1.
    pub gain: f64,
    /// The metered mean signal at that gain, as a share of the ADC's full scale, [0, 1]
    /// (`None`: a manual exposure, which meters nothing).
    pub metered: Option<f64>,
    /// The automatic exposure's target, as a share of full scale (`None`: manual).
    pub target: Option<f64>,
    /// Whether the automatic exposure wanted a gain beyond [1, max_gain] (so missed its
    /// target).
    pub at_limit: bool,
    /// The tone curve and bits of the codes (`None`: linear light).
    pub coding: Option<Coding>,
    /// The linear value (units of the scene's white) at the ADC's full scale.
    pub full_scale: f64,
}

impl Exposure {
    /// The code in [0, 1] (code / top code) of a delivered linear value, exact for what
    /// a coded camera delivers; for a camera in linear light, the value clamped to [0, 1].
    pub fn code(&self, value: f32) -> f32 {
        match self.coding {
            None => value.clamp(0.0, 1.0),
            Some(c) => {
                let code = (c.curve.encode(f64::from(value) / self.full_scale) * c.top()).round();
                (code / c.top()) as f32
            }
        }
    }
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
        (self.gain() * charge).round().clamp(0.0, self.max_dn())
    }

    /// A manual exposure's gain set (1); an automatic one's left to its metering.
    pub fn with_manual_gain(self) -> Sensor {
        Sensor {
            exposure_gain: self.auto_exposure.is_none().then_some(1.0),
            ..self
        }
    }

    /// The system gain the frame is taken with: K times the exposure's gain, DN per
    /// electron.
    pub fn gain(&self) -> f64 {
        self.gain_dn_per_e * self.exposure_gain.unwrap_or(1.0)
    }

    /// The linear value (units of the scene's white) whose signal fills the ADC.
    pub fn full_scale(&self) -> f64 {
        self.max_dn() / (self.gain() * self.mean_electrons(self.white_cd_m2))
    }

    /// What the camera delivers for a code: back in linear light, the mean dark signal
    /// subtracted, the white at 1.0. With a tone curve, the signal's share of full scale
    /// through the curve, quantised to the coding's bits, and decoded back.
    pub fn delivered(&self, dn: f64) -> f32 {
        let white = self.gain() * self.mean_electrons(self.white_cd_m2);
        let signal = dn - self.gain() * self.dark_electrons();
        match self.coding {
            None => (signal / white) as f32,
            Some(c) => {
                let code = (c.curve.encode(signal / self.max_dn()) * c.top()).round();
                (c.curve.decode(code / c.top()) * self.max_dn() / white) as f32
            }
        }
    }

    /// What a frame taken with this sensor records of its exposure (`metered` and
    /// `at_limit` from the automatic exposure's metering).
    pub fn exposure(&self, metered: Option<f64>, at_limit: bool) -> Exposure {
        Exposure {
            exposure_s: self.exposure_s,
            gain: self.exposure_gain.unwrap_or(1.0),
            metered,
            target: self.auto_exposure.map(|a| a.target),
            at_limit,
            coding: self.coding,
            full_scale: self.full_scale(),
        }
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
pub(crate) mod tests {
    use super::*;

    /// A sensor of a 12-bit ADC, 20 000 e⁻ well and 1 ms exposure, manual, linear light.
    pub(crate) fn sensor() -> Sensor {
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
            coding: None,
            auto_exposure: None,
            exposure_gain: Some(1.0),
        }
    }

    #[test]
    fn small_poisson_draws_follow_the_probability_mass_function() {
        // Each count's frequency against e^−μ μ^k / k!, within 5 standard errors.
        for mean in [0.3, 4.0, 12.0, 29.0] {
            let n = 200_000u32;
            let mut counts = vec![0u32; 100];
            for i in 0..n {
                let mut draws = Draws {
                    key: hash_u32(i ^ 0x5eed),
                    n: 0,
                };
                counts[poisson(mean, &mut draws) as usize] += 1;
            }
            let mut pmf = f64::exp(-mean);
            for (k, &count) in counts.iter().enumerate().take(60) {
                if k > 0 {
                    pmf *= mean / k as f64;
                }
                let expected = pmf * f64::from(n);
                let error = 5.0 * expected.sqrt() + 1.0;
                assert!(
                    (f64::from(count) - expected).abs() <= error,
                    "mean {mean}, k {k}: {count} vs {expected:.1}"
                );
            }
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
