//! Issue 27: the side-angle head tracker on the head mesh over a grid of head poses, against
//! the true eye, with a confidence that separates its good estimates from its bad ones.

mod common;

use seethru::measure::head_poses::{PoseResult, pose_grid, spread};
use seethru::system::head::CONFIDENT_HEAD;

/// das with the head mesh at its eye, turned from facing the back camera by −45° … 45° in
/// 15° steps (pitch 0, das's distance, the back camera's 640×480): 7 renders.
fn grid() -> Vec<PoseResult> {
    let scene = common::parse_in(
        &common::repo_path("scenes"),
        "das_mesh_head.toml",
        &common::das_with_mesh_head_text(),
    )
    .unwrap();
    let yaws = [-45.0, -30.0, -15.0, 0.0, 15.0, 30.0, 45.0];
    pose_grid(&scene, &yaws, &[0.0], &[1.0], None).unwrap()
}

#[test]
fn the_yaw_fit_finds_the_turned_eye_and_its_confidence_flags_the_poses_it_gets_wrong() {
    let results = grid();
    let cm = |m: f64| 100.0 * m;
    let table: Vec<String> = results
        .iter()
        .map(|r| {
            format!(
                "yaw {}: fit {:?} frontal {:?} confidence {:?} fitted yaw {:?}",
                r.yaw_deg, r.fitted_error_m, r.frontal_error_m, r.confidence, r.fitted_yaw_deg
            )
        })
        .collect();
    let table = table.join("\n");
    // From ±30° both eyes are in view: every such pose is detected. (At +45° the far eye is
    // behind the nose from das's pillar camera, so a miss there is right.)
    for r in results.iter().filter(|r| r.yaw_deg.abs() <= 30.0) {
        assert!(r.confidence.is_some(), "not detected:\n{table}");
    }
    let confident: Vec<&PoseResult> = results
        .iter()
        .filter(|r| r.confidence.is_some_and(|c| c >= CONFIDENT_HEAD))
        .collect();
    let unconfident: Vec<&PoseResult> = results
        .iter()
        .filter(|r| r.confidence.is_some_and(|c| c < CONFIDENT_HEAD))
        .collect();
    // The bound: every confident estimate within 3 cm of the true eye (measured: 0.8–2.5 cm),
    // and at least four of the five poses within ±30° confident.
    assert!(confident.len() >= 4, "{table}");
    for r in &confident {
        assert!(cm(r.fitted_error_m.unwrap()) < 3.0, "{table}");
    }
    // The fit beats the paper's frontal equations, which read a turned head as far away.
    let fitted: Vec<f64> = results.iter().filter_map(|r| r.fitted_error_m).collect();
    let frontal: Vec<f64> = results.iter().filter_map(|r| r.frontal_error_m).collect();
    let (fit, front) = (spread(&fitted).unwrap()[0], spread(&frontal).unwrap()[0]);
    assert!(
        fit < 0.7 * front,
        "median fit {fit} m, frontal {front} m\n{table}"
    );
    // The confidence correlates with the error: the unconfident poses (here the far eye at
    // the silhouette, −45°) are worse than the worst confident one.
    assert!(!unconfident.is_empty(), "{table}");
    let worst_confident = confident
        .iter()
        .map(|r| r.fitted_error_m.unwrap())
        .fold(0.0, f64::max);
    for r in &unconfident {
        assert!(r.fitted_error_m.unwrap() > worst_confident, "{table}");
    }
}

#[test]
fn the_mesh_head_scene_is_das_with_the_head_mesh() {
    assert_eq!(
        std::fs::read_to_string(common::repo_path("scenes/das_mesh_head.toml")).unwrap(),
        common::das_with_mesh_head(),
        "scenes/das_mesh_head.toml drifted from scenes/das.toml: regenerate it"
    );
}
