//! The flags of the scene-model methods (`ground`, `plane-fit`, `depth`): the depth sensor
//! and the filling of disocclusion holes. Shared by `run` and `compare`.

use seethru::system::depth_sensor::{SensorKind, SensorOptions};
use seethru::system::scene_model::{Fill, SceneModelOptions};

use crate::cli::args::{choice, pixels, positive, real};

#[derive(clap::Args, Clone)]
pub struct SceneModelArgs {
    /// Depth sensor of plane-fit and depth: ideal (the frontal render's depth), tof (σ ∝ z,
    /// 320 px wide, 15 m range, 1 cm at 1 m, 1 mm steps) or stereo (σ ∝ z², half the frontal
    /// width, 80 m, 2 mm at 1 m, inverse-depth steps of 0.0005 /m).
    #[arg(long = "depth-sensor", value_enum, value_parser = choice::<SensorKind>(), default_value_t = SensorKind::Ideal)]
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
    #[arg(long, value_enum, value_parser = choice::<Fill>(), default_value_t = Fill::None)]
    pub fill: Fill,
}

impl SceneModelArgs {
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
