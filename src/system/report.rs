//! `run.json`: every option of a run, the true and the used eye, the head detection, d2, the
//! crop in the paper's terms, how far it leaves the frontal view, and timings.

use glam::DVec3;
use serde_json::json;

use crate::analysis::paper::k_px;
use crate::scene::DriverFace;
use crate::scene::Scene;
use crate::system::compensation::Crop;
use crate::system::head_estimate::HeadFix;
use crate::system::options::{HeadSource, RunOptions, WorkingDistance};
use crate::system::tracker_model::WEBCAM_LANDMARKS;

#[allow(clippy::too_many_arguments)]
pub fn report(
    scene: &Scene,
    options: &RunOptions,
    crop: &Crop,
    eye_used: DVec3,
    head: Option<&HeadFix>,
    d2_used: Option<f64>,
    missing: f64,
    overflow: &[(&str, f64); 4],
    timings: serde_json::Map<String, serde_json::Value>,
) -> serde_json::Value {
    let eye_o = |e: DVec3| scene.obstacle.in_obstacle_frame(e);
    let (true_o, used_o) = (eye_o(scene.eye()), eye_o(eye_used));
    let paper = |o: DVec3| json!({"d1_m": o.z, "b_h_m": -o.x, "b_v_m": o.y});
    let ratios = crop.ratios();
    let [fw, fh] = crop.frontal_size;
    json!({
        "scene": scene.path.display().to_string(),
        "scene_absolute": scene.path.canonicalize().ok().map(|p| p.display().to_string()),
        "scene_hash": (!scene.source_hash.is_empty()).then_some(&scene.source_hash),
        "options": {
            "method": options.method,
            "d2": match options.d2 { WorkingDistance::Infinity => json!("inf"), WorkingDistance::Auto => json!("auto"), WorkingDistance::Metres(m) => json!(m) },
            "head": options.head,
            "head_bias_cm": options.head_bias_cm,
            "head_jitter_cm": options.head_jitter_cm,
            "seed": options.seed,
            "require_confident_head": options.require_confident_head,
            "min_head_confidence": options.min_head_confidence,
            "feature_width_m": options.feature_width,
            "spp": options.spp,
            "outside": options.outside,
            "filter": options.filter,
            "display": options.display,
        },
        "conventions": "obstacle frame: origin at the display centre, +z towards the driver; paper's b_h = −x (eye on the side of R1 for b_h > 0), b_v = y",
        "eye_true": {"world_m": scene.eye().to_array(), "obstacle_m": true_o.to_array(), "paper": paper(true_o)},
        "eye_used": {"world_m": eye_used.to_array(), "obstacle_m": used_o.to_array(), "paper": paper(used_o), "error_m": (eye_used - scene.eye()).length()},
        "head_model": (options.head == HeadSource::Model).then_some(WEBCAM_LANDMARKS),
        "head_detection": head.map(|h| {
            let d = &h.detection;
            json!({"face_box_px": d.face_box, "pupils_px": d.pupils, "feature_px": d.feature_px(), "pupil_areas_px": d.pupil_areas_px, "confidence": d.confidence, "face": face_name(scene.face), "tracker": tracker_name(scene.face), "fit": h.pose, "warning": (!d.confidence.is_confident_at(options.min_head_confidence)).then(|| d.confidence.warning_at("", options.min_head_confidence))})
        }),
        "d2_m": d2_used.map_or(json!("inf"), |d| json!(d)),
        "frontal_half_angle_deg": scene.frontal.half_angle_x.to_degrees(),
        "crop": {
            "corners_frontal_px_tl_tr_br_bl": crop.corners.map(|c| c.to_array()),
            "axis_aligned": crop.is_axis_aligned(1e-6),
            "R1_left": ratios.left, "R2_right": ratios.right, "R_top": ratios.top, "R_bottom": ratios.bottom,
            "K_px": {"left": k_px(ratios.left, fw), "right": k_px(ratios.right, fw), "top": k_px(ratios.top, fh), "bottom": k_px(ratios.bottom, fh)},
            "outside_frontal_view_px": overflow.iter().map(|(s, px)| (s.to_string(), json!(px))).collect::<serde_json::Map<_, _>>(),
        },
        "display_resolution": scene.obstacle.display_resolution,
        "missing_fraction": missing,
        "timings_s": timings,
    })
}

/// The `exposure` of a frame from a camera with a sensor (run.json's, capture.json's):
/// its time and gain, what its automatic exposure metered against its target, and its codes;
/// `null` for a camera without a sensor.
pub fn exposure_json(frame: &crate::render::frame::Frame) -> serde_json::Value {
    let Some(e) = frame.exposure else {
        return serde_json::Value::Null;
    };
    let white = f64::from(frame.white_cd_m2.unwrap_or(f32::NAN));
    json!({
        "exposure_ms": e.exposure_s * 1e3,
        "gain": e.gain,
        "metered": e.metered,
        "target": e.target,
        "at_limit": e.at_limit,
        "tone_curve": e.coding.map_or("none", |c| c.curve.name()),
        "output_bits": e.coding.map(|c| c.bits),
        "full_scale_cd_m2": e.full_scale * white,
        "note": "metered, target: the automatic exposure's mean signal and its aim, shares of the ADC's full scale (null: a manual exposure); at_limit: it could not reach its target; full_scale_cd_m2: the luminance that fills the ADC",
    })
}

/// The `[camera.driver] face` value of a face.
pub fn face_name(face: DriverFace) -> &'static str {
    match face {
        DriverFace::Ellipsoids => "ellipsoids",
        DriverFace::Mesh { .. } => "mesh",
    }
}

/// What `--head estimated` runs on a face (run.json's `head_detection.tracker`).
pub fn tracker_name(face: DriverFace) -> &'static str {
    match face {
        DriverFace::Ellipsoids => "frontal detector, eqs. d1 and b_h",
        DriverFace::Mesh { .. } => "side-angle detector, yaw fit",
    }
}
