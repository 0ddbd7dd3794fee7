//! The eye from a detection when the head is turned: eqs. d1 and b_h take the pupils' segment
//! as parallel to the back camera's image plane, so a head yawed by θ reads cos θ too narrow
//! and its eye 1/cos θ too far. Here the yaw is fitted instead, as a landmark tracker fits a
//! canonical face model: the shipped head's skin ([`skin_wireframe`]), turned about the world's
//! vertical and placed at the eye the yaw implies, must put its outline on the pupils' line
//! where the image has a colour step ([`FaceDetection::outline_candidates`]).
//!
//! For a trial yaw, the two pupil rays and the known interpupillary vector (horizontal, the
//! yaw's across direction) fix the eye (least squares, exact perspective, the calibrated back
//! camera's pose). The wireframe placed there is projected; its extreme crossings of the
//! pupils' line are the predicted outline, each side scored by its distance to the nearest
//! candidate, capped at 5% of the face's width so one missed edge (a shadowed cheek has no
//! colour step to the road) costs a bounded amount. The yaw is scanned in 1° steps over ±80°
//! about facing the camera, then refined by golden section. How much worse the best yaw 10° or
//! more away fits (`margin`) says whether the outline pinned the yaw down.

use glam::{DMat3, DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::scene::head_model::{HALF_IPD, skin_wireframe};
use crate::system::head::FaceDetection;

/// The detection scored with its fit ([`HeadConfidence::with_fit`]) and its fitted pose:
/// the eye is `pose.eye`. `eye_from_detection` in `system/head.rs` is the paper's frontal
/// equations alone.
///
/// [`HeadConfidence::with_fit`]: crate::system::head::HeadConfidence::with_fit
pub fn locate(
    detection: &FaceDetection,
    back: &Camera,
    feature_width: f64,
) -> (FaceDetection, HeadPose) {
    let pose = fit_head_pose(detection, back, feature_width);
    let scored = FaceDetection {
        confidence: detection
            .confidence
            .with_fit(pose.edge_rms_px, pose.yaw_deg, pose.margin),
        ..*detection
    };
    (scored, pose)
}

/// The fitted head: the eye, the yaw and how well (and how unambiguously) the outline fits.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HeadPose {
    /// The eye point (midpoint of the pupils), world frame, metres.
    pub eye: [f64; 3],
    /// Yaw of the face away from facing the back camera, about the world's vertical, degrees
    /// in [−80, 80]; positive turns the face towards the driver's left (world −x for a driver
    /// looking along −z).
    pub yaw_deg: f64,
    /// RMS of the two outline residuals at the fitted yaw (each capped at 5% of the face's
    /// width), back-camera pixels.
    pub edge_rms_px: f64,
    /// How much worse the best yaw at least 10° away fits: √(Δ mean squared residual) over the
    /// face's width, [0, 0.05]; near 0 the outline does not decide the yaw.
    pub margin: f64,
}

/// The search's half range about facing the camera, and the ambiguity test's distance, degrees.
const YAW_RANGE_DEG: i32 = 80;
const AMBIGUITY_DEG: f64 = 10.0;

/// Head frame → world for a yaw ψ about the world's +y (ψ = 0: the face looks along −z).
fn world_from_head(yaw: f64) -> DMat3 {
    DMat3::from_rotation_y(yaw)
}

