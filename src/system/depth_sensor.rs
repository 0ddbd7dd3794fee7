//! A modelled depth sensor beside the frontal camera: what the depth-based compensation
//! methods (`depth`, `plane-fit`) know of the scene's geometry.
//!
//! The sensor shares the frontal camera's pose and field of view (a co-located RGB-D pair, as
//! in Baričević et al.), at its own resolution; it is a pinhole, with a frontal lens the
//! pinhole of the lens's intrinsics ([`sensor_camera`]). `ideal` is the frontal render's own
//! depth (ray cast on the pinhole's grid when the frontal camera has a lens);
//! `tof` and `stereo` are ray cast at their resolution and then degraded as real sensors are:
//! no return past the range limit (or from the sky), seeded Gaussian noise whose σ grows with
//! distance — linearly for time of flight, quadratically for stereo (a fixed disparity error)
//! — and quantisation (a fixed depth step for time of flight, a fixed step of inverse depth,
//! i.e. of disparity, for stereo). Depth is the axial depth along the camera's axis.

use anyhow::{Result, bail};

use crate::geometry::camera::Camera;
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::render::render_job::RenderJob;
use crate::render::settings::RenderSettings;
use crate::scene::world::view_bit;
use crate::system::head::gaussian;
use crate::util::sampling::hash_words;

/// The kind of depth sensor.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum SensorKind {
    /// The frontal render's exact depth, at its resolution: no noise, no range limit.
    Ideal,
    /// Time of flight: σ(z) = σ₁·z, a fixed depth step, a short range.
    Tof,
    /// Stereo: σ(z) = σ₁·z², a fixed step of inverse depth (disparity), a longer range.
    Stereo,
}

/// The sensor the user asked for; `None` takes the kind's default.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorOptions {
    pub kind: SensorKind,
    /// Sensor image width, pixels (its height follows the frontal camera's aspect).
    pub width: Option<u32>,
    /// Farthest return, metres of axial depth, > 0.
    pub range_m: Option<f64>,
    /// σ of the depth noise at 1 m, metres, ≥ 0.
    pub noise_1m: Option<f64>,
    /// Quantisation step at 1 m, metres, ≥ 0 (0: none).
    pub quantum_1m: Option<f64>,
}

impl Default for SensorOptions {
    fn default() -> Self {
        Self {
            kind: SensorKind::Ideal,
            width: None,
            range_m: None,
            noise_1m: None,
            quantum_1m: None,
        }
    }
}

/// A sensor with every parameter resolved.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SensorModel {
    pub kind: SensorKind,
    /// Sensor resolution, pixels.
    pub width: u32,
    pub height: u32,
    /// Farthest return, metres (∞: unlimited, "inf" in JSON).
    #[serde(serialize_with = "crate::util::json::finite_or_inf")]
    pub range_m: f64,
    /// σ at 1 m, metres.
    pub noise_1m: f64,
    /// Step at 1 m, metres (for stereo: the step of inverse depth, 1/m, that gives it).
    pub quantum_1m: f64,
}

