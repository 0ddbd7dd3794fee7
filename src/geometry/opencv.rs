//! A camera in OpenCV's terms, for files that other tools read (`calibration.json`, run.json's
//! `calibration`): the intrinsic matrix K, the distortion model and its coefficients in
//! OpenCV's order, the image size, and the pose both as `world_from_camera` (4×4, OpenCV's
//! camera axes: +x right, +y down, +z forward) and as OpenCV's extrinsics `rvec`/`tvec`
//! (`x_camera = R(rvec) · x_world + tvec`, as `cv::projectPoints` takes them).
//!
//! seethru's camera looks down −z with +y up (geometry/camera.rs); OpenCV's camera frame is
//! seethru's turned half a turn about +x: (x, y, z)_cv = (x, −y, −z). OpenCV's pixel centres
//! are at integers, seethru's at +0.5 (geometry/lens.rs).

use glam::{DAffine3, DMat3, DMat4, DQuat, DVec3};
use serde_json::{Value, json};

use crate::geometry::camera::Camera;
use crate::geometry::lens::Distortion;

/// seethru's camera axes expressed in OpenCV's (and back: it is its own inverse).
pub const CV_FROM_SEETHRU_CAMERA: DMat3 = DMat3::from_cols(
    DVec3::new(1.0, 0.0, 0.0),
    DVec3::new(0.0, -1.0, 0.0),
    DVec3::new(0.0, 0.0, -1.0),
);

/// Rigid transform from OpenCV's camera frame to the world, metres.
pub fn world_from_cv_camera(camera: &Camera) -> DAffine3 {
    camera.world_from_camera * DAffine3::from_mat3(CV_FROM_SEETHRU_CAMERA)
}

/// A 4×4 row-major matrix of a rigid transform.
pub fn rows_4x4(t: DAffine3) -> [[f64; 4]; 4] {
    let m = DMat4::from(t).transpose();
    [
        m.x_axis.to_array(),
        m.y_axis.to_array(),
        m.z_axis.to_array(),
        m.w_axis.to_array(),
    ]
}

/// A 3×3 row-major matrix.
pub fn rows_3x3(m: DMat3) -> [[f64; 3]; 3] {
    let t = m.transpose();
    [
        t.x_axis.to_array(),
        t.y_axis.to_array(),
        t.z_axis.to_array(),
    ]
}

/// OpenCV's Rodrigues vector of a rotation: its axis times its angle, radians.
pub fn rodrigues(rotation: DMat3) -> DVec3 {
    let (axis, angle) = DQuat::from_mat3(&rotation).normalize().to_axis_angle();
    // glam gives an angle in [0, 2π); OpenCV's is in [0, π].
    if angle > std::f64::consts::PI {
        -axis * (2.0 * std::f64::consts::PI - angle)
    } else {
        axis * angle
    }
}

/// OpenCV's distortion model name and its coefficient vector in OpenCV's order: `pinhole`
/// (none), `opencv` (`cv::projectPoints`: k1, k2, p1, p2, k3) or `fisheye` (`cv::fisheye`:
/// k1, k2, k3, k4).
pub fn distortion_json(distortion: &Distortion) -> (&'static str, Vec<f64>) {
    match *distortion {
        Distortion::None => ("pinhole", vec![0.0; 5]),
        Distortion::Brown { k1, k2, k3, p1, p2 } => ("opencv", vec![k1, k2, p1, p2, k3]),
        Distortion::Fisheye { k1, k2, k3, k4 } => ("fisheye", vec![k1, k2, k3, k4]),
    }
}

/// One camera in OpenCV's conventions, at its own resolution.
pub fn camera_json(camera: &Camera) -> Value {
    let lens = camera.lens_or_pinhole();
    let k = DMat3::from_cols(
        DVec3::new(lens.fx, 0.0, 0.0),
        DVec3::new(0.0, lens.fy, 0.0),
        DVec3::new(lens.cx, lens.cy, 1.0),
    );
    let (model, coefficients) = distortion_json(&lens.distortion);
    let world_from_camera = world_from_cv_camera(camera);
    let camera_from_world = world_from_camera.inverse();
    json!({
        "image_size": [camera.width, camera.height],
        "K": rows_3x3(k),
        "distortion_model": model,
        "distortion_coefficients": coefficients,
        "world_from_camera": rows_4x4(world_from_camera),
        "rvec": rodrigues(camera_from_world.matrix3).to_array(),
        "tvec": camera_from_world.translation.to_array(),
        "position_world_m": camera.position().to_array(),
        "forward_world": camera.forward().to_array(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    /// K, rvec and tvec project a world point where the camera does (OpenCV's pixel = seethru's
    /// − 0.5), for a tilted camera: the convention is the one `cv::projectPoints` applies.
    #[test]
    fn k_rvec_tvec_project_as_the_camera_does() {
        let camera = Camera::look_at(
            DVec3::new(0.3, 1.2, -0.4),
            DVec3::new(2.0, 0.5, -6.0),
            DVec3::new(0.1, 1.0, 0.0),
            0.6,
            320,
            200,
        )
        .unwrap();
        let j = camera_json(&camera);
        let v = |key: &str| -> DVec3 {
            let a: Vec<f64> = serde_json::from_value(j[key].clone()).unwrap();
            DVec3::new(a[0], a[1], a[2])
        };
        let (rvec, tvec) = (v("rvec"), v("tvec"));
        let k: [[f64; 3]; 3] = serde_json::from_value(j["K"].clone()).unwrap();
        let world = DVec3::new(1.5, 0.2, -5.0);
        // Rodrigues by its own formula, not through the quaternion the code uses.
        let angle = rvec.length();
        let axis = rvec / angle;
        let rotate = |p: DVec3| {
            p * angle.cos() + axis.cross(p) * angle.sin() + axis * axis.dot(p) * (1.0 - angle.cos())
        };
        let c = rotate(world) + tvec;
        let u = k[0][0] * c.x / c.z + k[0][2];
        let v = k[1][1] * c.y / c.z + k[1][2];
        let expected = camera.project_point(world).unwrap() - DVec2::splat(0.5);
        assert!((u - expected.x).abs() < 1e-9 && (v - expected.y).abs() < 1e-9);
        // world_from_camera maps OpenCV's camera origin and +z to the position and forward.
        let m: [[f64; 4]; 4] = serde_json::from_value(j["world_from_camera"].clone()).unwrap();
        let forward = DVec3::new(m[0][2], m[1][2], m[2][2]);
        assert!(forward.abs_diff_eq(camera.forward(), 1e-12));
        assert!(DVec3::new(m[0][3], m[1][3], m[2][3]).abs_diff_eq(camera.position(), 1e-12));
    }
}
