//! The flags of the scene-model methods (`ground`, `plane-fit`, `depth`): the depth sensor
//! and the filling of disocclusion holes. Shared by `run` and `compare`.

use anyhow::bail;
use seethru::system::depth_sensor::{SensorKind, SensorOptions};
use seethru::system::options::Method;
use seethru::system::scene_model::{Fill, SceneModelOptions};

use crate::cli::args::{pixels, positive, real};

#[derive(clap::Args, Clone)]
pub struct SceneModelArgs {
    /// Depth sensor of plane-fit and depth: ideal (the frontal render's depth), tof (σ ∝ z,
    /// 320 px wide, 15 m range, 1 cm at 1 m, 1 mm steps) or stereo (σ ∝ z², half the frontal
    /// width, 80 m, 2 mm at 1 m, inverse-depth steps of 0.0005 /m).
    #[arg(long = "depth-sensor", value_enum, default_value_t = SensorKind::Ideal)]
    pub depth_sensor: SensorKind,
    /// Depth sensor width, pixels in [1, 16384], at most the frontal camera's (aspect kept;
    /// tof and stereo only; default: the sensor's).
    #[arg(long = "depth-resolution", value_parser = pixels)]
    pub depth_resolution: Option<u32>,
    /// Depth sensor range: no return past it (d2 → ∞ there), metres in [1e-6, 1e6] (tof and
    /// stereo only; default: the sensor's).
    #[arg(long = "depth-range", value_parser = positive(1e6))]
    pub depth_range: Option<f64>,
    /// Depth noise σ at 1 m, metres in [0, 10], growing as z (tof) or z² (stereo); seeded by
    /// --seed (tof and stereo only; default: the sensor's).
    #[arg(long = "depth-noise", value_parser = real(0.0, 10.0))]
    pub depth_noise: Option<f64>,
    /// Depth quantisation step at 1 m, metres in [0, 10] (0: none): constant for tof, growing
    /// as z² for stereo (a step of disparity) (tof and stereo only; default: the sensor's).
    #[arg(long = "depth-quantum", value_parser = real(0.0, 10.0))]
    pub depth_quantum: Option<f64>,
    /// Disocclusion holes of --method depth: none (black, counted blank), background (the
    /// nearest farther surface on the epipolar line) or inpaint (diffused from around).
    #[arg(long, value_enum, default_value_t = Fill::None)]
    pub fill: Fill,
}

impl SceneModelArgs {
    /// Refuses flags that `method` would ignore without a word: a sensor or its settings for
    /// a method that reads no depth, a fill for a method that leaves no holes. (The settings
    /// of the ideal sensor, which has none, are refused where the sensor is resolved.)
    pub fn check_used_by(&self, method: Method) -> anyhow::Result<()> {
        let given = [
            ("--depth-resolution", self.depth_resolution.is_some()),
            ("--depth-range", self.depth_range.is_some()),
            ("--depth-noise", self.depth_noise.is_some()),
            ("--depth-quantum", self.depth_quantum.is_some()),
        ];
        let reads_depth = matches!(method, Method::PlaneFit | Method::Depth);
        if !reads_depth
            && let Some((flag, _)) =
                std::iter::once(("--depth-sensor", self.depth_sensor != SensorKind::Ideal))
                    .chain(given)
                    .find(|(_, g)| *g)
        {
            bail!("{flag} is read by --method plane-fit and depth only, not by this method");
        }
        if method != Method::Depth && self.fill != Fill::None {
            bail!("--fill fills the holes of --method depth only");
        }
        Ok(())
    }

    pub fn options(&self) -> SceneModelOptions {
        SceneModelOptions {
            sensor: SensorOptions {
                kind: self.depth_sensor,
                width: self.depth_resolution,
                range_m: self.depth_range,
                noise_1m: self.depth_noise,
                quantum_1m: self.depth_quantum,
            },
            fill: self.fill,
        }
    }
}