impl SensorModel {
    /// Resolves `options` for a frontal camera; errors name the option, value and range.
    pub fn resolve(options: &SensorOptions, frontal: &Camera) -> Result<Self> {
        let fw = frontal.width;
        if options.kind == SensorKind::Ideal {
            let given = [
                options.width.map(|_| "option `depth_resolution`"),
                options.range_m.map(|_| "option `depth_range`"),
                options.noise_1m.map(|_| "option `depth_noise`"),
                options.quantum_1m.map(|_| "option `depth_quantum`"),
            ];
            if let Some(flag) = given.into_iter().flatten().next() {
                bail!(
                    "{flag} does not apply to option `depth_sensor` ideal (the frontal render's exact depth); use option `depth_sensor` tof or stereo"
                );
            }
        }
        let (width, range, noise, quantum) = match options.kind {
            SensorKind::Ideal => (fw, f64::INFINITY, 0.0, 0.0),
            SensorKind::Tof => (fw.min(320), 15.0, 0.01, 0.001),
            SensorKind::Stereo => (fw.div_ceil(2), 80.0, 0.002, 0.0005),
        };
        let width = options.width.unwrap_or(width);
        if width == 0 || width > fw {
            bail!(
                "option `depth_resolution` {width} is out of range [1, {fw}] (the frontal camera's width)"
            );
        }
        let height = ((width as u64 * frontal.height as u64 + fw as u64 / 2) / fw as u64)
            .clamp(1, frontal.height as u64) as u32;
        let model = SensorModel {
            kind: options.kind,
            width,
            height,
            range_m: options.range_m.unwrap_or(range),
            noise_1m: options.noise_1m.unwrap_or(noise),
            quantum_1m: options.quantum_1m.unwrap_or(quantum),
        };
        if model.range_m.is_nan() || model.range_m <= 0.0 {
            bail!("option `depth_range` must be > 0 m, got {}", model.range_m);
        }
        if !(model.noise_1m >= 0.0 && model.noise_1m.is_finite()) {
            bail!("option `depth_noise` must be ≥ 0 m, got {}", model.noise_1m);
        }
        if !(model.quantum_1m >= 0.0 && model.quantum_1m.is_finite()) {
            bail!(
                "option `depth_quantum` must be ≥ 0 m, got {}",
                model.quantum_1m
            );
        }
        Ok(model)
    }

    /// σ of the depth noise at axial depth `z`, metres.
    pub fn sigma(&self, z: f64) -> f64 {
        match self.kind {
            SensorKind::Stereo => self.noise_1m * z * z,
            _ => self.noise_1m * z,
        }
    }

    /// What the sensor reports for a surface at true axial depth `z` (finite, > 0): `None`
    /// past the range, else the noisy, quantised depth. `deviate` is a standard normal.
    pub fn reading(&self, z: f64, deviate: f64) -> Option<f64> {
        if !(z.is_finite() && z > 0.0 && z <= self.range_m) {
            return None;
        }
        let noisy = (z + self.sigma(z) * deviate).max(1e-3);
        let q = self.quantum_1m;
        Some(if q == 0.0 {
            noisy
        } else if self.kind == SensorKind::Stereo {
            // A fixed disparity step: inverse depth rounded to multiples of q (1/m).
            1.0 / ((1.0 / noisy / q).round().max(1.0) * q)
        } else {
            ((noisy / q).round().max(1.0)) * q
        })
    }
}

/// A depth image: inverse axial depth per sensor pixel (1/m; 0 where there is no return:
/// sky, or past the range). Inverse depth is affine in image coordinates over any plane, so
/// it is the quantity the methods interpolate and fit.
#[derive(Clone, Debug)]
pub struct DepthMap {
    /// The sensor as a camera ([`sensor_camera`]): a pinhole at the frontal camera's pose.
    pub camera: Camera,
    pub inverse_depth: Vec<f32>,
    pub model: SensorModel,
    /// The largest inverse depth of the image (its nearest return), 1/m; 0 with none.
    max_inverse_depth: f32,
}

impl DepthMap {
    pub fn new(camera: Camera, inverse_depth: Vec<f32>, model: SensorModel) -> Self {
        let max_inverse_depth = inverse_depth.iter().copied().fold(0.0, f32::max);
        Self {
            camera,
            inverse_depth,
            model,
            max_inverse_depth,
        }
    }

    /// The inverse depth of the nearest return, 1/m (0 when there is none).
    pub fn max_inverse_depth(&self) -> f32 {
        self.max_inverse_depth
    }

    /// Inverse depth of sensor pixel (x, y).
    pub fn at(&self, x: u32, y: u32) -> f32 {
        self.inverse_depth[(y * self.camera.width + x) as usize]
    }
}

