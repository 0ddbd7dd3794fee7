//! The flags of the scene-model methods (`ground`, `plane-fit`, `depth`): the depth sensor
//! and the filling of disocclusion holes. Shared by `run` and `compare`.

use seethru::system::depth_sensor::{SensorKind, SensorOptions};
use seethru::system::options::Method;
use seethru::system::scene_model::{Fill, SceneModelOptions};

use crate::cli::args::{ReadWhen, choice, pixels, positive, real, refuse_ignored};

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
    /// Refuses flags that `method` would ignore without a word: a sensor or its settings for
    /// a method that reads no depth, a fill for a method that leaves no holes. (The settings
    /// of the ideal sensor, which has none, are refused where the sensor is resolved.)
    pub fn check_used_by(&self, method: Method) -> anyhow::Result<()> {
        let reads_depth = matches!(method, Method::PlaneFit | Method::Depth);
        refuse_ignored(&Self::rules(
            reads_depth,
            reads_depth,
            method == Method::Depth,
            "by --method plane-fit and depth",
            "by --method depth (its disocclusion holes)",
        ))
    }

    /// The rules of these flags: the sensor's settings are read when `reads_depth`, its kind
    /// when `reads_kind`, the fill when `fills`; `depth_when` and `fill_when` say by what.
    pub fn rules(
        reads_depth: bool,
        reads_kind: bool,
        fills: bool,
        depth_when: &'static str,
        fill_when: &'static str,
    ) -> Vec<ReadWhen> {
        let depth = |flag| ReadWhen {
            flag,
            read: reads_depth,
            when: depth_when,
        };
        vec![
            ReadWhen {
                flag: "--depth-sensor",
                read: reads_kind,
                when: depth_when,
            },
            depth("--depth-resolution"),
            depth("--depth-range"),
            depth("--depth-noise"),
            depth("--depth-quantum"),
            ReadWhen {
                flag: "--fill",
                read: fills,
                when: fill_when,
            },
        ]
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
