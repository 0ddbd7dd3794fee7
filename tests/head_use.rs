//! Issue 27: the driver's face chosen in the scene (`[camera.driver] face`), and `--head
//! estimated` running the tracker it calls for: on the head mesh, the side-angle detector and
//! the yaw fit, in `run` (run.json) and `sequence` (frames.csv, the face-region tracker).

mod common;

use glam::DVec3;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::system::options::{HeadSource, Outside, RunOptions};
use seethru::system::pipeline::run;
use seethru::system::sequence::head_motion::HeadMotion;
use seethru::system::sequence::predict::Prediction;
use seethru::system::sequence::system_loop::{SequenceOptions, SystemLoop};
use seethru::system::sequence::timeline::Timeline;

fn mesh_head() -> Scene {
    Scene::load(&common::repo_path("scenes/das_mesh_head.toml")).unwrap()
}

/// das's back camera: on the display's top edge (display centre (1.05, 1.2, −0.75), H =
/// 0.45 m), world.
const BACK: DVec3 = DVec3::new(1.05, 1.425, -0.75);

/// The yaw, degrees, of a head looking along −z (the mesh face's default) from facing a
/// camera at `camera`, for its eye at `eye`: positive turns the face towards −x. Facing the
/// camera is looking along `camera − eye`, whose yaw from −z is atan2(−Δx, −Δz).
fn yaw_from_camera_deg(eye: DVec3, camera: DVec3) -> f64 {
    let d = camera - eye;
    -(-d.x).atan2(-d.z).to_degrees()
}

fn estimated() -> RunOptions {
    RunOptions {
        head: HeadSource::Estimated,
        spp: 1,
        width: Some(64),
        outside: Outside::Black,
        ..RunOptions::default()
    }
}

/// das_mesh_head with `--head estimated`: the yaw fit's eye (measured 1.3 cm off) within
/// 2.5 cm, confident, its yaw (measured −25.15°) within 1° of the head's true −25.02° from
/// facing the back camera, and run.json saying which tracker ran and what it fitted.
#[test]
fn the_mesh_face_is_tracked_by_the_yaw_fit() {
    let result = run(&RenderContext::new(mesh_head()).unwrap(), &estimated()).unwrap();
    let report = &result.report;
    let error = report["eye_used"]["error_m"].as_f64().unwrap();
    let detection = &report["head_detection"];
    let confidence = detection["confidence"]["value"].as_f64().unwrap();
    assert!(error < 0.025, "eye {error} m off: {detection}");
    assert!(confidence >= 0.5, "{detection}");
    // Scored with the fit's cues (outline residual, yaw, margin).
    assert_eq!(detection["confidence"]["fitted"], true, "{detection}");
    assert_eq!(detection["face"], "mesh");
    assert_eq!(detection["tracker"], "side-angle detector, yaw fit");
    let truth = yaw_from_camera_deg(DVec3::new(1.4, 1.2, 0.0), BACK);
    assert!((truth + 25.02).abs() < 0.01, "{truth}");
    let yaw = detection["fit"]["yaw_deg"].as_f64().unwrap();
    assert!((yaw - truth).abs() < 1.0, "fitted {yaw}°, true {truth}°");
    let margin = detection["fit"]["margin"].as_f64().unwrap();
    assert!((0.0..=0.05).contains(&margin), "{margin}");
    // The eye used is the fit's (no bias, no jitter, one eye).
    let fitted = DVec3::from_array(
        serde_json::from_value::<[f64; 3]>(detection["fit"]["eye"].clone()).unwrap(),
    );
    let used = DVec3::from_array(
        serde_json::from_value::<[f64; 3]>(report["eye_used"]["world_m"].clone()).unwrap(),
    );
    assert_eq!(fitted, used);
    assert_eq!(result.head_pose.map(|p| p.yaw_deg), Some(yaw));
    // das keeps its ellipsoid face and the frontal tracker: no fit.
    let das = run(&RenderContext::new(common::das()).unwrap(), &estimated()).unwrap();
    assert_eq!(das.report["head_detection"]["face"], "ellipsoids");
    assert!(das.report["head_detection"]["fit"].is_null());
    assert!(das.head_pose.is_none());
}

