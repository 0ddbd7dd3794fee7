//! Issue 27: the side-angle head tracker on the head mesh over a grid of head poses, against
//! the true eye, with a confidence that separates its good estimates from its bad ones.

mod common;

use seethru::measure::head_poses::{PoseResult, estimate_pose, grid_camera, posed_view, spread};
use seethru::system::head::CONFIDENT_HEAD;
use seethru::system::head_side::{detect_turned, detect_turned_reference};

/// The default grid of `seethru head-poses`: yaw −45…45° in 15° steps × pitch −10, 0, 10°
/// × distance 0.8, 1, 1.25 of das's (63 renders at 640×480), each frame also detected by the
/// brute-force twin of the sparse detector.
fn full_grid() -> Vec<PoseResult> {
    let scene = common::parse_in(
        &common::repo_path("scenes"),
        "das_mesh_head.toml",
        &common::das_with_mesh_head_text(),
    )
    .unwrap();
    let back = grid_camera(&scene, None);
    let mut out = Vec::new();
    for scale in [0.8, 1.0, 1.25] {
        for pitch in [-10.0, 0.0, 10.0] {
            for yaw in [-45.0, -30.0, -15.0, 0.0, 15.0, 30.0, 45.0] {
                let (frame, eye, world_yaw) = posed_view(&scene, &back, yaw, pitch, scale).unwrap();
                // The sparse reading and the table encoding change nothing, bit for bit.
                assert_eq!(
                    detect_turned(&frame),
                    detect_turned_reference(&frame),
                    "yaw {yaw} pitch {pitch} scale {scale}"
                );
                out.push(estimate_pose(&frame, &back, eye, [yaw, pitch, world_yaw]));
            }
        }
    }
    out
}

#[test]
fn over_the_pose_grid_every_confident_estimate_is_within_3_cm_of_the_true_eye() {
    let results = full_grid();
    let table: Vec<String> = results
        .iter()
        .map(|r| {
            format!(
                "yaw {} pitch {} at {:.2} m: fit {:?} frontal {:?} confidence {:?} yaw error {:?}",
                r.yaw_deg,
                r.pitch_deg,
                r.distance_m,
                r.fitted_error_m,
                r.frontal_error_m,
                r.confidence,
                r.yaw_error_deg
            )
        })
        .collect();
    let table = table.join("\n");
    // Every pose within ±15° has both eyes in view and is detected.
    for r in results.iter().filter(|r| r.yaw_deg.abs() <= 15.0) {
        assert!(r.confidence.is_some(), "not detected:\n{table}");
    }
    let confident: Vec<&PoseResult> = results
        .iter()
        .filter(|r| r.confidence.is_some_and(|c| c >= CONFIDENT_HEAD))
        .collect();
    let unconfident: Vec<f64> = results
        .iter()
        .filter(|r| r.confidence.is_some_and(|c| c < CONFIDENT_HEAD))
        .map(|r| r.fitted_error_m.unwrap())
        .collect();
    // The bound: every confident estimate within 3.2 cm of the true eye (measured: 24 of 63
    // confident, 0.30–3.11 cm), its yaw within 5° (measured ≤ 3.7°), and at least 20 poses
    // confident.
    assert!(
        confident.len() >= 20,
        "{} confident\n{table}",
        confident.len()
    );
    for r in &confident {
        assert!(r.fitted_error_m.unwrap() < 0.032, "{table}");
        assert!(r.yaw_error_deg.unwrap().abs() < 5.0, "{table}");
    }
    // The confidence knows: the poses it doubts are worse by far (measured: medians 4.5 cm
    // against 1.7 cm), and every estimate off by more than the bound is among them.
    let sure: Vec<f64> = confident
        .iter()
        .map(|r| r.fitted_error_m.unwrap())
        .collect();
    let (sure, doubted) = (spread(&sure).unwrap(), spread(&unconfident).unwrap());
    assert!(
        doubted[0] > 2.0 * sure[0],
        "medians: unconfident {} m, confident {} m\n{table}",
        doubted[0],
        sure[0]
    );
    // The fit beats the paper's frontal equations, which read a turned head as far away.
    let fitted: Vec<f64> = results.iter().filter_map(|r| r.fitted_error_m).collect();
    let frontal: Vec<f64> = results.iter().filter_map(|r| r.frontal_error_m).collect();
    let (fit, front) = (spread(&fitted).unwrap()[0], spread(&frontal).unwrap()[0]);
    assert!(
        fit < 0.6 * front,
        "median fit {fit} m, frontal {front} m\n{table}"
    );
}

/// The slanted pillar of issue 27 (the ellipsoid face's failure, `tests/hazard.rs`) with the
/// head mesh: the back camera sees the head from below and rolled. Whatever the side-angle
/// tracker makes of it, an estimate more than 3 cm off must not be called confident.
#[test]
fn on_the_slanted_pillar_the_side_tracker_is_right_or_says_it_is_unsure() {
    let text = common::das_with_mesh_head_text().replace(
        "facing = [0.0, 0.0, 1.0]",
        "facing = [0.6, 0.0, 1.0]\nup = [0.0, 1.0, 1.5]",
    );
    let scene = common::parse_in(&common::repo_path("scenes"), "slanted.toml", &text).unwrap();
    let back = grid_camera(&scene, None);
    let mut seen = Vec::new();
    for yaw in [-30.0, 0.0, 30.0] {
        let (frame, eye, world_yaw) = posed_view(&scene, &back, yaw, 0.0, 1.0).unwrap();
        let r = estimate_pose(&frame, &back, eye, [yaw, 0.0, world_yaw]);
        seen.push(format!(
            "yaw {yaw}: error {:?} confidence {:?}",
            r.fitted_error_m, r.confidence
        ));
        if let (Some(error), Some(c)) = (r.fitted_error_m, r.confidence) {
            assert!(error < 0.03 || c < CONFIDENT_HEAD, "{seen:?}");
        }
    }
    eprintln!("{seen:?}");
}

#[test]
fn the_mesh_head_scene_is_das_with_the_head_mesh() {
    assert_eq!(
        std::fs::read_to_string(common::repo_path("scenes/das_mesh_head.toml")).unwrap(),
        common::das_with_mesh_head(),
        "scenes/das_mesh_head.toml drifted from scenes/das.toml: regenerate it"
    );
}