/// The sensor as a camera: the frontal camera's pose, at the sensor's resolution, and a
/// pinhole: without a lens the frontal camera's own, with one the pinhole of the lens's
/// intrinsics (its distortion removed). Over a pinhole's image a line of sight is a straight
/// epipolar line and inverse depth over a plane is affine, which the depth search and the
/// plane fit rely on; what they find is projected into the frontal image through its lens.
pub fn sensor_camera(frontal_camera: &Camera, model: &SensorModel) -> Camera {
    frontal_camera
        .undistorted()
        .with_resolution(model.width, model.height)
}

/// [`sense`] from where the frontal camera captured its image (`captured`: carried on by the
/// vehicle, option `latency_camera`), its depths read as from where the camera is mounted
/// (`mounted`): the system does not know the vehicle moved since. With a still vehicle the two
/// are one camera and this is [`sense`].
pub fn sense_from(
    ctx: &RenderContext,
    captured: &Camera,
    mounted: &Camera,
    frontal: &Frame,
    model: SensorModel,
    seed: u32,
) -> DepthMap {
    let mut map = sense(ctx, captured, frontal, model, seed);
    map.camera.world_from_camera = mounted.world_from_camera;
    map
}

/// The sensor's depth image of the scene. `frontal` is the frontal render (the ideal
/// sensor's depth); other sensors are ray cast at their own resolution. Noise is seeded by
/// `seed` and the pixel index: the same for any thread count.
pub fn sense(
    ctx: &RenderContext,
    frontal_camera: &Camera,
    frontal: &Frame,
    model: SensorModel,
    seed: u32,
) -> DepthMap {
    let camera = sensor_camera(frontal_camera, &model);
    // Without a lens the ideal sensor's pixels are the frontal render's own; with one, its
    // pinhole grid is not the frontal image's, and is ray cast like the others (exactly).
    let depth: Vec<f32> = if model.kind == SensorKind::Ideal && frontal_camera.lens.is_none() {
        frontal.camera_z.clone()
    } else {
        let settings = RenderSettings {
            spp: 1,
            progress: false,
        };
        ctx.render(
            RenderJob::new(&camera, view_bit::FRONTAL)
                .settings(settings)
                .label("depth sensor"),
        )
        .0
        .camera_z
    };
    let noise_seed = hash_words(&[seed, 0xDE97_5E45]);
    let inverse_depth = depth
        .iter()
        .enumerate()
        .map(|(i, &z)| {
            let deviate = if model.noise_1m > 0.0 {
                gaussian(noise_seed, i as u32)
            } else {
                0.0
            };
            model
                .reading(z as f64, deviate)
                .map_or(0.0, |z| (1.0 / z) as f32)
        })
        .collect();
    DepthMap::new(camera, inverse_depth, model)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(kind: SensorKind, noise: f64, quantum: f64) -> SensorModel {
        SensorModel {
            kind,
            width: 10,
            height: 10,
            range_m: 20.0,
            noise_1m: noise,
            quantum_1m: quantum,
        }
    }

    #[test]
    fn noise_grows_linearly_for_tof_and_quadratically_for_stereo() {
        let tof = model(SensorKind::Tof, 0.01, 0.0);
        let stereo = model(SensorKind::Stereo, 0.01, 0.0);
        assert!((tof.sigma(4.0) - 0.04).abs() < 1e-12);
        assert!((stereo.sigma(4.0) - 0.16).abs() < 1e-12);
        assert!((tof.reading(4.0, 1.0).unwrap() - 4.04).abs() < 1e-12);
        assert_eq!(tof.reading(21.0, 0.0), None);
        assert_eq!(tof.reading(f64::INFINITY, 0.0), None);
    }

    #[test]
    fn quantisation_steps_depth_or_disparity() {
        let tof = model(SensorKind::Tof, 0.0, 0.05);
        assert!((tof.reading(3.02, 0.0).unwrap() - 3.0).abs() < 1e-12);
        // Stereo: inverse depth in steps of 0.01 /m: 1/3.02 = 0.3311 → 0.33 → 3.0303 m.
        let stereo = model(SensorKind::Stereo, 0.0, 0.01);
        assert!((stereo.reading(3.02, 0.0).unwrap() - 1.0 / 0.33).abs() < 1e-9);
    }
}
