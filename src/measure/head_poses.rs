//! The head tracker against the true eye over a grid of head poses: the scene's head (the
//! objects that move with it) turned about its neck by each yaw (from facing the back camera)
//! and pitch and moved along
//! the back camera's line of sight to each distance, the back camera's view rendered, and the
//! eye estimated by the paper's frontal equations (eqs. d1, b_h) and by the yaw fit.
//! Poses where no face or no two pupils are found are counted, never dropped silently.

use std::time::Instant;

use anyhow::Result;
use glam::{DAffine3, DVec3};

use crate::geometry::camera::Camera;
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::render::render_job::RenderJob;
use crate::render::settings::RenderSettings;
use crate::render::views::View;
use crate::scene::Scene;
use crate::scene::head_model::{eye_turned_about_neck, head_rotation};
use crate::scene::motion::MovesWith;
use crate::system::head::eye_from_detection;
use crate::system::head_pose::locate;
use crate::system::head_side::detect_turned;
use crate::util::quantile::nearest_rank;

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
    /// Fitted minus true yaw about the world's vertical, degrees (`None`: no detection).
    pub yaw_error_deg: Option<f64>,
    /// The true eye and the fitted one, world frame, metres.
    pub eye_m: [f64; 3],
    pub fitted_eye_m: Option<[f64; 3]>,
    /// Wall time of the fit (`detect_turned` and `locate`) on one thread, seconds; a
    /// measurement, not deterministic.
    pub fit_s: f64,
}

/// The back camera of a pose grid: the scene's, `back_width` pixels wide (aspect kept).
pub fn grid_camera(scene: &Scene, back_width: Option<u32>) -> Camera {
    match back_width {
        Some(w) => {
            let h = ((w as f64 * scene.back.height as f64 / scene.back.width as f64).round()
                as u32)
                .max(1);
            scene.back.with_resolution(w, h)
        }
        None => scene.back,
    }
}

/// The back camera's view of the scene's head turned about its neck by `yaw_deg` (from
/// facing the camera) and `pitch_deg`, its eye moved along the camera's line of sight to
/// `scale` times the scene's distance; with the true eye (world frame, metres) and the head's
/// yaw about the world's vertical (degrees, as [`HeadPose::world_yaw_deg`]).
///
/// [`HeadPose::world_yaw_deg`]: crate::system::head_pose::HeadPose::world_yaw_deg
pub fn posed_view(
    scene: &Scene,
    back: &Camera,
    yaw_deg: f64,
    pitch_deg: f64,
    scale: f64,
) -> Result<(Frame, DVec3, f64)> {
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
    let rotation = head_rotation(facing_deg + yaw_deg, pitch_deg);
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
    let (frame, _) = ctx.render(
        RenderJob::new(back, View::Back.bit())
            .settings(settings)
            .label("back"),
    );
    Ok((frame, eye, facing_deg + yaw_deg))
}

