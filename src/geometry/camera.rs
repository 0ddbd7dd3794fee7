//! Cameras: pose, intrinsics, rays and projection.
//!
//! A camera looks down its local −z with +x right and +y up (the glTF convention). Pixel
//! coordinates are continuous: pixel `(i, j)` covers `[i, i+1) × [j, j+1)`, its centre is at
//! `(i + 0.5, j + 0.5)`, and `(0, 0)` is the top-left corner of the image. Without a lens a
//! camera is the ideal pinhole of its half angle with square pixels, centred; with a
//! [`Lens`] (OpenCV's intrinsics and distortion) rays and projections go through it.

use glam::{DAffine3, DMat3, DVec2, DVec3};

use crate::geometry::lens::Lens;
use crate::geometry::lens_check::{LensError, MAX_OFF_AXIS};
use crate::geometry::shutter::Shutter;

/// Largest angle between a point's ray and the ray its projection's pixel sees for the
/// projection to count as inside the lens's domain, radians (1e-7 rad is 0.0003′; Newton's
/// inverse agrees to ~1e-12 where the map is invertible).
const DOMAIN_ROUND_TRIP_RAD: f64 = 1e-7;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Rigid transform from camera space to world space (metres). Camera space: the camera
    /// looks down −z, +x is right, +y is up.
    pub world_from_camera: DAffine3,
    /// Horizontal half angle of view, in radians, in (0, π/2). The paper's θ. With a lens,
    /// that of the pinhole with the lens's fx: `atan(W / (2 fx))`.
    pub half_angle_x: f64,
    /// Image width in pixels, ≥ 1.
    pub width: u32,
    /// Image height in pixels, ≥ 1.
    pub height: u32,
    /// `None`: the ideal pinhole of `half_angle_x`. Otherwise the intrinsics and distortion
    /// (OpenCV's conventions, geometry/lens.rs) that rays and projections go through.
    pub lens: Option<Lens>,
    /// When its rows and samples see the world ([`Shutter::INSTANT`]: all at the frame's
    /// instant). Only a render in time (a moving camera or world) reads it.
    pub shutter: Shutter,
    /// `None`: the ideal sensor (the radiance as it is). Otherwise the EMVA 1288 sensor whose
    /// codes the camera delivers (geometry/sensor.rs): a frontal or back camera's.
    pub sensor: Option<crate::geometry::sensor::Sensor>,
}

/// Why a camera cannot be built.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraError {
    /// `look_at` equals the eye, or `up` is parallel to the viewing direction.
    DegenerateOrientation,
    HalfAngleOutOfRange(f64),
    Lens(LensError),
}

impl std::fmt::Display for CameraError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CameraError::DegenerateOrientation => write!(
                f,
                "viewing direction is zero or parallel to `up`; choose a look_at away from the eye and an up not along the view"
            ),
            CameraError::HalfAngleOutOfRange(a) => write!(
                f,
                "half angle of view must be in (0°, 90°), got {:.3}°",
                a.to_degrees()
            ),
            CameraError::Lens(e) => e.fmt(f),
        }
    }
}

/// Rotation whose columns are camera +x, +y, +z (= −forward) in world space.
pub fn world_from_camera_rotation(forward: DVec3, up: DVec3) -> Result<DMat3, CameraError> {
    let back = -forward.normalize_or_zero();
    let right = up.cross(back).normalize_or_zero();
    if back == DVec3::ZERO || right == DVec3::ZERO || !right.is_finite() {
        return Err(CameraError::DegenerateOrientation);
    }
    let true_up = back.cross(right);
    Ok(DMat3::from_cols(right, true_up, back))
}

impl std::error::Error for CameraError {}

impl Camera {
    pub fn new(
        world_from_camera: DAffine3,
        half_angle_x: f64,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        if !(half_angle_x > 0.0 && half_angle_x < std::f64::consts::FRAC_PI_2) {
            return Err(CameraError::HalfAngleOutOfRange(half_angle_x));
        }
        Ok(Self {
            world_from_camera,
            half_angle_x,
            width,
            height,
            lens: None,
            shutter: Shutter::INSTANT,
            sensor: None,
        })
    }

