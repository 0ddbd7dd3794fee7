//! The eye from a detection when the head is turned: eqs. d1 and b_h take the pupils' segment
//! as parallel to the back camera's image plane, so a head yawed by θ reads cos θ too narrow
//! and its eye 1/cos θ too far. Here the yaw is fitted instead, from where the pupils sit
//! between the head's edges on their row, against the shipped head's outline at eye height
//! ([`eye_row_section`]), as a landmark tracker fits a canonical face model.
//!
//! For a trial yaw, the two pupil rays and the known interpupillary vector fix the eye
//! (least squares, exact perspective); the head's outline placed there and projected gives
//! its two edges. The yaw whose edges match the measured ones is kept (a scan in 1° steps,
//! then a golden-section refinement).

use glam::{DMat3, DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::scene::head_model::eye_row_section;
use crate::system::head::FaceDetection;

/// The detection scored with its fit ([`HeadConfidence::with_fit`]) and its fitted pose:
/// what `--head estimated` uses (the eye is `pose.eye`). `eye_from_detection` in
/// `system/head.rs` is the paper's frontal equations alone.
pub fn locate(
    detection: &FaceDetection,
    back: &Camera,
    feature_width: f64,
) -> (FaceDetection, HeadPose) {
    let pose = fit_head_pose(detection, back, feature_width);
    let scored = FaceDetection {
        confidence: detection.confidence.with_fit(
            pose.edge_rms_px,
            pose.yaw_deg,
            pose.expected_area_ratio,
        ),
        ..*detection
    };
    (scored, pose)
}

/// The fitted head: the eye, the yaw and how well the outline fits.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HeadPose {
    /// The eye point (midpoint of the pupils), world frame, metres.
    pub eye: [f64; 3],
    /// Yaw of the face away from facing the back camera, about the camera's vertical axis,
    /// degrees in [−75, 75]; positive turns the face towards the camera's −x.
    pub yaw_deg: f64,
    /// RMS of the two edges' residuals at the fitted yaw, back-camera pixels.
    pub edge_rms_px: f64,
    /// The smaller over the larger iris's foreshortening (cosine between the face's forward
    /// direction and each eye's ray to the camera) at the fitted pose, (0, 1]: the pupil blobs'
    /// area ratio to expect.
    pub expected_area_ratio: f64,
}

/// Limits of the yaw search, degrees.
const YAW_LIMIT_DEG: f64 = 75.0;

/// The camera-frame ray through an ideal (pinhole) pixel; −z is the viewing axis.
fn ray(back: &Camera, pixel: DVec2) -> DVec3 {
    let f = back.width as f64 / 2.0 / back.half_angle_x.tan();
    DVec3::new(
        (pixel.x - back.width as f64 / 2.0) / f,
        (back.height as f64 / 2.0 - pixel.y) / f,
        -1.0,
    )
}

fn project(back: &Camera, p: DVec3) -> DVec2 {
    let f = back.width as f64 / 2.0 / back.half_angle_x.tan();
    DVec2::new(
        back.width as f64 / 2.0 + f * p.x / -p.z,
        back.height as f64 / 2.0 - f * p.y / -p.z,
    )
}

/// Head frame → camera frame for a yaw θ: at θ = 0 the face (head −z) looks along the
/// camera's +z, towards it.
fn camera_from_head(yaw: f64) -> DMat3 {
    DMat3::from_rotation_y(yaw + std::f64::consts::PI)
}

/// The eye (camera frame) for a yaw: the points on the two pupil rays whose difference is
/// the interpupillary vector, in the least-squares sense; `rays[0]` is the image-left pupil.
fn eye_at(yaw: f64, rays: [DVec3; 2], feature_width: f64) -> DVec3 {
    // Image-left is camera −x: the head's +x pupil at θ = 0.
    let across = camera_from_head(yaw) * DVec3::X * feature_width;
    // s r0 − t r1 = across.
    let (a, b) = (rays[0], -rays[1]);
    let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
    let (ca, cb) = (a.dot(across), b.dot(across));
    let det = aa * bb - ab * ab;
    let s = (ca * bb - cb * ab) / det;
    let t = (aa * cb - ab * ca) / det;
    (rays[0] * s + rays[1] * t) / 2.0
}

