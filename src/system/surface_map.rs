//! The planar compensation per display pixel, for a curved display (one that is not the
//! obstacle's flat face): the eye's ray through each display pixel's point on the surface meets
//! the model plane (z = −d2 in the obstacle frame, or d2 → ∞) and is projected into the
//! believed frontal camera. On a flat display this is the crop's homography, pixel by pixel
//! (tested); the homography stays the fast path there.

use anyhow::{Result, bail};
use glam::{DAffine3, DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::geometry::lens::Lens;
use crate::render::frame::{Frame, Pixel};
use crate::scene::display_keys::pixel_uv;
use crate::scene::{Obstacle, Scene};
use crate::system::compensation::ModelPlane;
use crate::system::display::{Filter, MISSING_ID, sample};

/// The world point of every display pixel's centre (row-major); `None` where a curved
/// display's UVs do not cover the pixel.
pub fn display_points(obstacle: &Obstacle) -> Vec<Option<DVec3>> {
    let [w, h] = obstacle.display_resolution;
    let size = [w, h];
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let uv = pixel_uv(x as f64 + 0.5, y as f64 + 0.5, size);
            let local = match obstacle.display_shape.curved() {
                None => Some(DVec3::new(
                    (uv.x - 0.5) * obstacle.width,
                    (0.5 - uv.y) * obstacle.height,
                    0.0,
                )),
                Some(surface) => surface.point_at_uv(uv),
            };
            local.map(|p| obstacle.world_from_obstacle.transform_point3(p))
        })
        .collect()
}

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
        let s = self.obstacle_from_world.transform_point3(on_display);
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

/// The display image of a curved display: every pixel's point through `model` into the
/// frontal frame. Returns it and the number of display pixels that show nothing (the model
/// point outside the frontal image or behind the camera, or the pixel outside the UVs).
pub fn curved_display(
    frontal: &Frame,
    obstacle: &Obstacle,
    model: &PointModel,
    filter: Filter,
) -> (Frame, usize) {
    use rayon::prelude::*;
    let points = display_points(obstacle);
    let pixels: Vec<Pixel> = points
        .par_iter()
        .map(|p| match p.and_then(|p| model.frontal_point(p)) {
            Some(f) => sample(frontal, f, filter),
            None => Pixel {
                object_id: MISSING_ID,
                ..Pixel::SKY
            },
        })
        .collect();
    let missing = pixels.iter().filter(|p| p.object_id == MISSING_ID).count();
    let [w, h] = obstacle.display_resolution;
    (Frame::from_pixels(w, h, &pixels), missing)
}
