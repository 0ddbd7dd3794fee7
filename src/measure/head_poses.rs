//! The head tracker against the true eye over a grid of head poses: the scene's head (the
//! objects that move with it) turned about its neck by each yaw (from facing the back camera)
//! and pitch and moved along
//! the back camera's line of sight to each distance, the back camera's view rendered, and the
//! eye estimated by the paper's frontal equations (eqs. d1, b_h) and by the yaw fit.
//! Poses where no face or no two pupils are found are counted, never dropped silently.

use anyhow::Result;
use glam::{DAffine3, DVec3};

use crate::render::integrator::RenderContext;
use crate::render::settings::RenderSettings;
use crate::render::views::View;
use crate::scene::Scene;
use crate::scene::head_model::{eye_turned_about_neck, head_rotation};
use crate::scene::motion::MovesWith;
use crate::system::head::eye_from_detection;
use crate::system::head_pose::locate;
use crate::system::head_side::detect_turned;

/// One pose of the grid and what the tracker made of it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PoseResult {
    /// Head yaw from facing the back camera (positive: the face turns further to the driver's
    /// left) and pitch (positive: up), degrees, about the neck.
    pub yaw_deg: f64,
    pub pitch_deg: f64,
    /// Distance from the back camera to the true eye, metres.
    pub distance_m: f64,
    /// Eye errors, metres: the frontal equations and the yaw fit; `None`: no detection.
    pub frontal_error_m: Option<f64>,
    pub fitted_error_m: Option<f64>,
    /// The detection's confidence with the yaw fit's cues, [0, 1] (`None`: no detection).
    pub confidence: Option<f64>,
    /// The confidence from the frontal cues alone (what the frontal equations had).
    pub frontal_confidence: Option<f64>,
    /// The fitted yaw from facing the back camera, degrees.
    pub fitted_yaw_deg: Option<f64>,
}

/// The grid: every yaw × pitch × distance scale (the scene's eye distance from the back
/// camera times the scale); the back camera `back_width` pixels wide.
pub fn pose_grid(
    scene: &Scene,
    yaws: &[f64],
    pitches: &[f64],
    distance_scales: &[f64],
    back_width: Option<u32>,
) -> Result<Vec<PoseResult>> {
    let back = match back_width {
        Some(w) => {
            let h = ((w as f64 * scene.back.height as f64 / scene.back.width as f64).round()
                as u32)
                .max(1);
            scene.back.with_resolution(w, h)
        }
        None => scene.back,
    };
    let eye0 = scene.eye();
    if !scene
        .objects
        .iter()
        .any(|o| o.motion.moves_with == MovesWith::Head)
    {
        anyhow::bail!("the scene has no object with moves_with = \"head\" to turn");
    }
    let camera = back.position();
    // Yaw 0 faces the back camera: the world yaw whose −z axis points from the eye at it.
    let to_camera = camera - eye0;
    let facing_deg = (-to_camera.x).atan2(-to_camera.z).to_degrees();
    let mut out = Vec::new();
    for &scale in distance_scales {
        for &pitch in pitches {
            for &yaw in yaws {
                let rotation = head_rotation(facing_deg + yaw, pitch);
                let start = camera + (eye0 - camera) * scale;
                let eye = eye_turned_about_neck(start, rotation);
                let head_from_start = DAffine3::from_translation(eye)
                    * DAffine3::from_mat3(rotation)
                    * DAffine3::from_translation(-eye0);
                let mut posed = scene.clone();
                for o in &mut posed.objects {
                    if o.motion.moves_with == MovesWith::Head {
                        o.world_from_object = head_from_start * o.world_from_object;
                    }
                }
                posed.driver.world_from_camera.translation = eye;
                let ctx = RenderContext::new(posed)?;
                let settings = RenderSettings {
                    spp: 1,
                    progress: false,
                };
                let (frame, _) = ctx.render(&back, View::Back.bit(), settings, "back");
                let detection = detect_turned(&frame).ok();
                let located = detection.as_ref().map(|d| locate(d, &back, 0.064));
                let error = |e: DVec3| (e - eye).length();
                out.push(PoseResult {
                    yaw_deg: yaw,
                    pitch_deg: pitch,
                    distance_m: (eye - camera).length(),
                    frontal_error_m: detection
                        .as_ref()
                        .map(|d| error(eye_from_detection(d, &back, 0.064))),
                    frontal_confidence: detection.as_ref().map(|d| d.confidence.value),
                    fitted_error_m: located.map(|(_, p)| error(DVec3::from(p.eye))),
                    confidence: located.map(|(d, _)| d.confidence.value),
                    fitted_yaw_deg: located.map(|(_, p)| p.yaw_deg),
                });
            }
        }
    }
    Ok(out)
}

/// Median, 95th percentile and maximum of some values (nearest rank); `None` when empty.
pub fn spread(values: &[f64]) -> Option<[f64; 3]> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let rank = |q: f64| v[((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    Some([rank(0.5), rank(0.95), v[v.len() - 1]])
}

/// The error table (Markdown): one row per estimator, cm, with the poses flagged unconfident
/// and those without a detection.
pub fn pose_table(results: &[PoseResult]) -> String {
    let confident = |r: &PoseResult| {
        r.confidence
            .is_some_and(|c| c >= crate::system::head::CONFIDENT_HEAD)
    };
    let unconfident = results
        .iter()
        .filter(|r| r.confidence.is_some() && !confident(r))
        .count();
    let missed = results.iter().filter(|r| r.confidence.is_none()).count();
    let mut s = format!(
        "{} poses: {} unconfident (confidence < {}), {} without a detection (not in the errors)\n\n| estimator | median cm | p95 cm | max cm | median cm, confident only | max cm, confident only |\n|---|---:|---:|---:|---:|---:|\n",
        results.len(),
        unconfident,
        crate::system::head::CONFIDENT_HEAD,
        missed
    );
    let cm = |x: Option<f64>| x.map_or("—".to_string(), |v| format!("{:.2}", 100.0 * v));
    for (name, pick) in [
        (
            "frontal equations (d1, b_h)",
            (|r: &PoseResult| r.frontal_error_m) as fn(&PoseResult) -> Option<f64>,
        ),
        ("yaw fit", |r: &PoseResult| r.fitted_error_m),
    ] {
        let all: Vec<f64> = results.iter().filter_map(pick).collect();
        let sure: Vec<f64> = results
            .iter()
            .filter(|r| confident(r))
            .filter_map(pick)
            .collect();
        let (a, c) = (spread(&all), spread(&sure));
        s += &format!(
            "| {name} | {} | {} | {} | {} | {} |\n",
            cm(a.map(|x| x[0])),
            cm(a.map(|x| x[1])),
            cm(a.map(|x| x[2])),
            cm(c.map(|x| x[0])),
            cm(c.map(|x| x[2])),
        );
    }
    s
}
