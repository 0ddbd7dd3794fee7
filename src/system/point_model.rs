//! The planar model per display point: the eye's ray through a point of the display's
//! surface meets the model plane (z = −d2 in the obstacle frame, or d2 → ∞) and is projected
//! into the believed frontal camera. A curved display's compensation
//! (`system/surface_map.rs`) and its ideal display (`system/display.rs`) both
//! map through it.

use anyhow::{Result, bail};
use glam::{DAffine3, DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::geometry::lens::Lens;
use crate::scene::Scene;
use crate::system::compensation::ModelPlane;

/// Display point → frontal pixel under the planar model, for one eye.
#[derive(Clone, Debug)]
pub struct PointModel {
    /// The eye the compensation uses, obstacle frame, metres.
    eye: DVec3,
    plane: ModelPlane,
    obstacle_from_world: DAffine3,
    world_from_obstacle: DAffine3,
    /// The believed frontal camera without its distortion.
    pinhole: Camera,
    /// The believed frontal lens; `None` for a pinhole.
    lens: Option<Lens>,
}

impl PointModel {
    /// The model of `scene`'s believed frontal camera ([calibration]) for the eye at `eye`
    /// (world).
    pub fn new(scene: &Scene, eye: DVec3, plane: ModelPlane) -> Result<Self> {
        let believed = scene.calibration.frontal.apply(&scene.frontal)?;
        let obstacle_from_world = scene.obstacle.world_from_obstacle.inverse();
        let eye = obstacle_from_world.transform_point3(eye);
        if eye.z <= 0.0 {
            bail!(
                "the eye the compensation uses must be in front of the display (d1 > 0), got d1 = {} m",
                crate::util::number::short(eye.z)
            );
        }
        Ok(PointModel {
            eye,
            plane,
            obstacle_from_world,
            world_from_obstacle: scene.obstacle.world_from_obstacle,
            pinhole: believed.undistorted(),
            lens: believed.lens,
        })
    }

    /// The frontal pixel (continuous, distorted by the believed lens) that the display point
    /// `on_display` (world) shows; `None` where the eye's ray misses the model plane or the
    /// model point is behind the camera.
    pub fn frontal_point(&self, on_display: DVec3) -> Option<DVec2> {
        self.frontal_point_local(self.obstacle_from_world.transform_point3(on_display))
    }

    /// [`PointModel::frontal_point`] of a display point given in the obstacle frame (metres):
    /// the `seethru` view of a moving display finds the point where the display is now.
    pub fn frontal_point_local(&self, s: DVec3) -> Option<DVec2> {
        let ray = s - self.eye;
        let undistorted = match self.plane {
            ModelPlane::At(d2) => {
                if ray.z >= 0.0 {
                    return None;
                }
                let p = self.eye + ray * ((-d2 - self.eye.z) / ray.z);
                self.pinhole
                    .project_point(self.world_from_obstacle.transform_point3(p))?
            }
            ModelPlane::Infinity => self
                .pinhole
                .project_direction(self.world_from_obstacle.transform_vector3(ray))?,
        };
        Some(match &self.lens {
            None => undistorted,
            Some(lens) => lens.distort_pixel(undistorted),
        })
    }
}