    /// A camera seeing through `lens` (checked on the image: no fold, less than a
    /// hemisphere, finite, focal lengths > 0).
    pub fn with_lens(
        world_from_camera: DAffine3,
        lens: Lens,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        lens.check(width, height).map_err(CameraError::Lens)?;
        Ok(Self {
            world_from_camera,
            half_angle_x: lens.equivalent_half_angle(width),
            width,
            height,
            lens: Some(lens),
            shutter: Shutter::INSTANT,
            sensor: None,
        })
    }

    /// The lens the camera sees through: its own, or the ideal pinhole's in OpenCV's terms.
    pub fn lens_or_pinhole(&self) -> Lens {
        self.lens
            .unwrap_or_else(|| Lens::pinhole(self.half_angle_x, self.width, self.height))
    }

    /// The same camera with the distortion removed (a pinhole with the lens's intrinsics):
    /// its projection of a plane into the image is a homography. Itself without a lens.
    pub fn undistorted(&self) -> Self {
        Self {
            lens: self.lens.map(|l| l.undistorted()),
            ..*self
        }
    }

    /// Where the ideal pinhole of `half_angle_x` (square pixels, centred) would see the ray
    /// that this camera sees at `pixel`: the input of eqs. d1 and b_h for a real lens.
    /// The identity without a lens.
    pub fn ideal_pixel(&self, pixel: DVec2) -> DVec2 {
        match self.lens {
            None => pixel,
            Some(_) => {
                let d = self.camera_direction(pixel);
                let ideal = Self {
                    lens: None,
                    ..*self
                };
                ideal.project_camera(d).unwrap_or(pixel)
            }
        }
    }

    /// A camera at `eye` looking towards `target`, with `up` as the approximate up direction.
    pub fn look_at(
        eye: DVec3,
        target: DVec3,
        up: DVec3,
        half_angle_x: f64,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        let rotation = world_from_camera_rotation(target - eye, up)?;
        Self::new(
            DAffine3::from_mat3_translation(rotation, eye),
            half_angle_x,
            width,
            height,
        )
    }

    pub fn with_resolution(mut self, width: u32, height: u32) -> Self {
        // A lens's pixel intrinsics scale with the image; its distortion does not.
        self.lens = self.lens.map(|l| {
            l.scaled(
                width as f64 / self.width as f64,
                height as f64 / self.height as f64,
            )
        });
        self.width = width;
        self.height = height;
        self
    }

    pub fn position(&self) -> DVec3 {
        self.world_from_camera.translation
    }

    /// Unit viewing direction (camera −z) in world space.
    pub fn forward(&self) -> DVec3 {
        -self.world_from_camera.matrix3.z_axis
    }

    pub fn tan_half_x(&self) -> f64 {
        self.half_angle_x.tan()
    }

    /// The angle the central pixel's width subtends at the eye, arc-minutes (the pinhole's
    /// widest pixel: pixels off the axis subtend less).
    pub fn central_pixel_arcmin(&self) -> f64 {
        (2.0 * self.tan_half_x() / self.width as f64)
            .atan()
            .to_degrees()
            * 60.0
    }

    /// Tangent of the vertical half angle (square pixels).
    pub fn tan_half_y(&self) -> f64 {
        self.tan_half_x() * self.height as f64 / self.width as f64
    }

    /// Camera-space direction (not normalised, z = −1) through continuous pixel coordinates.
    pub fn camera_direction(&self, pixel: DVec2) -> DVec3 {
        if let Some(lens) = &self.lens {
            return lens.camera_direction(pixel);
        }
        let ndc_x = 2.0 * pixel.x / self.width as f64 - 1.0;
        let ndc_y = 1.0 - 2.0 * pixel.y / self.height as f64;
        DVec3::new(ndc_x * self.tan_half_x(), ndc_y * self.tan_half_y(), -1.0)
    }

    /// World-space ray (origin, unit direction) through continuous pixel coordinates.
    pub fn world_ray(&self, pixel: DVec2) -> (DVec3, DVec3) {
        let dir = self
            .world_from_camera
            .transform_vector3(self.camera_direction(pixel))
            .normalize();
        (self.position(), dir)
    }