/// das_mesh_head with the pillar slanted as in tests/hazard.rs (turned 31° towards the
/// driver, leaning back): the yaw fit's outline margin is ambiguous there (measured 0.001
/// face widths, confidence 0.04), so `run` warns in one line and `--require-confident-head`
/// refuses, writing nothing.
#[test]
fn the_mesh_face_on_a_slanted_pillar_warns() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("slanted_mesh.toml");
    std::fs::write(&scene, common::slanted_scene_text("das_mesh_head.toml")).unwrap();
    let args = |out: &str, extra: &[&str]| {
        common::estimated_run_args(&scene, &dir.path().join(out), extra)
    };
    let (ok, _, err) = common::seethru(&args("warned", &[]));
    assert!(ok, "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.starts_with("warning:")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(warnings[0].contains("head estimate unreliable"), "{err}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("warned/run.json")).unwrap())
            .unwrap();
    let detection = &report["head_detection"];
    assert_eq!(detection["tracker"], "side-angle detector, yaw fit");
    assert!(
        detection["confidence"]["value"].as_f64().unwrap() < 0.5,
        "{detection}"
    );
    let (ok, _, err) = common::seethru(&args("refused", &["--require-confident-head"]));
    assert!(!ok);
    assert!(
        err.starts_with("error:") && err.contains("--require-confident-head"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!dir.path().join("refused").exists(), "nothing written");
}

/// `--min-head-confidence` is the bound the estimate's confidence is held to. On the slanted
/// mesh face (confidence 0.04): just above it, `--require-confident-head` refuses, naming the
/// bound; just below, the run passes without the warning that the default 0.5 gives.
#[test]
fn the_head_confidence_bound_is_the_users() {
    let dir = tempfile::tempdir().unwrap();
    let slanted = dir.path().join("slanted_mesh.toml");
    std::fs::write(&slanted, common::slanted_scene_text("das_mesh_head.toml")).unwrap();
    let run = |out: &str, extra: &[&str]| {
        common::seethru(&common::estimated_run_args(
            &slanted,
            &dir.path().join(out),
            extra,
        ))
    };
    let report = |out: &str| -> serde_json::Value {
        serde_json::from_str(
            &std::fs::read_to_string(dir.path().join(out).join("run.json")).unwrap(),
        )
        .unwrap()
    };
    let (ok, _, err) = run("warned", &[]);
    assert!(
        ok && err.contains("warning: head estimate unreliable"),
        "{err}"
    );
    let confidence = report("warned")["head_detection"]["confidence"]["value"]
        .as_f64()
        .unwrap();
    assert!((0.01..0.5).contains(&confidence), "{confidence}");
    let above = confidence + 0.005;
    let (ok, _, err) = run(
        "above",
        &[
            "--require-confident-head",
            "--min-head-confidence",
            &above.to_string(),
        ],
    );
    assert!(!ok && err.contains("head estimate unreliable"), "{err}");
    assert!(
        err.contains(&format!("< {}", seethru::util::number::short(above))),
        "{err}"
    );
    assert!(!dir.path().join("above").exists(), "nothing written");
    let below = confidence - 0.005;
    let (ok, _, err) = run(
        "below",
        &[
            "--require-confident-head",
            "--min-head-confidence",
            &below.to_string(),
        ],
    );
    assert!(ok && !err.contains("warning:"), "{err}");
    // serde_json's reading is not correctly rounded: equal but for the last bits.
    let written = report("below")["options"]["min_head_confidence"]
        .as_f64()
        .unwrap();
    assert!((written - below).abs() < 1e-15, "{written} {below}");
    assert!(report("below")["head_detection"]["warning"].is_null());
}