/// The fitted pose of a detection; `feature_width` is A in metres.
pub fn fit_head_pose(detection: &FaceDetection, back: &Camera, feature_width: f64) -> HeadPose {
    let pin = back.undistorted();
    let camera_from_world = back.world_from_camera.inverse();
    let pupils = detection.pupils.map(|p| back.ideal_pixel(DVec2::from(p)));
    let origin = back.position();
    let rays = pupils.map(|p| {
        back.world_from_camera
            .transform_vector3(pin.camera_direction(p))
    });
    let along = (pupils[1] - pupils[0]).normalize_or(DVec2::X);
    let normal = DVec2::new(-along.y, along.x);
    let mid = (pupils[0] + pupils[1]) / 2.0;
    let measured: [Vec<f64>; 2] = [0, 1].map(|k| {
        detection.outline_candidates[k]
            .iter()
            .filter(|p| p[0].is_finite())
            .map(|p| (back.ideal_pixel(DVec2::from(*p)) - mid).dot(along))
            .collect()
    });
    let face_w = f64::from(detection.face_box[2] - detection.face_box[0]).max(1.0);
    let cap = (0.05 * face_w).max(1.5);
    let nearest = |k: usize, s: f64| {
        measured[k]
            .iter()
            .map(|m| (s - m).abs())
            .fold(cap, f64::min)
    };
    let (vertices, edges) = skin_wireframe(88, 60);
    let scale = feature_width / (2.0 * HALF_IPD);
    // The eye for a yaw: the points on the two pupil rays whose difference is the
    // interpupillary vector (image-left is the head's +x pupil), least squares.
    let eye_at = |yaw: f64| {
        let across = world_from_head(yaw) * DVec3::X * feature_width;
        let (a, b) = (rays[0], -rays[1]);
        let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
        let (ca, cb) = (a.dot(across), b.dot(across));
        let det = aa * bb - ab * ab;
        let s = (ca * bb - cb * ab) / det;
        let t = (aa * cb - ab * ca) / det;
        origin + (rays[0] * s + rays[1] * t) / 2.0
    };
    // The residuals of the predicted outline and the eye, for a yaw.
    let residuals = |yaw: f64| -> Option<(f64, f64, DVec3)> {
        let eye = eye_at(yaw);
        let rotation = world_from_head(yaw);
        let projected: Vec<Option<DVec2>> = vertices
            .iter()
            .map(|v| {
                pin.project_camera(
                    camera_from_world.transform_point3(eye + rotation * (*v * scale)),
                )
            })
            .collect();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for [i, j] in &edges {
            let (Some(p), Some(q)) = (projected[*i], projected[*j]) else {
                continue;
            };
            let (dp, dq) = ((p - mid).dot(normal), (q - mid).dot(normal));
            if (dp > 0.0) == (dq > 0.0) {
                continue;
            }
            let s = (p + (q - p) * (dp / (dp - dq)) - mid).dot(along);
            (lo, hi) = (lo.min(s), hi.max(s));
        }
        (lo <= hi).then(|| (nearest(0, lo), nearest(1, hi), eye))
    };
    let cost = |yaw: f64| residuals(yaw).map_or(f64::INFINITY, |(a, b, _)| a * a + b * b);
    // Facing the camera: the yaw whose −z axis points from the frontal eye at the camera.
    let to_camera = origin - eye_at(0.0);
    let facing = (-to_camera.x).atan2(-to_camera.z);
    let scan: Vec<(f64, f64)> = (-YAW_RANGE_DEG..=YAW_RANGE_DEG)
        .map(|k| {
            let yaw = facing + f64::from(k).to_radians();
            (yaw, cost(yaw))
        })
        .collect();
    let best = scan
        .iter()
        .fold(
            (facing, f64::INFINITY),
            |b, &s| if s.1 < b.1 { s } else { b },
        )
        .0;
    let step = 1f64.to_radians();
    let (mut a, mut b) = (best - step, best + step);
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..30 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if cost(c) < cost(d) {
            b = d;
        } else {
            a = c;
        }
    }
    let yaw = (a + b) / 2.0;
    let (r0, r1, eye) = residuals(yaw).unwrap_or((cap, cap, eye_at(yaw)));
    let best_cost = r0 * r0 + r1 * r1;
    let other = scan
        .iter()
        .filter(|s| (s.0 - yaw).abs() >= AMBIGUITY_DEG.to_radians())
        .map(|s| s.1)
        .fold(f64::INFINITY, f64::min);
    HeadPose {
        eye: eye.to_array(),
        yaw_deg: (yaw - facing).to_degrees(),
        edge_rms_px: (best_cost / 2.0).sqrt(),
        margin: (((other - best_cost) / 2.0).max(0.0).sqrt() / face_w).min(0.05),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::camera::Camera;

    /// A detection whose pupils and outline candidates are the exact projections of the head
    /// model at a known eye and yaw: the fit must return that eye and yaw.
    #[test]
    fn a_consistent_detection_is_fitted_back_to_its_pose() {
        let back = Camera::look_at(
            DVec3::new(1.05, 1.425, -0.75),
            DVec3::new(1.05, 1.425, 1.0),
            DVec3::Y,
            35f64.to_radians(),
            640,
            480,
        )
        .unwrap();
        let eye = DVec3::new(1.4, 1.2, 0.0);
        let to_camera = back.position() - eye;
        let facing = (-to_camera.x).atan2(-to_camera.z);
        for turn in [-30.0f64, 0.0, 20.0] {
            let yaw = facing + turn.to_radians();
            let r = world_from_head(yaw);
            let pupils = [1.0, -1.0].map(|s| {
                back.project_point(eye + r * DVec3::X * s * HALF_IPD)
                    .unwrap()
            });
            // The outline: the wireframe's extreme crossings of the pupils' line, as the fit
            // computes them, placed by brute force over a fine sampling of the line.
            let (vertices, edges) = skin_wireframe(88, 60);
            let along = (pupils[1] - pupils[0]).normalize();
            let normal = DVec2::new(-along.y, along.x);
            let mid = (pupils[0] + pupils[1]) / 2.0;
            let projected: Vec<DVec2> = vertices
                .iter()
                .map(|v| back.project_point(eye + r * *v).unwrap())
                .collect();
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for [i, j] in edges {
                let (p, q) = (projected[i], projected[j]);
                let (dp, dq) = ((p - mid).dot(normal), (q - mid).dot(normal));
                if (dp > 0.0) != (dq > 0.0) {
                    let s = (p + (q - p) * (dp / (dp - dq)) - mid).dot(along);
                    (lo, hi) = (lo.min(s), hi.max(s));
                }
            }
            let mut outline_candidates =
                [[[f64::NAN; 2]; crate::system::head::OUTLINE_CANDIDATES]; 2];
            outline_candidates[0][0] = (mid + along * lo).to_array();
            outline_candidates[1][0] = (mid + along * hi).to_array();
            // A decoy step inside the face on each side.
            outline_candidates[0][1] = (mid + along * lo * 0.6).to_array();
            outline_candidates[1][1] = (mid + along * hi * 0.6).to_array();
            let detection = FaceDetection {
                face_box: [80, 280, 180, 460],
                pupils: pupils.map(|p| p.to_array()),
                pupil_areas_px: [30, 30],
                row_edges: [[0.0; 2]; 2],
                outline_candidates,
                confidence: crate::system::head::HeadConfidence::of(
                    [80, 280, 180, 460],
                    pupils,
                    [30, 30],
                ),
            };
            let pose = fit_head_pose(&detection, &back, 2.0 * HALF_IPD);
            let error = (DVec3::from(pose.eye) - eye).length();
            assert!(error < 2e-3, "turn {turn}: eye {error} m off");
            assert!(
                (pose.yaw_deg - turn).abs() < 1.0,
                "turn {turn}: fitted {}",
                pose.yaw_deg
            );
            assert!(pose.edge_rms_px < 0.2, "{pose:?}");
        }
    }
}
