//! `--head estimated`: the eye from the back camera's image with the tracker the scene's face
//! calls for (`[camera.driver] face`, [`DriverFace`]). The ellipsoid face (das's) is found by
//! the frontal detector ([`detect`]) and placed by the paper's eqs. d1 and b_h, applied in a
//! virtual camera square to the face, whose orientation is known (it faces the vehicle's
//! forward), so that a back camera yawed or pitched on the display is corrected for
//! ([`eye_facing`]; the view angle it measures is a confidence cue); the head mesh, which a pillar camera sees turned, by the
//! side-angle detector ([`detect_turned`]) and the yaw fit ([`locate`]), whose eye, yaw and
//! margin are kept ([`HeadFix::pose`]) and whose cues score the confidence.

use glam::{DMat3, DVec2, DVec3};

use crate::geometry::camera::Camera;
use crate::render::footprint::PixelRect;
use crate::render::frame::Frame;
use crate::scene::DriverFace;
use crate::system::head::{DetectError, FaceDetection, detect, eye_facing};
use crate::system::head_pose::{HeadPose, locate};
use crate::system::head_side::detect_turned;

/// A head estimate: the eye and what it was found from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeadFix {
    /// The estimated eye (midpoint of the pupils), world frame, metres.
    pub eye: DVec3,
    /// The detection; for the mesh face its confidence includes the yaw fit's cues.
    pub detection: FaceDetection,
    /// The yaw fit (mesh face only): its eye is [`HeadFix::eye`].
    pub pose: Option<HeadPose>,
}

/// The detector the face calls for, on the whole of `frame` (8-bit sRGB as a camera delivers
/// it).
pub fn detect_face(face: DriverFace, frame: &Frame) -> Result<FaceDetection, DetectError> {
    match face {
        DriverFace::Ellipsoids => detect(frame),
        DriverFace::Mesh { .. } => detect_turned(frame),
    }
}

/// The eye of a detection of `face` through the believed back camera `back`; `feature_width`
/// is the interpupillary distance A, metres. `world_from_face` is the orientation the
/// ellipsoid face is expected to have (it looks down its −z, +y up): facing the vehicle's
/// forward, [`FACING_FORWARD`] in a scene as written (the mesh face's yaw is fitted instead).
pub fn fix_from(
    face: DriverFace,
    detection: FaceDetection,
    back: &Camera,
    feature_width: f64,
    world_from_face: DMat3,
) -> HeadFix {
    match face {
        DriverFace::Ellipsoids => {
            let facing = eye_facing(&detection, back, feature_width, world_from_face);
            HeadFix {
                eye: facing.eye,
                detection: FaceDetection {
                    confidence: detection.confidence.with_view(facing.view_angle_deg),
                    ..detection
                },
                pose: None,
            }
        }
        DriverFace::Mesh { .. } => {
            let (scored, pose) = locate(&detection, back, feature_width);
            HeadFix {
                eye: DVec3::from(pose.eye),
                detection: scored,
                pose: Some(pose),
            }
        }
    }
}

/// The ellipsoid face's expected orientation in a scene as written (at t = 0 of a sequence):
/// the vehicle drives along world −z, and the driver faces where it goes, upright.
pub const FACING_FORWARD: DMat3 = DMat3::IDENTITY;

/// [`detect_face`] then [`fix_from`], the face facing forward in the scene's world.
pub fn estimate(
    face: DriverFace,
    frame: &Frame,
    back: &Camera,
    feature_width: f64,
) -> Result<HeadFix, DetectError> {
    Ok(fix_from(
        face,
        detect_face(face, frame)?,
        back,
        feature_width,
        FACING_FORWARD,
    ))
}

/// The pixels [`detect_turned`] can have read for `detection` (a bound from its rules, with
/// margin): the face box grown by the pupil search box's eighth, the sclera radius (0.08
/// face widths) and the pupil centroid's rings; and the outline walks, 1.2 face widths plus
/// 2 px beyond each pupil along the pupils' line. A tracker that rendered only a region holding
/// this rectangle (the rest blank) gets the whole image's detection, bit for bit, unless a
/// skin region larger than the face lies wholly outside the region (`tests/head_use.rs`
/// compares both).
pub fn turned_reads(detection: &FaceDetection, camera: &Camera) -> PixelRect {
    let [x0, y0, x1, y1] = detection.face_box.map(f64::from);
    let (fw, fh) = (x1 - x0, y1 - y0);
    let grow = (fw.max(fh) / 8.0).max(2.0) + 0.08 * fw + 6.0;
    let (mut lo, mut hi) = (
        DVec2::new(x0, y0) - grow,
        DVec2::new(x1, y1) + DVec2::splat(grow),
    );
    let pupils = detection.pupils.map(DVec2::from);
    let along = (pupils[1] - pupils[0]).normalize_or(DVec2::X);
    let reach = 1.2 * fw + 4.0;
    for end in [pupils[0] - along * reach, pupils[1] + along * reach] {
        lo = lo.min(end - 2.0);
        hi = hi.max(end + 2.0);
    }
    let clamp = |v: f64, size: u32| v.clamp(0.0, f64::from(size)) as u32;
    PixelRect {
        x0: clamp(lo.x.floor(), camera.width),
        y0: clamp(lo.y.floor(), camera.height),
        x1: clamp(hi.x.ceil(), camera.width),
        y1: clamp(hi.y.ceil(), camera.height),
    }
}

/// The mesh face's true yaw from facing the back camera, degrees, in the convention of
/// [`HeadPose::yaw_deg`] (about the world's vertical; positive turns the face towards the
/// driver's left, −x): the face's yaw minus the yaw at which it would look from `eye` straight
/// at `camera` (both world, the scene's frame, where the face's yaw is given). `None` for the
/// ellipsoid face, which has no fitted yaw.
pub fn true_yaw_from_camera_deg(face: DriverFace, eye: DVec3, camera: DVec3) -> Option<f64> {
    let DriverFace::Mesh { yaw_deg } = face else {
        return None;
    };
    let to_camera = camera - eye;
    let facing = (-to_camera.x).atan2(-to_camera.z).to_degrees();
    Some(yaw_deg - facing)
}
