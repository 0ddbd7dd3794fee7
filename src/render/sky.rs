//! The sky: a horizon-to-zenith gradient with procedural clouds and the sun's disc, and the
//! ambient light it casts. Everything here is a pure function of the direction, so it is
//! deterministic and needs no textures.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::scene::texture::Texels;

use crate::scene::{Photometry, Sky, Sun};
use crate::util::color::srgb_to_linear3;
use crate::util::sampling::{hash_u32, unit_float};

/// Sky and sun in linear RGB, ready for shading: in the scene's units (a relative scene's,
/// or a photometric scene's white, [`Photometry::white_cd_m2`]).
#[derive(Clone, Debug)]
pub struct SkyModel {
    zenith: Vec3,
    horizon: Vec3,
    /// Radiance below the horizon, and of the ground that lights surfaces from below.
    ground: Vec3,
    /// The sky's radiance as a floor receives it (its irradiance over π before `ambient`).
    sky_mean: Vec3,
    /// The ambient light's multiplier (1 in a photometric scene).
    ambient: f32,
    /// The clouds' brightness multiplier (1 in a relative scene).
    cloud_scale: f32,
    cloud_cover: f32,
    cloud_height: f32,
    cloud_size: f32,
    /// Cloud noise over one period of the cloud layer, precomputed: evaluating five octaves
    /// of noise per sky pixel cost more than tracing its ray. Values in [0, 1), scalars: an
    /// RGB table of them took three times the cache.
    clouds: Texels<f32>,
    /// Unit direction towards the sun, world frame.
    pub sun_direction: Vec3,
    /// Sun irradiance on a surface facing it over π, linear RGB: a Lambertian surface of
    /// albedo ρ facing the sun has radiance ρ × this.
    pub sun_irradiance: Vec3,
    /// Radiance of the sun's disc.
    sun_disc: Vec3,
}

/// Cosine of the sun disc's angular radius as drawn in the sky (0.5°, twice the real one so
/// that it shows at small resolutions).
const SUN_DISC_COS: f32 = 0.999_962;

impl SkyModel {
    /// The sky and sun of a scene: relative (`photometry` `None`) or in physical units.
    pub fn new(sky: &Sky, sun: &Sun, photometry: Option<&Photometry>) -> Self {
        let (zenith, horizon) = (
            srgb_to_linear3(sky.zenith_color),
            srgb_to_linear3(sky.horizon_color),
        );
        let (sun_colour, ground_colour) = (
            srgb_to_linear3(sun.color),
            srgb_to_linear3(sky.ground_color),
        );
        let sun_direction = sun.direction.as_vec3();
        let common = Self {
            zenith,
            horizon,
            ground: ground_colour,
            sky_mean: horizon.lerp(zenith, 0.5),
            ambient: sky.ambient as f32,
            cloud_scale: 1.0,
            cloud_cover: sky.cloud_cover as f32,
            cloud_height: sky.cloud_height as f32,
            cloud_size: sky.cloud_size as f32,
            clouds: cloud_table(sky.cloud_seed),
            sun_direction,
            sun_irradiance: sun_colour * sun.intensity as f32,
            sun_disc: sun_colour * sun.intensity as f32 * 4.0,
        };
        let Some(p) = photometry else {
            return common;
        };
        // Radiance in units of the white: cd/m² / white_cd_m2.
        let sky_scale = (p.sky_cd_m2_per_unit(sky) / p.white_cd_m2) as f32;
        let sun_scale = (p.sun_lux_per_unit(sun) / p.white_cd_m2) as f32;
        let (zenith, horizon) = (zenith * sky_scale, horizon * sky_scale);
        let sky_mean = Vec3::from_array(std::array::from_fn(|i| {
            Sky::cosine_mean(f64::from(horizon[i]), f64::from(zenith[i])) as f32
        }));
        let sun_irradiance = sun_colour * (sun_scale / std::f32::consts::PI);
        let disc_solid_angle = 2.0 * std::f32::consts::PI * (1.0 - SUN_DISC_COS);
        Self {
            zenith,
            horizon,
            // The ground below the horizon: a Lambertian plane under the sun and the sky.
            ground: ground_colour * (sun_irradiance * sun_direction.y.max(0.0) + sky_mean),
            sky_mean,
            ambient: 1.0,
            cloud_scale: sky_scale,
            sun_irradiance,
            sun_disc: sun_colour * (sun_scale / disc_solid_angle),
            ..common
        }
    }