/// The tracker's estimates from one back-camera frame against the true eye; the fit
/// (`detect_turned` and `locate`) timed on the calling thread.
pub fn estimate_pose(
    frame: &Frame,
    back: &Camera,
    eye: DVec3,
    [yaw_deg, pitch_deg, world_yaw_deg]: [f64; 3],
) -> PoseResult {
    let started = Instant::now();
    let detection = detect_turned(frame).ok();
    let located = detection.as_ref().map(|d| locate(d, back, 0.064));
    let fit_s = started.elapsed().as_secs_f64();
    let error = |e: DVec3| (e - eye).length();
    PoseResult {
        yaw_deg,
        pitch_deg,
        distance_m: (eye - back.position()).length(),
        frontal_error_m: detection
            .as_ref()
            .map(|d| error(eye_from_detection(d, back, 0.064))),
        frontal_confidence: detection.as_ref().map(|d| d.confidence.value),
        fitted_error_m: located.map(|(_, p)| error(DVec3::from(p.eye))),
        confidence: located.map(|(d, _)| d.confidence.value),
        fitted_yaw_deg: located.map(|(_, p)| p.yaw_deg),
        yaw_error_deg: located
            .map(|(_, p)| (p.world_yaw_deg - world_yaw_deg + 540.0).rem_euclid(360.0) - 180.0),
        eye_m: eye.to_array(),
        fitted_eye_m: located.map(|(_, p)| p.eye),
        fit_s,
    }
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
    let back = grid_camera(scene, back_width);
    let mut out = Vec::new();
    for &scale in distance_scales {
        for &pitch in pitches {
            for &yaw in yaws {
                let (frame, eye, world_yaw) = posed_view(scene, &back, yaw, pitch, scale)?;
                out.push(estimate_pose(&frame, &back, eye, [yaw, pitch, world_yaw]));
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
    Some([
        nearest_rank(&v, 0.5),
        nearest_rank(&v, 0.95),
        v[v.len() - 1],
    ])
}

/// The fit's wall time per frame (`detect_turned` and `locate`, one thread) over a grid, one
/// line: median, p95 and max in ms, and `setup_s`, the one-time set-up
/// ([`prepare_fit`](crate::system::head_pose::prepare_fit)) not in them. A measurement, not
/// deterministic: kept out of [`pose_table`].
pub fn fit_time_line(results: &[PoseResult], setup_s: f64) -> Option<String> {
    let ms: Vec<f64> = results.iter().map(|r| 1e3 * r.fit_s).collect();
    spread(&ms).map(|[median, p95, max]| {
        format!(
            "fit time per frame (detect_turned + locate, one thread, {} frames): median {median:.1} ms, p95 {p95:.1} ms, max {max:.1} ms; one-time set-up {:.1} ms (not included)",
            ms.len(),
            1e3 * setup_s
        )
    })
}

/// The error table (Markdown): one row per estimator and confidence class, cm, with the
/// poses flagged unconfident and those without a detection counted.
pub fn pose_table(results: &[PoseResult]) -> String {
    let confident = |r: &PoseResult| {
        r.confidence
            .is_some_and(|c| c >= crate::system::head::CONFIDENT_HEAD)
    };
    let unconfident = |r: &PoseResult| r.confidence.is_some() && !confident(r);
    let missed = results.iter().filter(|r| r.confidence.is_none()).count();
    let mut s = format!(
        "{} poses: {} confident, {} unconfident (confidence < {}), {} without a detection (not in the errors)\n",
        results.len(),
        results.iter().filter(|r| confident(r)).count(),
        results.iter().filter(|r| unconfident(r)).count(),
        crate::system::head::CONFIDENT_HEAD,
        missed
    );
    s += "\n| estimator (poses with a detection) | poses | median cm | p95 cm | max cm |\n|---|---:|---:|---:|---:|\n";
    let cm = |x: Option<f64>| x.map_or("—".to_string(), |v| format!("{:.2}", 100.0 * v));
    type Row = (&'static str, fn(&PoseResult) -> Option<f64>);
    let rows: [Row; 4] = [
        ("frontal equations (d1, b_h)", |r| r.frontal_error_m),
        ("yaw fit", |r| r.fitted_error_m),
        ("yaw fit, confident", |r| {
            r.fitted_error_m
                .filter(|_| r.confidence.unwrap_or(0.0) >= crate::system::head::CONFIDENT_HEAD)
        }),
        ("yaw fit, unconfident", |r| {
            r.fitted_error_m
                .filter(|_| r.confidence.unwrap_or(1.0) < crate::system::head::CONFIDENT_HEAD)
        }),
    ];
    for (name, pick) in rows {
        let errors: Vec<f64> = results.iter().filter_map(pick).collect();
        let a = spread(&errors);
        s += &format!(
            "| {name} | {} | {} | {} | {} |\n",
            errors.len(),
            cm(a.map(|x| x[0])),
            cm(a.map(|x| x[1])),
            cm(a.map(|x| x[2])),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pose result with only what the table and the time line read.
    fn result(frontal: Option<f64>, fitted: Option<f64>, confidence: Option<f64>) -> PoseResult {
        PoseResult {
            yaw_deg: 0.0,
            pitch_deg: 0.0,
            distance_m: 1.0,
            frontal_error_m: frontal,
            fitted_error_m: fitted,
            confidence,
            frontal_confidence: confidence,
            fitted_yaw_deg: None,
            yaw_error_deg: None,
            eye_m: [0.0; 3],
            fitted_eye_m: None,
            fit_s: 0.0,
        }
    }

    #[test]
    fn the_grid_camera_keeps_the_back_cameras_aspect() {
        let das = Scene::bundled("das.toml");
        assert_eq!((das.back.width, das.back.height), (640, 480));
        let size = |w| {
            let c = grid_camera(&das, w);
            (c.width, c.height)
        };
        assert_eq!(size(None), (640, 480));
        assert_eq!(size(Some(320)), (320, 240));
        // 101 × 3/4 = 75.75: rounded.
        assert_eq!(size(Some(101)), (101, 76));
        assert_eq!(size(Some(1)), (1, 1));
    }

    #[test]
    fn the_spread_is_the_nearest_rank_median_p95_and_max() {
        assert_eq!(spread(&[]), None);
        assert_eq!(spread(&[4.0]), Some([4.0; 3]));
        // 1…20 shuffled: ranks ⌈0.5·20⌉ = 10 and ⌈0.95·20⌉ = 19.
        let values: Vec<f64> = (0..20).map(|i| ((i * 7) % 20 + 1) as f64).collect();
        assert_eq!(spread(&values), Some([10.0, 19.0, 20.0]));
        // Three values: ranks 2 and 3.
        assert_eq!(spread(&[0.3, -1.0, 0.1]), Some([0.1, 0.3, 0.3]));
    }

    #[test]
    fn the_fit_time_line_gives_the_spread_in_milliseconds_and_the_set_up_apart() {
        assert_eq!(fit_time_line(&[], 1.0), None);
        let results: Vec<PoseResult> = (1..=20)
            .map(|i| PoseResult {
                fit_s: i as f64 * 1e-3,
                ..result(None, None, None)
            })
            .collect();
        let line = fit_time_line(&results, 0.25).unwrap();
        assert!(
            line.contains(
                "20 frames): median 10.0 ms, p95 19.0 ms, max 20.0 ms; one-time set-up 250.0 ms"
            ),
            "{line}"
        );
    }

    #[test]
    fn the_pose_table_counts_every_class_and_spreads_each_estimators_errors() {
        let c = crate::system::head::CONFIDENT_HEAD;
        let results = [
            result(Some(0.10), Some(0.01), Some(c)),
            result(Some(0.20), Some(0.02), Some(1.0)),
            result(Some(0.30), Some(0.05), Some(c - 0.01)),
            result(None, None, None),
        ];
        let table = pose_table(&results);
        assert!(
            table.starts_with(&format!(
                "4 poses: 2 confident, 1 unconfident (confidence < {c}), 1 without a detection"
            )),
            "{table}"
        );
        for row in [
            "| frontal equations (d1, b_h) | 3 | 20.00 | 30.00 | 30.00 |",
            "| yaw fit | 3 | 2.00 | 5.00 | 5.00 |",
            "| yaw fit, confident | 2 | 1.00 | 2.00 | 2.00 |",
            "| yaw fit, unconfident | 1 | 5.00 | 5.00 | 5.00 |",
        ] {
            assert!(table.contains(row), "{row} not in\n{table}");
        }
        // No pose of a class: its row says so.
        let table = pose_table(&results[..2]);
        assert!(
            table.contains("| yaw fit, unconfident | 0 | — | — | — |"),
            "{table}"
        );
    }

    #[test]
    fn a_scene_without_a_head_has_no_pose_to_turn() {
        let mut headless = Scene::bundled("das.toml");
        for o in &mut headless.objects {
            o.motion.moves_with = MovesWith::Vehicle;
        }
        let back = grid_camera(&headless, Some(16));
        let err = posed_view(&headless, &back, 0.0, 0.0, 1.0).unwrap_err();
        assert!(
            err.to_string().contains("no object with moves_with"),
            "{err}"
        );
    }

    #[test]
    fn a_grid_moves_the_eye_along_the_line_of_sight_and_measures_the_tracker_there() {
        // The mesh head at 0.8 and 1.25 of its distance, facing the back camera: the eye
        // (turned about the neck to face it) within a few cm of that distance, the tracker
        // detecting it, and its yaw error wrapped into (−180°, 180°].
        let das = Scene::bundled("das_mesh_head.toml");
        let camera = das.back.position();
        let d0 = (das.eye() - camera).length();
        let results = pose_grid(&das, &[0.0], &[0.0], &[0.8, 1.25], None).unwrap();
        assert_eq!(results.len(), 2);
        for (r, scale) in results.iter().zip([0.8, 1.25]) {
            let eye = DVec3::from(r.eye_m);
            assert_eq!(r.distance_m, (eye - camera).length());
            assert!((r.distance_m - scale * d0).abs() < 0.05, "{scale}: {r:?}");
            let error = r.yaw_error_deg.unwrap();
            assert!(error.abs() < 10.0, "{r:?}");
            assert!(r.fitted_error_m.unwrap() < 0.1, "{r:?}");
        }
        // The same frame against a true yaw 360° or 720° away: the same error; 180° away:
        // the error wrapped to the other side.
        let back = grid_camera(&das, None);
        let (frame, eye, world_yaw) = posed_view(&das, &back, 0.0, 0.0, 1.0).unwrap();
        let error = |w: f64| {
            estimate_pose(&frame, &back, eye, [0.0, 0.0, w])
                .yaw_error_deg
                .unwrap()
        };
        let e = error(world_yaw);
        assert!((error(world_yaw + 360.0) - e).abs() < 1e-9);
        assert!((error(world_yaw - 720.0) - e).abs() < 1e-9);
        let turned = error(world_yaw + 180.0);
        assert!(
            turned > -180.0 && turned <= 180.0 && turned.abs() > 170.0,
            "{turned}"
        );
        // 180° apart, on the circle.
        let apart = (turned - e).rem_euclid(360.0);
        assert!((apart - 180.0).abs() < 1e-9, "{turned} vs {e}");
    }
}