/// The scene key: a value outside its list, `face_yaw_deg` without the mesh face or out of
/// [−80, 80], and the mesh face beside an object of the file named `head` (das's ellipsoid
/// head: two faces) are each one `error:` line naming the file, line and key.
#[test]
fn the_face_key_refuses_what_it_cannot_build() {
    let dir = tempfile::tempdir().unwrap();
    let das = std::fs::read_to_string(common::repo_path("scenes/das.toml"))
        .unwrap()
        .replace("../assets", common::repo_path("assets").to_str().unwrap());
    let mesh = std::fs::read_to_string(common::repo_path("scenes/das_mesh_head.toml"))
        .unwrap()
        .replace("../assets", common::repo_path("assets").to_str().unwrap());
    let driver = "[camera.driver]\n";
    let cases: [(&str, String, &[&str]); 5] = [
        (
            "beard",
            das.replacen(driver, &format!("{driver}face = \"beard\"\n"), 1),
            &["`camera.driver.face`", "`beard`", "ellipsoids, mesh"],
        ),
        (
            "yaw_without_mesh",
            das.replacen(driver, &format!("{driver}face_yaw_deg = 10.0\n"), 1),
            &["`camera.driver.face_yaw_deg`", "only with face = \"mesh\""],
        ),
        (
            "yaw_range",
            mesh.replacen(driver, &format!("{driver}face_yaw_deg = 95.0\n"), 1),
            &["`camera.driver.face_yaw_deg`", "95", "[-80, 80]"],
        ),
        (
            "nan_yaw",
            mesh.replacen(driver, &format!("{driver}face_yaw_deg = nan\n"), 1),
            &["`camera.driver.face_yaw_deg`"],
        ),
        (
            "two_faces",
            das.replacen(driver, &format!("{driver}face = \"mesh\"\n"), 1),
            &["`camera.driver.face`", "named `head`"],
        ),
    ];
    for (name, text, expected) in cases {
        let path = dir.path().join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        let (ok, out, err) = common::seethru(&[
            "render",
            path.to_str().unwrap(),
            "--out",
            dir.path().join(name).to_str().unwrap(),
            "--view",
            "back",
            "--width",
            "8",
            "--quiet",
        ]);
        assert!(!ok, "{name}: accepted\n{out}");
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        let at = format!("{name}.toml:");
        assert!(
            err.starts_with("error:") && err.contains(&at),
            "{name}: {err}"
        );
        for e in expected {
            assert!(err.contains(e), "{name}: `{e}` not in {err}");
        }
        assert!(!dir.path().join(name).exists(), "{name}: wrote output");
    }
}

