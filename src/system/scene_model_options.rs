//! The options of the scene-model methods (`ground`, `plane-fit`, `depth`): which depth
//! sensor, and how disocclusion holes are filled.

use crate::system::depth_sensor::SensorOptions;

/// How disocclusion holes of `--method depth` are filled.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Fill {
    /// Shown black and counted as blank.
    None,
    /// The nearest farther surface along the epipolar line.
    Background,
    /// Diffused in from the seen pixels around the hole (colour: their mean, layer by layer;
    /// the shown point: the farthest of them).
    Inpaint,
}

/// The depth sensor and the hole filling of the scene-model methods.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneModelOptions {
    pub sensor: SensorOptions,
    pub fill: Fill,
}

impl Default for SceneModelOptions {
    fn default() -> Self {
        Self {
            sensor: SensorOptions::default(),
            fill: Fill::None,
        }
    }
}
