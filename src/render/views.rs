//! The views the simulator renders (docs/DESIGN.md §5) and the camera and visibility of each.

use crate::geometry::camera::Camera;
use crate::scene::Scene;
use crate::scene::world::view_bit;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum View {
    /// The driver's eye with the obstacle removed: the ground truth.
    Truth,
    /// The driver's eye with the obstacle present and the display off.
    Occluded,
    /// The frontal camera, filming the scene behind the obstacle.
    Frontal,
    /// The back camera on the display, filming the driver's head.
    Back,
}

impl View {
    pub const ALL: [View; 4] = [View::Truth, View::Occluded, View::Frontal, View::Back];

    pub fn name(self) -> &'static str {
        match self {
            View::Truth => "truth",
            View::Occluded => "occluded",
            View::Frontal => "frontal",
            View::Back => "back",
        }
    }

    pub fn camera(self, scene: &Scene) -> Camera {
        match self {
            View::Truth | View::Occluded => scene.driver,
            View::Frontal => scene.frontal,
            View::Back => scene.back,
        }
    }

    /// The [`view_bit`] that selects what this view shows.
    pub fn bit(self) -> u8 {
        match self {
            View::Truth => view_bit::TRUTH,
            View::Occluded => view_bit::OCCLUDED,
            View::Frontal => view_bit::FRONTAL,
            View::Back => view_bit::BACK,
        }
    }
}