/// A swaying head (±6 cm across the display at 1 Hz) turns the mesh face against the fixed
/// back camera by −21.1° … −28.7°: frames.csv's fitted yaw follows the truth within 1°
/// (measured ≤ 0.36°), its true yaw column is the geometry's, and every estimate is confident
/// and within 2.5 cm of the true eye (measured 0.8–1.8 cm).
#[test]
fn frames_csv_records_the_fitted_yaw_against_the_true_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("seq");
    let (ok, _, err) = common::seethru(&[
        "sequence",
        "scenes/das_mesh_head.toml",
        "--out",
        out.to_str().unwrap(),
        "--head",
        "sway",
        "--sway-cm",
        "6",
        "--sway-hz",
        "1",
        "--duration",
        "1",
        "--fps",
        "8",
        "--head-source",
        "estimated",
        "--width",
        "64",
        "--frontal-width",
        "160",
        "--spp",
        "1",
        "--frames",
        "none",
        "--outside",
        "black",
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let text = std::fs::read_to_string(out.join("latency_0ms/frames.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 8);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for r in &rows {
        let t = r[column("head_sample_s")];
        // The sway: the eye moves along the display's x (das: the world's x).
        let eye = DVec3::new(1.4 + 0.06 * (std::f64::consts::TAU * t).sin(), 1.2, 0.0);
        let truth = yaw_from_camera_deg(eye, BACK);
        (lo, hi) = (lo.min(truth), hi.max(truth));
        let row = format!("{r:?}");
        assert!(
            (r[column("head_yaw_true_deg")] - truth).abs() < 1e-6,
            "t = {t}: {row}"
        );
        assert!(
            (r[column("head_yaw_deg")] - truth).abs() < 3.0,
            "t = {t}: fitted {} true {truth}",
            r[column("head_yaw_deg")]
        );
        let margin = r[column("head_fit_margin")];
        assert!(margin > 0.0 && margin <= 0.05, "t = {t}: {row}");
        assert!(r[column("head_confidence")] >= 0.5, "t = {t}: {row}");
        let estimated = DVec3::new(
            r[column("eye_estimated_x_m")],
            r[column("eye_estimated_y_m")],
            r[column("eye_estimated_z_m")],
        );
        // Obstacle frame: das's display centre is at (1.05, 1.2, −0.75), axes the world's.
        let true_o = eye - DVec3::new(1.05, 1.2, -0.75);
        assert!((estimated - true_o).length() < 0.025, "t = {t}: {row}");
    }
    assert!(hi - lo > 7.0, "the sway turns the face by {} °", hi - lo);
}

/// The face-region tracker on the mesh face (a leaning head, 12 refreshes): every estimate
/// and yaw fit bit for bit the whole image's, with fewer back pixels rendered.
#[test]
fn the_tracked_mesh_face_estimates_are_the_whole_images() {
    let options = SequenceOptions {
        run: RunOptions {
            head: HeadSource::Estimated,
            width: Some(48),
            height: Some(27),
            frontal_width: Some(96),
            spp: 1,
            outside: Outside::Black,
            speed_kmh: 50.0,
            ..RunOptions::default()
        },
        timeline: Timeline {
            duration: 0.4,
            fps: 30.0,
            display_hz: 30.0,
            latency_camera: 0.05,
            latency_tracking: 0.01,
        },
        head: HeadMotion::Lean {
            distance: 0.1,
            duration: 0.3,
            start: 0.05,
        },
        predict: Prediction::None,
        reproject: false,
        byo: Default::default(),
    };
    let scene = mesh_head();
    let estimates = |track: bool| {
        let mut system = SystemLoop::new(&scene, options.clone()).unwrap();
        system.track_face = track;
        let shown: Vec<_> = (0..system.options.timeline.frames())
            .map(|k| {
                let s = system.show(k).unwrap();
                (
                    s.eye_estimated.to_array(),
                    s.head_confidence,
                    s.head_pose.map(|p| p.yaw_deg),
                )
            })
            .collect();
        (shown, system.back_pixels)
    };
    let (tracked, tracked_pixels) = estimates(true);
    let (whole, whole_pixels) = estimates(false);
    assert_eq!(tracked.len(), 12);
    for (k, (t, w)) in tracked.iter().zip(&whole).enumerate() {
        assert_eq!(t.0.map(f64::to_bits), w.0.map(f64::to_bits), "frame {k}");
        assert_eq!(t.1.map(f64::to_bits), w.1.map(f64::to_bits), "frame {k}");
        assert_eq!(t.2.map(f64::to_bits), w.2.map(f64::to_bits), "frame {k}");
        assert!(t.2.is_some(), "frame {k}: the mesh face is fitted");
    }
    let moved = DVec3::from_array(tracked[11].0) - DVec3::from_array(tracked[0].0);
    assert!(
        moved.length() > 0.05,
        "the estimates follow the lean: {moved}"
    );
    assert_eq!(whole_pixels, 12 * 640 * 480);
    assert!(
        2 * tracked_pixels < whole_pixels,
        "tracked {tracked_pixels} of {whole_pixels} back pixels"
    );
}

/// A sweep's eye parameter moves the driver's head with the eye (`Scene::move_eye`), so
/// `--head estimated` measures the swept eye: das with eye_x = 0.06 m is estimated within
/// 2 cm of the moved eye, not 6 cm off at the seat's.
#[test]
fn a_swept_eye_carries_the_head() {
    let base = common::das();
    let (scene, options) = seethru::measure::sweep_grid::configure(
        &base,
        &estimated(),
        &[("eye_x".to_string(), "0.06".to_string())],
    )
    .unwrap();
    assert!((scene.eye() - base.eye() - DVec3::new(0.06, 0.0, 0.0)).length() < 1e-12);
    let result = run(&RenderContext::new(scene).unwrap(), &options).unwrap();
    let error = result.report["eye_used"]["error_m"].as_f64().unwrap();
    assert!(error < 0.02, "{error} m from the swept eye");
}
