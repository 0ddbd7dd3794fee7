//! Planar parallax compensation in 3-D (docs/DESIGN.md §4): which part of the frontal image the
//! display must show so that it looks transparent from a given eye, under a planar scene
//! model at working distance `d2` (or `d2 → ∞`).

use glam::{DMat3, DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::geometry::homography::homography;
use crate::scene::Obstacle;

/// The planar scene model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ModelPlane {
    /// The plane `z = −d2` of the obstacle frame; `d2` in metres, > 0.
    At(f64),
    /// The paper's `d2 → ∞`: only directions matter.
    Infinity,
}

/// The crop of the frontal image that the display shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crop {
    /// Frontal-image pixel coordinates (continuous) of the display's corners as the model sees
    /// them: top-left, top-right, bottom-right, bottom-left.
    pub corners: [DVec2; 4],
    /// Maps homogeneous display pixel coordinates (x right, y down, (0, 0) the display's
    /// top-left corner) to homogeneous frontal pixel coordinates.
    pub frontal_from_display: DMat3,
    /// Frontal image size, pixels.
    pub frontal_size: [u32; 2],
}

/// How the crop sits in the frontal image, in the paper's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CropRatios {
    /// Fraction of the frontal image's width discarded on the left (`R1`) and right (`R2`).
    pub left: f64,
    pub right: f64,
    /// The vertical counterparts: fraction of the height discarded at the top and bottom.
    pub top: f64,
    pub bottom: f64,
}

impl Crop {
    /// The crop rectangle's ratios, from the bounding box of the corners (exact when the
    /// frontal camera's axis is perpendicular to the display, the paper's case).
    /// The corners' bounding box in frontal pixels: (min, max).
    pub fn bounds(&self) -> (DVec2, DVec2) {
        let min = self
            .corners
            .iter()
            .fold(DVec2::splat(f64::INFINITY), |a, c| a.min(*c));
        let max = self
            .corners
            .iter()
            .fold(DVec2::splat(f64::NEG_INFINITY), |a, c| a.max(*c));
        (min, max)
    }

    pub fn ratios(&self) -> CropRatios {
        let [w, h] = self.frontal_size.map(f64::from);
        let (min, max) = self.bounds();
        CropRatios {
            left: min.x / w,
            right: (w - max.x) / w,
            top: min.y / h,
            bottom: (h - max.y) / h,
        }
    }

    /// Whether the four corners form an axis-aligned rectangle (to `tolerance` pixels), so
    /// that a plain crop-and-resize suffices.
    pub fn is_axis_aligned(&self, tolerance: f64) -> bool {
        let [tl, tr, br, bl] = self.corners;
        (tl.y - tr.y).abs() <= tolerance
            && (bl.y - br.y).abs() <= tolerance
            && (tl.x - bl.x).abs() <= tolerance
            && (tr.x - br.x).abs() <= tolerance
    }

    /// Frontal pixel coordinates of continuous display pixel coordinates.
    pub fn frontal_point(&self, display: DVec2) -> DVec2 {
        let p = self.frontal_from_display * display.extend(1.0);
        DVec2::new(p.x / p.z, p.y / p.z)
    }
}

/// Why a crop cannot be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum CropError {
    /// The eye is not in front of the display (`d1 ≤ 0`).
    EyeBehindDisplay { d1: f64 },
    /// A corner's model point is behind the frontal camera.
    BehindFrontalCamera,
}

impl std::fmt::Display for CropError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CropError::EyeBehindDisplay { d1 } => {
                write!(
                    f,
                    "the eye the compensation uses must be in front of the display (d1 > 0), got d1 = {} m: check the driver camera's position and option `head_bias_cm`",
                    crate::util::number::short(*d1)
                )
            }
            CropError::BehindFrontalCamera => write!(
                f,
                "the model plane point of a display corner is behind the frontal camera: the working distance (option `d2`) lies nearer than the camera, or the camera faces away from the plane"
            ),
        }
    }
}

impl std::error::Error for CropError {}

/// The crop for an eye at `eye` (world), the display of `obstacle`, the `frontal` camera and
/// the model plane, at display resolution `display_size` (pixels).
pub fn compute_crop(
    eye: DVec3,
    obstacle: &Obstacle,
    frontal: &Camera,
    plane: ModelPlane,
    display_size: [u32; 2],
) -> Result<Crop, CropError> {
    let obstacle_from_world = obstacle.world_from_obstacle.inverse();
    let eye_o = obstacle_from_world.transform_point3(eye);
    let d1 = eye_o.z;
    if d1 <= 0.0 {
        return Err(CropError::EyeBehindDisplay { d1 });
    }
    let mut corners = [DVec2::ZERO; 4];
    for (out, corner) in corners.iter_mut().zip(obstacle.display_corners()) {
        let c = obstacle_from_world.transform_point3(corner);
        // The driver's ray E → C continued to the model plane, or its direction.
        let projected = match plane {
            ModelPlane::At(d2) => {
                let p = eye_o + (c - eye_o) * (d1 + d2) / d1;
                frontal.project_point(obstacle.world_from_obstacle.transform_point3(p))
            }
            ModelPlane::Infinity => {
                frontal.project_direction(obstacle.world_from_obstacle.transform_vector3(c - eye_o))
            }
        };
        *out = projected.ok_or(CropError::BehindFrontalCamera)?;
    }
    let [w, h] = display_size.map(f64::from);
    let display = [
        DVec2::new(0.0, 0.0),
        DVec2::new(w, 0.0),
        DVec2::new(w, h),
        DVec2::new(0.0, h),
    ];
    Ok(Crop {
        corners,
        frontal_from_display: homography(display, corners),
        frontal_size: [frontal.width, frontal.height],
    })
}