    /// Continuous pixel coordinates of a camera-space direction or point; `None` behind the camera.
    pub fn project_camera(&self, p: DVec3) -> Option<DVec2> {
        if let Some(lens) = &self.lens {
            return lens.project(p);
        }
        if p.z >= 0.0 {
            return None;
        }
        let x = p.x / -p.z / self.tan_half_x();
        let y = p.y / -p.z / self.tan_half_y();
        Some(DVec2::new(
            (x + 1.0) * 0.5 * self.width as f64,
            (1.0 - y) * 0.5 * self.height as f64,
        ))
    }

    /// [`Camera::project_camera`] where the lens's map can be trusted: `None` behind the
    /// camera, at [`MAX_OFF_AXIS`] or more off the axis, or where the forward map is not
    /// inverted by [`Camera::camera_direction`] (past a fold of the distortion, where a
    /// polynomial lens sends a far-off ray back into the image). The methods that project
    /// reconstructed 3-D points (ground, plane-fit, depth) call this, so that a point outside
    /// the lens's domain is a hole, never a wrong pixel. The same as `project_camera`
    /// without a lens.
    pub fn project_camera_in_domain(&self, p: DVec3) -> Option<DVec2> {
        let pixel = self.project_camera(p)?;
        if self.lens.is_none() {
            return Some(pixel);
        }
        let off_axis = DVec2::new(p.x, p.y).length().atan2(-p.z);
        if !(pixel.is_finite() && off_axis < MAX_OFF_AXIS) {
            return None;
        }
        // The round trip: the ray the image sees at `pixel` must be `p`'s. Newton's inverse
        // is exact to ~1e-15 inside the domain; a fold lands on another ray entirely.
        // atan2(|a × b|, a · b): exact at small angles, where acos loses half the digits.
        let (back, ray) = (self.camera_direction(pixel).normalize(), p.normalize());
        let disagreement = back.cross(ray).length().atan2(back.dot(ray));
        (disagreement < DOMAIN_ROUND_TRIP_RAD).then_some(pixel)
    }

    /// [`Camera::project_camera_in_domain`] of a world point.
    pub fn project_point_in_domain(&self, world: DVec3) -> Option<DVec2> {
        self.project_camera_in_domain(self.world_from_camera.inverse().transform_point3(world))
    }

    /// [`Camera::project_camera_in_domain`] of a world direction (a point at infinity).
    pub fn project_direction_in_domain(&self, world_dir: DVec3) -> Option<DVec2> {
        self.project_camera_in_domain(
            self.world_from_camera
                .inverse()
                .transform_vector3(world_dir),
        )
    }

    /// Pixel coordinates of a world point; `None` behind the camera. May fall outside the image.
    pub fn project_point(&self, world: DVec3) -> Option<DVec2> {
        self.project_camera(self.world_from_camera.inverse().transform_point3(world))
    }

    /// Pixel coordinates of the vanishing point of a world direction (a point at infinity).
    pub fn project_direction(&self, world_dir: DVec3) -> Option<DVec2> {
        self.project_camera(
            self.world_from_camera
                .inverse()
                .transform_vector3(world_dir),
        )
    }

