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
        confidence: detection.confidence.with_fit(
            pose.edge_rms_px,
            pose.yaw_deg,
            pose.margin,
            detection.pupil_areas_px[0].min(detection.pupil_areas_px[1]),
        ),
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
    /// The same yaw about the world's vertical, degrees in (−180, 180]: 0 when the face looks
    /// along the world's −z, positive towards −x (the rotation `rotate_deg = [0, yaw, 0]`).
    pub world_yaw_deg: f64,
    /// RMS of the two outline residuals at the fitted yaw (each capped at 5% of the face's
    /// width), back-camera pixels.
    pub edge_rms_px: f64,
    /// How much worse the best yaw at least 10° away fits: √(Δ mean squared residual) over the
    /// face's width, [0, 0.05]; near 0 the outline does not decide the yaw.
    pub margin: f64,
}

/// The search's half range about facing the camera, its coarse step, and the ambiguity
/// test's distance, degrees.
const YAW_RANGE_DEG: i32 = 80;
const COARSE_STEP_DEG: i32 = 2;
const AMBIGUITY_DEG: f64 = 10.0;

/// Head frame → world for a yaw ψ about the world's +y (ψ = 0: the face looks along −z).
fn world_from_head(yaw: f64) -> DMat3 {
    DMat3::from_rotation_y(yaw)
}

/// The skin's wireframe (`skin_wireframe`), built once: `coarse` for the yaw scan, `fine`
/// for the refinement and the fitted outline.
struct Wireframes {
    coarse: Wireframe,
    fine: Wireframe,
}

struct Wireframe {
    /// Head frame, metres (the shipped head's size).
    vertices: Vec<DVec3>,
    edges: Vec<[u32; 2]>,
}

impl Wireframe {
    fn new(columns: usize, rows: usize) -> Self {
        let (vertices, edges) = skin_wireframe(columns, rows);
        Wireframe {
            vertices,
            edges: edges.iter().map(|e| e.map(|i| i as u32)).collect(),
        }
    }
}

/// Builds what every fit shares, once per process: the head's wireframes and the sRGB
/// encoding table of `detect_turned` (tens of ms; otherwise the first frame pays it).
pub fn prepare_fit() {
    wireframes();
    crate::util::color::encode_srgb8(glam::Vec3::ZERO);
}

fn wireframes() -> &'static Wireframes {
    static WIREFRAMES: std::sync::OnceLock<Wireframes> = std::sync::OnceLock::new();
    WIREFRAMES.get_or_init(|| Wireframes {
        coarse: Wireframe::new(44, 30),
        fine: Wireframe::new(88, 60),
    })
}

/// What a fit knows of the detection: the pupils' rays and the plane they span with the
/// camera's centre (its image is the pupils' line), the outline candidates along that line.
struct Fit<'a> {
    back: &'a Camera,
    camera_from_world: glam::DAffine3,
    origin: DVec3,
    rays: [DVec3; 2],
    /// The plane through the camera's centre and both pupils: its unit normal, and two unit
    /// vectors in it, `forward` between the rays and `across` towards the right pupil's ray;
    /// across/forward is monotone along the pupils' image line.
    normal: DVec3,
    forward: DVec3,
    across: DVec3,
    /// The pupils' image line: midpoint and direction (ideal pixels).
    mid: DVec2,
    along: DVec2,
    /// Outline candidates along the line from `mid`, left and right, ideal pixels.
    measured: [Vec<f64>; 2],
    cap: f64,
    feature_width: f64,
    /// Head model metres → metres for this feature width.
    scale: f64,
}

