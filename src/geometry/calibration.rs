//! Calibration error: the copy of a camera that the compensation believes in. The renderer
//! uses the true camera; head estimation and the crop use [`CameraCalibration::apply`] of it,
//! so that the cost of a wrong focal length, pose or distortion model can be measured.

use glam::{DAffine3, DMat3, DVec3};

use crate::geometry::camera::{Camera, CameraError};
use crate::geometry::lens::{Distortion, Lens};

/// How the believed camera differs from the true one. `Default` is exact.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct CameraCalibration {
    /// Relative focal length error: believed fx, fy = true · (1 + this). Dimensionless, in
    /// [−0.5, 0.5] (the scene key is in percent).
    pub focal_error: f64,
    /// Orientation error, radians, each in [−10°, 10°]: the believed camera is the true one
    /// turned by yaw (about its +y), then pitch (+x), then roll (+z), in its own frame.
    pub yaw_error: f64,
    pub pitch_error: f64,
    pub roll_error: f64,
    /// Position error, metres, in the true camera's frame (+x right, +y up, +z backwards).
    pub position_error: DVec3,
    /// Believe in a distortion-free lens (the true intrinsics, no coefficients).
    pub ignore_distortion: bool,
    /// Believed distortion coefficients by name, replacing the true ones: k1, k2, k3, k4,
    /// p1, p2 (`None`: the true value). k4 is the fisheye's, p1 and p2 Brown's.
    pub coefficients: [Option<f64>; 6],
}

/// The coefficient names of [`CameraCalibration::coefficients`], in order.
pub const COEFFICIENT_NAMES: [&str; 6] = ["k1", "k2", "k3", "k4", "p1", "p2"];

impl CameraCalibration {
    pub fn is_exact(&self) -> bool {
        *self == Self::default()
    }

    /// The coefficients that `distortion` has, by [`COEFFICIENT_NAMES`] index.
    pub fn applicable(distortion: &Distortion) -> &'static [usize] {
        match distortion {
            Distortion::None => &[],
            Distortion::Brown { .. } => &[0, 1, 2, 4, 5],
            Distortion::Fisheye { .. } => &[0, 1, 2, 3],
        }
    }

    /// The camera the compensation believes in, given the true one. Exactly `truth` when the
    /// calibration is exact, so that the pinhole path stays bit-identical.
    pub fn apply(&self, truth: &Camera) -> Result<Camera, CameraError> {
        if self.is_exact() {
            return Ok(*truth);
        }
        let rotation = DMat3::from_rotation_y(self.yaw_error)
            * DMat3::from_rotation_x(self.pitch_error)
            * DMat3::from_rotation_z(self.roll_error);
        let true_from_believed = DAffine3::from_mat3_translation(rotation, self.position_error);
        let world_from_camera = truth.world_from_camera * true_from_believed;
        let lens = truth.lens_or_pinhole();
        let scale = 1.0 + self.focal_error;
        let c = self.coefficients;
        let pick = |i: usize, v: f64| c[i].unwrap_or(v);
        let distortion = match lens.distortion {
            _ if self.ignore_distortion => Distortion::None,
            Distortion::None => Distortion::None,
            Distortion::Brown { k1, k2, k3, p1, p2 } => Distortion::Brown {
                k1: pick(0, k1),
                k2: pick(1, k2),
                k3: pick(2, k3),
                p1: pick(4, p1),
                p2: pick(5, p2),
            },
            Distortion::Fisheye { k1, k2, k3, k4 } => Distortion::Fisheye {
                k1: pick(0, k1),
                k2: pick(1, k2),
                k3: pick(2, k3),
                k4: pick(3, k4),
            },
        };
        let believed = Lens {
            fx: lens.fx * scale,
            fy: lens.fy * scale,
            distortion,
            ..lens
        };
        if truth.lens.is_none() && believed == lens {
            // Only the pose is wrong: keep the ideal pinhole's own formulas.
            return Ok(Camera {
                world_from_camera,
                ..*truth
            });
        }
        Camera::with_lens(world_from_camera, believed, truth.width, truth.height)
    }
}

/// The compensation's copies of the system's cameras.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Calibration {
    pub frontal: CameraCalibration,
    pub back: CameraCalibration,
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn camera() -> Camera {
        Camera::look_at(DVec3::ZERO, -DVec3::Z, DVec3::Y, 0.7, 320, 240).unwrap()
    }

    #[test]
    fn exact_calibration_is_the_true_camera() {
        let c = camera();
        assert_eq!(CameraCalibration::default().apply(&c).unwrap(), c);
    }

    #[test]
    fn focal_and_yaw_errors_move_the_image_as_they_should() {
        let c = camera();
        let longer = CameraCalibration {
            focal_error: 0.01,
            ..Default::default()
        }
        .apply(&c)
        .unwrap();
        // A point 100 px right of the centre appears 1 % farther out to the believed camera.
        let p = c.world_ray(DVec2::new(260.0, 120.0)).1;
        let q = longer.project_direction(p).unwrap();
        assert!((q.x - 160.0 - 101.0).abs() < 1e-6, "{q}");
        let yawed = CameraCalibration {
            yaw_error: 0.5f64.to_radians(),
            ..Default::default()
        }
        .apply(&c)
        .unwrap();
        // The believed camera turned left (+y): the axis appears right of its centre.
        let axis = yawed.project_direction(-DVec3::Z).unwrap();
        let expected = 160.0 + 0.5f64.to_radians().tan() * 160.0 / 0.7f64.tan();
        assert!((axis.x - expected).abs() < 1e-6, "{axis}");
    }
}
