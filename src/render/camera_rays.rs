//! Primary rays of a camera in f32, with the per-camera constants hoisted out of the pixel
//! loop. A camera with a lens has its rays from the lens model's inverse (f64).

use glam::{DVec2, Mat3, Vec3};

use crate::geometry::camera::Camera;

pub struct CameraRays {
    /// Camera centre, world frame, metres.
    pub origin: Vec3,
    world_from_camera: Mat3,
    /// Camera-space direction of the pixel coordinates (0, 0), and its change per pixel.
    corner: Vec3,
    step_x: f32,
    step_y: f32,
    /// The camera, where it has a lens: rays through [`Camera::world_ray`].
    lens_camera: Option<Camera>,
}

impl CameraRays {
    pub fn new(camera: &Camera) -> Self {
        let (tx, ty) = (camera.tan_half_x() as f32, camera.tan_half_y() as f32);
        Self {
            origin: camera.position().as_vec3(),
            world_from_camera: camera.world_from_camera.matrix3.as_mat3(),
            corner: Vec3::new(-tx, ty, -1.0),
            step_x: 2.0 * tx / camera.width as f32,
            step_y: -2.0 * ty / camera.height as f32,
            lens_camera: camera.lens.is_some().then_some(*camera),
        }
    }

    /// Unit direction (world frame) of the ray through continuous pixel coordinates, as
    /// [`Camera::world_ray`] but in f32.
    #[inline]
    pub fn direction(&self, px: f32, py: f32) -> Vec3 {
        if let Some(camera) = &self.lens_camera {
            let p = DVec2::new(px as f64, py as f64);
            return camera.world_ray(p).1.as_vec3();
        }
        let local = self.corner + Vec3::new(px * self.step_x, py * self.step_y, 0.0);
        (self.world_from_camera * local).normalize()
    }
}