impl Fit<'_> {
    /// The eye for a yaw: the points on the two pupil rays whose difference is the
    /// interpupillary vector (image-left is the head's +x pupil), least squares.
    fn eye_at(&self, yaw: f64) -> DVec3 {
        let across = world_from_head(yaw) * DVec3::X * self.feature_width;
        let (a, b) = (self.rays[0], -self.rays[1]);
        let (aa, ab, bb) = (a.dot(a), a.dot(b), b.dot(b));
        let (ca, cb) = (a.dot(across), b.dot(across));
        let det = aa * bb - ab * ab;
        let s = (ca * bb - cb * ab) / det;
        let t = (aa * cb - ab * ca) / det;
        self.origin + (self.rays[0] * s + self.rays[1] * t) / 2.0
    }

    /// The predicted outline for a yaw: where the wireframe placed at the yaw's eye crosses
    /// the pupils' plane farthest to either side (in front of the camera), as positions along
    /// the pupils' image line; and that eye. The crossings are found in the head's frame (the
    /// plane moved into it), so only the two extreme points are projected.
    fn outline(
        &self,
        wire: &Wireframe,
        yaw: f64,
        distance: &mut Vec<f64>,
    ) -> Option<(f64, f64, DVec3)> {
        let eye = self.eye_at(yaw);
        let rotation = world_from_head(yaw);
        let to_head = |v: DVec3| rotation.transpose() * v * self.scale;
        let offset = eye - self.origin;
        let (n, n0) = (to_head(self.normal), self.normal.dot(offset));
        let (f, f0) = (to_head(self.forward), self.forward.dot(offset));
        let (u, u0) = (to_head(self.across), self.across.dot(offset));
        distance.clear();
        distance.extend(wire.vertices.iter().map(|v| n.dot(*v) + n0));
        let (mut lo, mut hi) = (
            (f64::INFINITY, DVec3::ZERO),
            (f64::NEG_INFINITY, DVec3::ZERO),
        );
        for &[i, j] in &wire.edges {
            let (di, dj) = (distance[i as usize], distance[j as usize]);
            if (di > 0.0) == (dj > 0.0) {
                continue;
            }
            let (vi, vj) = (wire.vertices[i as usize], wire.vertices[j as usize]);
            let x = vi + (vj - vi) * (di / (di - dj));
            let depth = f.dot(x) + f0;
            if depth <= 0.0 {
                continue;
            }
            let t = (u.dot(x) + u0) / depth;
            if t < lo.0 {
                lo = (t, x);
            }
            if t > hi.0 {
                hi = (t, x);
            }
        }
        if lo.0 > hi.0 {
            return None;
        }
        let pin = self.back.undistorted();
        let on_line = |x: DVec3| {
            let world = eye + rotation * (x * self.scale);
            pin.project_camera(self.camera_from_world.transform_point3(world))
                .map(|p| (p - self.mid).dot(self.along))
        };
        Some((on_line(lo.1)?, on_line(hi.1)?, eye))
    }

    /// Distance of a predicted outline position to the nearest candidate, capped.
    fn nearest(&self, side: usize, s: f64) -> f64 {
        self.measured[side]
            .iter()
            .map(|m| (s - m).abs())
            .fold(self.cap, f64::min)
    }

    /// The squared residuals' sum for a yaw, and the residuals and eye.
    fn cost(&self, wire: &Wireframe, yaw: f64, distance: &mut Vec<f64>) -> (f64, f64, f64, DVec3) {
        match self.outline(wire, yaw, distance) {
            Some((lo, hi, eye)) => {
                let (a, b) = (self.nearest(0, lo), self.nearest(1, hi));
                (a * a + b * b, a, b, eye)
            }
            None => (f64::INFINITY, self.cap, self.cap, self.eye_at(yaw)),
        }
    }
}

/// Steps of the golden section: the bracket of two coarse steps (4°) shrinks by 0.618 a step,
/// to 4° × 0.618^24 ≈ 4e-5°.
const GOLDEN_STEPS: usize = 24;