/// The fitted pose of a detection with its measured `edges` (ideal-pixel x of the head's left
/// and right edge along the pupils' row); `feature_width` is A in metres.
pub fn fit_head_pose(detection: &FaceDetection, back: &Camera, feature_width: f64) -> HeadPose {
    let pupils = detection.pupils.map(|p| back.ideal_pixel(DVec2::from(p)));
    let edges = detection
        .row_edges
        .map(|p| back.ideal_pixel(DVec2::from(p)));
    let rays = pupils.map(|p| ray(back, p));
    let section = eye_row_section(120);
    let scale = feature_width / (2.0 * crate::scene::head_model::HALF_IPD);
    let residuals = |yaw: f64| -> (f64, f64, DVec3) {
        let eye = eye_at(yaw, rays, feature_width);
        let rotation = camera_from_head(yaw);
        let along = (pupils[1] - pupils[0]).normalize_or(DVec2::X);
        let mid = (pupils[0] + pupils[1]) / 2.0;
        // The edges' positions along the pupils' line, relative to their midpoint.
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for h in &section {
            let p = project(back, eye + rotation * (*h * scale));
            let s = (p - mid).dot(along);
            (lo, hi) = (lo.min(s), hi.max(s));
        }
        let measured = edges.map(|e| (e - mid).dot(along));
        (lo - measured[0], hi - measured[1], eye)
    };
    let cost = |yaw: f64| {
        let (a, b, _) = residuals(yaw);
        a * a + b * b
    };
    let limit = YAW_LIMIT_DEG.to_radians();
    let step = 1f64.to_radians();
    let mut best = 0.0;
    let mut best_cost = f64::INFINITY;
    let mut yaw = -limit;
    while yaw <= limit + 1e-12 {
        let c = cost(yaw);
        if c < best_cost {
            (best, best_cost) = (yaw, c);
        }
        yaw += step;
    }
    // Golden-section search within a step either side.
    let (mut a, mut b) = ((best - step).max(-limit), (best + step).min(limit));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..40 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if cost(c) < cost(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let yaw = (a + b) / 2.0;
    let (r0, r1, eye) = residuals(yaw);
    let forward = camera_from_head(yaw) * DVec3::NEG_Z;
    let across = camera_from_head(yaw) * DVec3::X * (feature_width / 2.0);
    let seen = [eye + across, eye - across].map(|p| forward.dot(-p.normalize()).max(1e-3));
    HeadPose {
        eye: back.world_from_camera.transform_point3(eye).to_array(),
        yaw_deg: yaw.to_degrees(),
        edge_rms_px: ((r0 * r0 + r1 * r1) / 2.0).sqrt(),
        expected_area_ratio: seen[0].min(seen[1]) / seen[0].max(seen[1]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_eye_from_two_rays_is_exact_for_a_consistent_pair() {
        // A pair of pupils at a known eye and yaw, projected and solved back.
        let (yaw, a) = (0.5f64, 0.064);
        let eye = DVec3::new(0.05, -0.02, -0.7);
        let across = camera_from_head(yaw) * DVec3::X * a;
        let (p0, p1) = (eye + across / 2.0, eye - across / 2.0);
        let rays = [p0 / -p0.z, p1 / -p1.z];
        let got = eye_at(yaw, rays, a);
        assert!((got - eye).length() < 1e-12, "{got}");
        // With the yaw taken as 0 the eye comes out elsewhere (farther, the pair reads narrow).
        assert!(eye_at(0.0, rays, a).z < eye.z - 0.05);
    }
}