    fn gradient(&self, dir: Vec3) -> Vec3 {
        if dir.y < 0.0 {
            return self.horizon.lerp(self.ground, (-dir.y * 8.0).min(1.0));
        }
        self.horizon.lerp(self.zenith, dir.y.sqrt())
    }

    /// Cloud density in [0, 1] seen in direction `dir` (upper hemisphere only).
    pub fn cloud_density(&self, dir: Vec3) -> f32 {
        let haze = smoothstep(0.02, 0.18, dir.y);
        if haze == 0.0 || self.cloud_cover <= 0.0 {
            return 0.0;
        }
        // Where the ray meets the cloud layer, in units of cloud size.
        let p = Vec2::new(dir.x, dir.z) * (self.cloud_height / dir.y) / self.cloud_size;
        let n = self.clouds.sample(p / CLOUD_PERIOD as f32);
        let threshold = 0.72 - 0.45 * self.cloud_cover;
        let density = ((n - threshold) / 0.12).clamp(0.0, 1.0);
        // Far clouds dissolve into the haze at the horizon.
        density * haze
    }

    /// Radiance seen along a ray that leaves the scene in direction `dir` (unit).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.radiance_of(dir, true)
    }

    /// [`SkyModel::radiance`] without the sun's disc: what a glossy coat's reflection rays
    /// gather (the coat reflects the sun already, as the delta light it is to the shading).
    pub fn radiance_without_sun(&self, dir: Vec3) -> Vec3 {
        self.radiance_of(dir, false)
    }

    fn radiance_of(&self, dir: Vec3, sun: bool) -> Vec3 {
        let base = self.gradient(dir);
        let cloud = self.cloud_density(dir);
        let cloud_color =
            Vec3::splat(0.9) * (0.55 + 0.45 * self.sun_direction.y.max(0.0)) * self.cloud_scale;
        let mut c = base.lerp(cloud_color, cloud);
        if sun && dir.dot(self.sun_direction) > SUN_DISC_COS && cloud < 0.5 {
            c += self.sun_disc;
        }
        c
    }

    /// Ambient irradiance over π on a surface with unit normal `n`: the sky above, the ground
    /// below (exact for a floor, a ceiling and a uniform sky; the clouds are left out).
    pub fn ambient(&self, n: Vec3) -> Vec3 {
        self.ground.lerp(self.sky_mean, 0.5 + 0.5 * n.y) * self.ambient
    }
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Cloud sizes per period of the cloud table; the pattern repeats every `CLOUD_PERIOD` cloud
/// sizes (kilometres away, where the haze hides it).
const CLOUD_PERIOD: u32 = 8;
/// Texels of the cloud table per side.
const CLOUD_TABLE: u32 = 512;

fn cloud_table(seed: u32) -> Texels<f32> {
    let n = CLOUD_TABLE;
    let octaves = Octaves::new(seed);
    let texels = (0..n * n)
        .into_par_iter()
        .map(|i| {
            let p = Vec2::new((i % n) as f32 + 0.5, (i / n) as f32 + 0.5)
                * (CLOUD_PERIOD as f32 / n as f32);
            octaves.fbm(p)
        })
        .collect();
    Texels {
        width: n,
        height: n,
        texels,
    }
}

/// Value noise on the integer lattice, repeating every `period` cells: the lattice values,
/// hashed once, and their smooth interpolation.
struct Lattice {
    period: u32,
    /// Row-major, `period`² values in [0, 1).
    values: Vec<f32>,
}

impl Lattice {
    fn new(seed: u32, period: u32) -> Lattice {
        assert!(period.is_power_of_two());
        let values = (0..period * period)
            .map(|i| {
                let (x, y) = (i % period, i / period);
                let key = x.wrapping_mul(0x8da6_b343) ^ y.wrapping_mul(0xd816_3841) ^ seed;
                unit_float(hash_u32(key))
            })
            .collect();
        Lattice { period, values }
    }

    /// Noise in [0, 1] at `p`.
    fn noise(&self, p: Vec2) -> f32 {
        let i = Vec2::new(fast_floor(p.x), fast_floor(p.y));
        let f = p - i;
        // The period is a power of two: wrapping is a mask (also for negative cells).
        let wrap = |v: i32| (v & (self.period as i32 - 1)) as usize;
        let (x0, y0) = (i.x as i32, i.y as i32);
        let (x, y) = ([wrap(x0), wrap(x0 + 1)], [wrap(y0), wrap(y0 + 1)]);
        let row = self.period as usize;
        let corner = |dx: usize, dy: usize| self.values[y[dy] * row + x[dx]];
        let u = f * f * (Vec2::splat(3.0) - 2.0 * f);
        let top = corner(0, 0) + (corner(1, 0) - corner(0, 0)) * u.x;
        let bottom = corner(0, 1) + (corner(1, 1) - corner(0, 1)) * u.x;
        top + (bottom - top) * u.y
    }
}