/// The minimum of `f` in [`a`, `b`] by golden-section search, for `f` unimodal there: each of
/// `steps` steps keeps the part of the bracket around the lower of two inner points (at
/// 0.382 and 0.618 of it) and evaluates `f` once, at the new inner point. Returns the final
/// bracket's midpoint, within (b − a) · 0.618^`steps` / 2 of the minimum.
fn golden_section_min(mut a: f64, mut b: f64, steps: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..steps {
        if fc < fd {
            (b, d, fd) = (d, c, fc);
            c = b - g * (b - a);
            fc = f(c);
        } else {
            (a, c, fc) = (c, d, fd);
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    (a + b) / 2.0
}

/// The fitted pose of a detection; `feature_width` is A in metres.
///
/// The yaw is scanned over ±80° about facing the camera in 2° steps on a coarse wireframe
/// (44 × 30 quads), then refined by golden section within ±2° of the best on the fine one
/// (88 × 60); the margin compares the scan's best yaw at least 10° away.
pub fn fit_head_pose(detection: &FaceDetection, back: &Camera, feature_width: f64) -> HeadPose {
    let pin = back.undistorted();
    let pupils = detection.pupils.map(|p| back.ideal_pixel(DVec2::from(p)));
    let origin = back.position();
    let rays = pupils.map(|p| {
        back.world_from_camera
            .transform_vector3(pin.camera_direction(p))
    });
    let along = (pupils[1] - pupils[0]).normalize_or(DVec2::X);
    let mid = (pupils[0] + pupils[1]) / 2.0;
    let normal = rays[0].cross(rays[1]).normalize_or(DVec3::Y);
    let forward =
        (rays[0].normalize_or_zero() + rays[1].normalize_or_zero()).normalize_or(DVec3::NEG_Z);
    // From pupil 0's ray toward pupil 1's, with no test needed: (r0 × r1) × f = r1 (r0·f) −
    // r0 (r1·f), so across·r1 − across·r0 = (r0·f)(|r1|² − r0·r1) + (r1·f)(|r0|² − r0·r1),
    // which is cos(θ/2)|r0||r1|(|r0| + |r1|)(1 − cos θ) > 0 for the unit bisector f of two
    // rays θ < 180° apart (r·f = |r| cos(θ/2)).
    let across = normal.cross(forward).normalize_or(DVec3::X);
    let measured: [Vec<f64>; 2] = [0, 1].map(|k| {
        detection.outline_candidates[k]
            .iter()
            .filter(|p| p[0].is_finite())
            .map(|p| (back.ideal_pixel(DVec2::from(*p)) - mid).dot(along))
            .collect()
    });
    let face_w = f64::from(detection.face_box[2] - detection.face_box[0]).max(1.0);
    let fit = Fit {
        back,
        camera_from_world: back.world_from_camera.inverse(),
        origin,
        rays,
        normal,
        forward,
        across,
        mid,
        along,
        measured,
        cap: (0.05 * face_w).max(1.5),
        feature_width,
        scale: feature_width / (2.0 * HALF_IPD),
    };
    let Wireframes { coarse, fine } = wireframes();
    let mut distance = Vec::with_capacity(fine.vertices.len());
    // Facing the camera: the yaw whose −z axis points from the frontal eye at the camera.
    let to_camera = origin - fit.eye_at(0.0);
    let facing = (-to_camera.x).atan2(-to_camera.z);
    let scan: Vec<(f64, f64)> = (-YAW_RANGE_DEG / COARSE_STEP_DEG
        ..=YAW_RANGE_DEG / COARSE_STEP_DEG)
        .map(|k| {
            let yaw = facing + f64::from(k * COARSE_STEP_DEG).to_radians();
            (yaw, fit.cost(coarse, yaw, &mut distance).0)
        })
        .collect();
    let best = scan
        .iter()
        .fold(
            (facing, f64::INFINITY),
            |b, &s| if s.1 < b.1 { s } else { b },
        )
        .0;
    // The fine wireframe's minimum within a coarse step of the scan's best.
    let step = f64::from(COARSE_STEP_DEG).to_radians();
    let yaw = golden_section_min(best - step, best + step, GOLDEN_STEPS, |yaw| {
        fit.cost(fine, yaw, &mut distance).0
    });
    let (best_cost, _, _, eye) = fit.cost(fine, yaw, &mut distance);
    let best_cost = best_cost.min(2.0 * fit.cap * fit.cap);
    let other = scan
        .iter()
        .filter(|s| (s.0 - yaw).abs() >= AMBIGUITY_DEG.to_radians())
        .map(|s| s.1)
        .fold(f64::INFINITY, f64::min);
    HeadPose {
        eye: eye.to_array(),
        yaw_deg: (yaw - facing).to_degrees(),
        world_yaw_deg: yaw.to_degrees(),
        edge_rms_px: (best_cost / 2.0).sqrt(),
        margin: (((other - best_cost) / 2.0).max(0.0).sqrt() / face_w).min(0.05),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::camera::Camera;

    /// The golden section finds the minimum of unimodal functions within its documented
    /// bound, (b − a) · 0.618^steps / 2, wherever the minimum lies in the bracket (near
    /// either end, at an end, off centre on an asymmetric function), with one evaluation
    /// per step beyond the first two.
    #[test]
    fn the_golden_section_finds_a_minimum_within_its_shrunken_bracket() {
        let g = (5f64.sqrt() - 1.0) / 2.0;
        // Name, bracket [a, b], where the minimum lies, the function.
        type Case = (&'static str, f64, f64, f64, fn(f64) -> f64);
        let cases: [Case; 6] = [
            ("parabola at 0.3", 0.0, 1.0, 0.3, |x| (x - 0.3) * (x - 0.3)),
            ("parabola at 0.93", 0.0, 1.0, 0.93, |x| {
                (x - 0.93) * (x - 0.93)
            }),
            ("parabola at -0.71", -1.0, 1.0, -0.71, |x| {
                (x + 0.71) * (x + 0.71)
            }),
            ("exp(x) − 3x at ln 3", 0.0, 2.0, 3f64.ln(), |x| {
                x.exp() - 3.0 * x
            }),
            ("rising: at its left end", 2.0, 5.0, 2.0, |x| x * x),
            ("falling: at its right end", -4.0, -1.0, -1.0, |x| x * x),
        ];
        for (name, a, b, at, f) in cases {
            for steps in [8, 24] {
                let mut calls = 0;
                let found = golden_section_min(a, b, steps, |x| {
                    calls += 1;
                    assert!((a..=b).contains(&x), "{name}: evaluated at {x} outside");
                    f(x)
                });
                let bound = (b - a) * g.powi(steps as i32) / 2.0;
                assert!(
                    (found - at).abs() <= bound * (1.0 + 1e-9),
                    "{name}, {steps} steps: {found} against {at} (bound {bound:e})"
                );
                assert_eq!(calls, steps + 2, "{name}");
            }
        }
    }

    /// The back camera and eye of the fit's tests: das's, with the face 0.75 m before the camera.
    fn back_and_eye() -> (Camera, DVec3) {
        let back = Camera::look_at(
            DVec3::new(1.05, 1.425, -0.75),
            DVec3::new(1.05, 1.425, 1.0),
            DVec3::Y,
            35f64.to_radians(),
            640,
            480,
        )
        .unwrap();
        (back, DVec3::new(1.4, 1.2, 0.0))
    }

    /// A detection whose pupils and outline candidates are the exact projections of the head
    /// model (its interpupillary distance `width`, metres) with its eye at `eye`, turned by
    /// `turn` degrees from facing `back`, its outline edges then moved `outward` pixels
    /// away from the face along the pupils' line.
    fn consistent_detection(
        back: &Camera,
        eye: DVec3,
        turn: f64,
        width: f64,
        outward: f64,
    ) -> FaceDetection {
        let to_camera = back.position() - eye;
        let facing = (-to_camera.x).atan2(-to_camera.z);
        let scale = width / (2.0 * HALF_IPD);
        let yaw = facing + turn.to_radians();
        // The scene's rotation convention (what the renderer turns the mesh by).
        let r = crate::scene::head_model::head_rotation(yaw.to_degrees(), 0.0);
        let pupils = [1.0, -1.0].map(|s| {
            back.project_point(eye + r * DVec3::X * s * HALF_IPD * scale)
                .unwrap()
        });
        // The outline, by brute force: every vertex of the fine wireframe projected, the
        // extreme crossings of the projected edges with the pupils' image line (the fit
        // intersects the pupils' plane in the head's frame instead and projects two points).
        let (vertices, edges) = skin_wireframe(88, 60);
        let along = (pupils[1] - pupils[0]).normalize();
        let normal = DVec2::new(-along.y, along.x);
        let mid = (pupils[0] + pupils[1]) / 2.0;
        let projected: Vec<DVec2> = vertices
            .iter()
            .map(|v| back.project_point(eye + r * *v * scale).unwrap())
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
        let mut outline_candidates = [[[f64::NAN; 2]; crate::system::head::OUTLINE_CANDIDATES]; 2];
        outline_candidates[0][0] = (mid + along * (lo - outward)).to_array();
        outline_candidates[1][0] = (mid + along * (hi + outward)).to_array();
        // A decoy step inside the face on each side.
        outline_candidates[0][1] = (mid + along * lo * 0.6).to_array();
        outline_candidates[1][1] = (mid + along * hi * 0.6).to_array();
        FaceDetection {
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
        }
    }

    /// A detection whose pupils and outline candidates are the exact projections of the head
    /// model at a known eye and yaw: the fit must return that eye and yaw.
    #[test]
    fn a_consistent_detection_is_fitted_back_to_its_pose() {
        let (back, eye) = back_and_eye();
        // The shipped head's interpupillary distance, and a wider face (the head scaled).
        for (turn, width) in [
            (-30.0f64, 2.0 * HALF_IPD),
            (0.0, 2.0 * HALF_IPD),
            (20.0, 2.0 * HALF_IPD),
            (-30.0, 0.071),
            (20.0, 0.071),
        ] {
            let detection = consistent_detection(&back, eye, turn, width, 0.0);
            let pose = fit_head_pose(&detection, &back, width);
            let error = (DVec3::from(pose.eye) - eye).length();
            // The detection is exact and the fit's outline the same fine wireframe's: the eye
            // to 10 µm (45 nm today), the yaw to 0.2° (the residual is flat to 0.07° about
            // its minimum), the outline to a thousandth of a pixel (6e-6 today).
            assert!(
                error < 1e-5,
                "turn {turn}, width {width}: eye {error} m off"
            );
            assert!(
                (pose.yaw_deg - turn).abs() < 0.2,
                "turn {turn}, width {width}: fitted {}",
                pose.yaw_deg
            );
            assert!(pose.edge_rms_px < 1e-3, "{pose:?}");
        }
    }

    /// The outline's residual is in image pixels along the pupils' line: a face whose edges
    /// both lie `outward` pixels beyond the model's (wider than its pupils say, which no turn
    /// explains: a turn moves both edges one way) leaves `outward` pixels on each side.
    #[test]
    fn a_face_wider_than_its_pupils_leaves_its_excess_as_the_edge_residual() {
        let (back, eye) = back_and_eye();
        for outward in [1.0, 3.0] {
            let detection = consistent_detection(&back, eye, 0.0, 2.0 * HALF_IPD, outward);
            let pose = fit_head_pose(&detection, &back, 2.0 * HALF_IPD);
            assert!(
                (pose.edge_rms_px - outward).abs() < 0.05 * outward,
                "{outward} px outward: {pose:?}"
            );
        }
    }

    /// An outline edge far off on one side (hair, an ear, the seat's edge) costs at most the
    /// cap, 5 % of the face box's width: the other side's edge still fits the pose, and the
    /// residual is the cap's.
    #[test]
    fn an_edge_far_off_on_one_side_is_capped_and_the_other_side_fits_the_pose() {
        let (back, eye) = back_and_eye();
        let width = 2.0 * HALF_IPD;
        for turn in [0.0, 20.0] {
            let mut detection = consistent_detection(&back, eye, turn, width, 0.0);
            let [p0, p1] = detection.pupils.map(DVec2::from);
            let along = (p1 - p0).normalize();
            let edge = DVec2::from(detection.outline_candidates[1][0]);
            detection.outline_candidates[1][0] = (edge + along * 8.0).to_array();
            // No decoys: with one side capped, the other side's single edge is all there is
            // to fit, and a decoy there would fit some other yaw as well (an ambiguity the
            // margin reports).
            detection.outline_candidates[0][1] = [f64::NAN; 2];
            detection.outline_candidates[1][1] = [f64::NAN; 2];
            let pose = fit_head_pose(&detection, &back, width);
            let cap = 0.05 * f64::from(detection.face_box[2] - detection.face_box[0]);
            assert!((pose.yaw_deg - turn).abs() < 0.2, "turn {turn}: {pose:?}");
            assert!(
                (DVec3::from(pose.eye) - eye).length() < 1e-4,
                "turn {turn}: {pose:?}"
            );
            assert!(
                (pose.edge_rms_px - cap / 2f64.sqrt()).abs() < 1e-6,
                "turn {turn}: {pose:?}, cap {cap} px"
            );
        }
    }

    /// The fit searches turns within ±80° of facing the camera (beyond, the far eye is
    /// hidden and the pupils' line no longer measures the head): a detection made at a
    /// turn near either end of that range is fitted at its turn, one made beyond it within
    /// the range, not at its own turn.
    #[test]
    fn the_fit_searches_turns_within_eighty_degrees_of_facing_the_camera() {
        let (back, eye) = back_and_eye();
        for turn in [-70.0, 70.0] {
            let detection = consistent_detection(&back, eye, turn, 2.0 * HALF_IPD, 0.0);
            let pose = fit_head_pose(&detection, &back, 2.0 * HALF_IPD);
            assert!((pose.yaw_deg - turn).abs() < 0.2, "turn {turn}: {pose:?}");
        }
        for turn in [-120.0, 120.0] {
            let detection = consistent_detection(&back, eye, turn, 2.0 * HALF_IPD, 0.0);
            let pose = fit_head_pose(&detection, &back, 2.0 * HALF_IPD);
            let bound = f64::from(YAW_RANGE_DEG + COARSE_STEP_DEG);
            assert!(pose.yaw_deg.abs() <= bound, "turn {turn}: {pose:?}");
        }
    }

    /// A face whose outline was not found (no candidate on either side) fits every turn as
    /// well: each side's residual is the cap, 5 % of the face box's width, and the margin
    /// between the best turn and any other is nil, which the confidence reads as doubt.
    #[test]
    fn a_face_without_an_outline_leaves_the_cap_on_both_sides_and_no_margin() {
        let (back, eye) = back_and_eye();
        let mut detection = consistent_detection(&back, eye, 10.0, 2.0 * HALF_IPD, 0.0);
        detection.outline_candidates =
            [[[f64::NAN; 2]; crate::system::head::OUTLINE_CANDIDATES]; 2];
        let pose = fit_head_pose(&detection, &back, 2.0 * HALF_IPD);
        let cap = 0.05 * f64::from(detection.face_box[2] - detection.face_box[0]);
        assert!(
            (pose.edge_rms_px - cap).abs() < 1e-9,
            "{pose:?}, cap {cap} px"
        );
        assert_eq!(pose.margin, 0.0, "{pose:?}");
    }
}