    /// Depth along the camera's viewing axis (−z in camera space) of a world point, metres.
    pub fn axial_depth(&self, world: DVec3) -> f64 {
        -self.world_from_camera.inverse().transform_point3(world).z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn test_camera() -> Camera {
        Camera::look_at(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(-4.0, 0.5, -7.0),
            DVec3::Y,
            0.6,
            320,
            200,
        )
        .unwrap()
    }

    /// Against the angle between two traced rays a pixel apart at the centre, and more than
    /// that of any pixel nearer the edge.
    #[test]
    fn the_central_pixel_subtends_the_angle_between_its_edge_rays() {
        let cam = test_camera();
        let angle = |x: f64| {
            let y = cam.height as f64 / 2.0;
            let (_, a) = cam.world_ray(DVec2::new(x, y));
            let (_, b) = cam.world_ray(DVec2::new(x + 1.0, y));
            a.angle_between(b).to_degrees() * 60.0
        };
        let centre = angle(cam.width as f64 / 2.0);
        assert!((cam.central_pixel_arcmin() - centre).abs() < 1e-9 * centre);
        assert!(angle(10.0) < 0.9 * centre);
    }

    #[test]
    fn project_unproject_round_trip() {
        let cam = test_camera();
        for &(x, y) in &[(0.5, 0.5), (160.0, 100.0), (319.25, 3.75), (12.0, 199.9)] {
            let pixel = DVec2::new(x, y);
            let (origin, dir) = cam.world_ray(pixel);
            for distance in [0.1, 3.0, 250.0] {
                let back = cam.project_point(origin + dir * distance).unwrap();
                assert!((back - pixel).length() < 1e-9, "{pixel} -> {back}");
            }
            let back = cam.project_direction(dir).unwrap();
            assert!((back - pixel).length() < 1e-9);
        }
    }

    #[test]
    fn image_corners_span_the_half_angle() {
        let cam = test_camera();
        let left = cam.camera_direction(DVec2::new(0.0, 100.0));
        assert!((left.x.atan2(-left.z) + 0.6).abs() < 1e-12);
        let top = cam.camera_direction(DVec2::new(160.0, 0.0));
        let expected = (0.6f64.tan() * 200.0 / 320.0).atan();
        assert!((top.y.atan2(-top.z) - expected).abs() < 1e-12);
    }

    #[test]
    fn points_behind_do_not_project() {
        let cam = test_camera();
        let behind = cam.position() - cam.forward();
        assert_eq!(cam.project_point(behind), None);
        assert!((cam.axial_depth(cam.position() + 2.0 * cam.forward()) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_cameras_are_rejected() {
        let e = Camera::look_at(DVec3::ZERO, DVec3::ZERO, DVec3::Y, 0.5, 10, 10);
        assert_eq!(e, Err(CameraError::DegenerateOrientation));
        let e = Camera::look_at(DVec3::ZERO, DVec3::Y, DVec3::Y, 0.5, 10, 10);
        assert_eq!(e, Err(CameraError::DegenerateOrientation));
        let e = Camera::look_at(DVec3::ZERO, DVec3::X, DVec3::Y, 1.6, 10, 10);
        assert!(matches!(e, Err(CameraError::HalfAngleOutOfRange(_))));
    }

    #[test]
    fn a_point_past_a_fold_of_the_distortion_is_outside_the_lens_domain() {
        use crate::geometry::lens::{Distortion, Lens};
        // Brown k1 = −0.2: the radial map r (1 − 0.2 r²) rises to 0.86 at r = 1.29 and falls
        // after. The 120 × 80 image (fx = 100) reaches 0.72, inside the rise.
        let lens = Lens {
            fx: 100.0,
            fy: 100.0,
            cx: 59.5,
            cy: 39.5,
            distortion: Distortion::Brown {
                k1: -0.2,
                k2: 0.0,
                k3: 0.0,
                p1: 0.0,
                p2: 0.0,
            },
        };
        let camera = Camera::with_lens(DAffine3::IDENTITY, lens, 120, 80).unwrap();
        // r = 1.9 (62° off the axis) folds back to 0.53: 53 px right of the centre, inside
        // the image, where the lens sees another ray. Not in the domain.
        let folded = DVec3::new(1.9, 0.0, -1.0);
        let wrong = camera.project_camera(folded).unwrap();
        assert!((wrong.x - 60.0 - 52.9).abs() < 0.1, "{wrong}");
        assert_eq!(camera.project_camera_in_domain(folded), None);
        // Inside the rise, the projection itself.
        let inside = DVec3::new(0.5, -0.3, -1.0);
        assert_eq!(
            camera.project_camera_in_domain(inside),
            camera.project_camera(inside)
        );
        // Behind the camera, and without a lens the pinhole's projection bit for bit.
        assert_eq!(
            camera.project_camera_in_domain(DVec3::new(0.0, 0.0, 1.0)),
            None
        );
        let pinhole = test_camera();
        let p = DVec3::new(3.0, -1.0, -9.0);
        assert_eq!(pinhole.project_point_in_domain(p), pinhole.project_point(p));
    }
}