/// `floor` without a libm call (the x86-64 baseline has no rounding instruction).
fn fast_floor(x: f32) -> f32 {
    let t = x as i32 as f32;
    if t > x { t - 1.0 } else { t }
}

/// Five octaves of value noise, each of twice the frequency of the one before and all
/// repeating every `CLOUD_PERIOD`.
struct Octaves([Lattice; 5]);

impl Octaves {
    fn new(seed: u32) -> Octaves {
        Octaves(std::array::from_fn(|octave| {
            Lattice::new(seed.wrapping_add(octave as u32), CLOUD_PERIOD << octave)
        }))
    }

    /// Their fractal sum at `p`, in [0, 1].
    fn fbm(&self, p: Vec2) -> f32 {
        let (mut sum, mut amplitude, mut norm, mut q) = (0.0, 0.5, 0.0, p);
        for lattice in &self.0 {
            sum += amplitude * lattice.noise(q);
            norm += amplitude;
            amplitude *= 0.5;
            // The integer shift decorrelates the lattices.
            q = q * 2.0 + Vec2::new(17.0, 5.0);
        }
        sum / norm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test_sky(cover: f64) -> Sky {
        Sky {
            zenith_color: [0.2, 0.4, 0.9],
            horizon_color: [0.8, 0.9, 1.0],
            ground_color: [0.3, 0.3, 0.3],
            ambient: 0.5,
            cloud_cover: cover,
            cloud_height: 1500.0,
            cloud_size: 900.0,
            cloud_seed: 7,
        }
    }

    fn model(cover: f64) -> SkyModel {
        let sky = test_sky(cover);
        let sun = Sun {
            direction: glam::DVec3::Y,
            color: [1.0; 3],
            intensity: 2.0,
        };
        SkyModel::new(&sky, &sun, None)
    }

    /// Fraction of upward directions (elevation above 30°) that see a cloud.
    fn covered_fraction(m: &SkyModel) -> f32 {
        let n = 4000;
        let mut covered = 0;
        for i in 0..n {
            let a = i as f32 * 2.399_963;
            let r = 0.8 * (i as f32 / n as f32).sqrt();
            let dir = Vec3::new(r * a.cos(), 1.0, r * a.sin()).normalize();
            if m.cloud_density(dir) > 0.5 {
                covered += 1;
            }
        }
        covered as f32 / n as f32
    }

    #[test]
    fn cloud_cover_controls_the_cloudy_fraction() {
        assert_eq!(covered_fraction(&model(0.0)), 0.0);
        let (low, mid, high) = (
            covered_fraction(&model(0.2)),
            covered_fraction(&model(0.5)),
            covered_fraction(&model(0.9)),
        );
        assert!(low < mid && mid < high, "{low} {mid} {high}");
        assert!(mid > 0.05 && mid < 0.95);
    }

    #[test]
    fn gradient_runs_from_horizon_to_zenith() {
        let m = model(0.0);
        assert!(
            m.radiance(Vec3::new(1.0, 0.0, 0.0))
                .abs_diff_eq(m.horizon, 1e-6)
        );
        // Straight up is the sun's disc in this model; look just beside it.
        let up = Vec3::new(0.02, 1.0, 0.0).normalize();
        assert!(
            m.radiance(up)
                .abs_diff_eq(m.horizon.lerp(m.zenith, up.y.sqrt()), 1e-6)
        );
        assert!(m.radiance(Vec3::Y).x > m.zenith.x + 1.0);
    }

    fn photometric(sun_lux: f64, zenith_cd_m2: f64, white: f64) -> (SkyModel, Sky, Sun) {
        let sky = test_sky(0.0);
        let sun = Sun {
            direction: glam::DVec3::new(0.3, 0.6, -0.2).normalize(),
            color: [1.0, 0.9, 0.7],
            intensity: 1.0,
        };
        let p = Photometry {
            sun_illuminance_lux: sun_lux,
            sky_zenith_cd_m2: zenith_cd_m2,
            white_cd_m2: white,
            lamp_sampling: Default::default(),
        };
        (SkyModel::new(&sky, &sun, Some(&p)), sky, sun)
    }

    /// ∫ f(dir) cos θ dω over the upper hemisphere by the midpoint rule in (cos θ, φ).
    fn hemisphere_integral(f: impl Fn(Vec3) -> Vec3) -> glam::DVec3 {
        let (n_mu, n_phi) = (400, 64);
        let mut sum = glam::DVec3::ZERO;
        for i in 0..n_mu {
            let mu = (i as f64 + 0.5) / n_mu as f64;
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) / n_phi as f64 * std::f64::consts::TAU;
                let s = (1.0 - mu * mu).sqrt();
                let dir = glam::DVec3::new(s * phi.cos(), mu, s * phi.sin()).as_vec3();
                sum += f(dir).as_dvec3() * mu;
            }
        }
        sum * (std::f64::consts::TAU / (n_mu * n_phi) as f64)
    }

    #[test]
    fn a_floor_receives_pi_times_the_ambient_from_the_sky_it_sees() {
        // No sun, so that its disc adds nothing: the floor's irradiance from the sky's
        // radiance, integrated direction by direction, is π × the ambient term.
        let (m, _, _) = photometric(0.0, 6000.0, 1000.0);
        let irradiance = hemisphere_integral(|d| m.radiance(d));
        let ambient = m.ambient(Vec3::Y).as_dvec3() * std::f64::consts::PI;
        let error = (irradiance - ambient).abs() / ambient;
        assert!(error.max_element() < 1e-3, "{irradiance} vs {ambient}");
        // And the zenith's luminance is the stated one, in units of the white.
        let zenith = crate::util::color::luminance(m.radiance(Vec3::Y));
        assert!((zenith - 6.0).abs() < 1e-5, "{zenith}");
    }

    #[test]
    fn the_suns_disc_carries_its_illuminance() {
        // The disc's radiance over its solid angle is the sun's illuminance (in units of the
        // white): a lens looking at the sun collects E.
        let (lux, white) = (90_000.0, 2000.0);
        let (m, _, sun) = photometric(lux, 0.0, white);
        let to_sun = sun.direction.as_vec3();
        let (n, cone) = (2000, (1.0 - SUN_DISC_COS) * 1.5);
        // Midpoint rule over the cone around the sun in (cos, angle).
        let axis = to_sun.any_orthonormal_pair();
        let mut sum = 0.0f64;
        for i in 0..n {
            let cos = 1.0 - (i as f32 + 0.5) / n as f32 * cone;
            for j in 0..32 {
                let phi = (j as f32 + 0.5) / 32.0 * std::f32::consts::TAU;
                let s = (1.0 - cos * cos).sqrt();
                let dir = to_sun * cos + (axis.0 * phi.cos() + axis.1 * phi.sin()) * s;
                sum += f64::from(crate::util::color::luminance(m.radiance(dir.normalize())));
            }
        }
        let collected = sum * f64::from(cone) / n as f64 / 32.0 * std::f64::consts::TAU;
        let expected = lux / white;
        assert!(
            (collected - expected).abs() / expected < 0.02,
            "{collected} vs {expected}"
        );
        // And a surface facing the sun gets E/π (Lambert's albedo 1).
        let facing = crate::util::color::luminance(m.sun_irradiance);
        assert!((f64::from(facing) - expected / std::f64::consts::PI).abs() < 1e-3 * expected);
    }

    #[test]
    fn the_ground_below_is_a_lambertian_plane_under_the_sun_and_the_sky() {
        // A ceiling sees only the ground, and the sky below the horizon is that ground:
        // albedo × (E sin h / π + the sky's ambient), in units of the white.
        let (lux, zenith, white) = (60_000.0, 5_000.0, 1_500.0);
        let (m, sky, sun) = photometric(lux, zenith, white);
        let albedo = srgb_to_linear3(sky.ground_color);
        let sun_colour = srgb_to_linear3(sun.color);
        let sun_part = sun_colour / crate::util::color::luminance(sun_colour)
            * (lux / white / std::f64::consts::PI * sun.direction.y) as f32;
        let expected = albedo * (sun_part + m.ambient(Vec3::Y));
        assert!(
            m.ambient(-Vec3::Y)
                .abs_diff_eq(expected, 1e-5 * expected.max_element())
        );
        let down = Vec3::new(0.3, -0.9, 0.1).normalize();
        assert!(
            m.radiance(down)
                .abs_diff_eq(expected, 1e-5 * expected.max_element())
        );
    }
}
