//! Real cameras: lens models in the scene file, calibration error, and what they cost —
//! each measured on rendered frames against a closed form or the pinhole camera.

mod common;

use common::{MINIMAL, parse, repo_path};
use glam::{DVec2, DVec3};
use seethru::analysis::binocular::{model_point_normalised, radial_error_px};
use seethru::geometry::camera::Camera;
use seethru::geometry::lens::Distortion;
use seethru::measure::metrics::measure;
use seethru::render::integrator::RenderContext;
use seethru::render::settings::resized;
use seethru::scene::Scene;
use seethru::scene::source::SourceFile;
use seethru::system::display::DisplayModel;
use seethru::system::options::RunOptions;
use seethru::system::pipeline::{RunResult, run};

const FRONTAL: &str = "[camera.frontal]\n";

fn with_frontal(keys: &str) -> String {
    MINIMAL.replacen(FRONTAL, &format!("{FRONTAL}{keys}\n"), 1)
}

#[test]
fn lens_keys_are_read_in_opencv_conventions() {
    let scene = parse(&with_frontal(
        "model = \"brown\"\nfx = 40.0\nfy = 41.0\ncx = 31.5\ncy = 17.0\nk1 = -0.05\np2 = 0.001",
    ))
    .unwrap();
    let lens = scene.frontal.lens.unwrap();
    assert_eq!(
        (lens.fx, lens.fy, lens.cx, lens.cy),
        (40.0, 41.0, 31.5, 17.0)
    );
    assert_eq!(
        lens.distortion,
        Distortion::Brown {
            k1: -0.05,
            k2: 0.0,
            k3: 0.0,
            p1: 0.0,
            p2: 0.001
        }
    );
    // OpenCV's principal point (31.5, 17) is seethru's (32, 17.5): the axis's pixel.
    let axis = scene
        .frontal
        .project_camera(DVec3::new(0.0, 0.0, -1.0))
        .unwrap();
    assert!((axis - DVec2::new(32.0, 17.5)).length() < 1e-12, "{axis}");
    // Without a model or intrinsics the camera is the ideal pinhole, as before.
    assert_eq!(parse(MINIMAL).unwrap().frontal.lens, None);
}

#[test]
fn bad_lens_keys_give_one_line_naming_file_line_and_key() {
    let cases: &[(&str, &str, &str)] = &[
        // (keys added to [camera.frontal], expected key, expected words)
        (
            "model = \"brown\"\nk1 = -0.9",
            "camera.frontal.k1",
            "folds (the lens map is not invertible) at undistorted radius 0.608",
        ),
        (
            "model = \"fisheye\"\nk1 = nan",
            "camera.frontal.k1",
            "must be in [-1000, 1000], got NaN",
        ),
        (
            "model = \"brown\"\nk2 = inf",
            "camera.frontal.k2",
            "must be in [-1000, 1000], got inf",
        ),
        // Nothing folds, but the image would see a sliver of the scene: no lens.
        (
            "model = \"brown\"\nk1 = 1e10",
            "camera.frontal.k1",
            "must be in [-1000, 1000], got 10000000000",
        ),
        (
            "model = \"fisheye\"\nk3 = -1e300",
            "camera.frontal.k3",
            "must be in [-1000, 1000], got -1e300",
        ),
        (
            "fx = 0.0",
            "camera.frontal.fx",
            "must be in (0, 10000000] pixels",
        ),
        ("fx = 30.0\nfy = -4", "camera.frontal.fy", "got -4"),
        (
            "model = \"brown\"\nk4 = 0.1",
            "camera.frontal.k4",
            "unknown key",
        ),
        (
            "model = \"zoom\"",
            "camera.frontal.model",
            "`zoom` is not one of: pinhole, brown, fisheye",
        ),
        (
            "fx = 30.0\nhalf_angle_deg = 40",
            "camera.frontal.half_angle_deg",
            "not both",
        ),
        (
            "model = \"fisheye\"\nfx = 8.0",
            "camera.frontal.fx",
            "89° or more off its axis",
        ),
    ];
    for &(keys, key, words) in cases {
        let text = with_frontal(keys);
        let err = parse(&text).expect_err(&format!("`{keys}` must be rejected"));
        let shown = err.to_string();
        assert_eq!(err.key, key, "{shown}");
        assert!(shown.contains(words), "`{shown}` lacks `{words}`");
        assert!(shown.starts_with("test-scenes/scene.toml:"), "{shown}");
        assert!(!shown.contains('\n'), "one line: {shown}");
        let last = key.rsplit('.').next().unwrap();
        let line = text
            .lines()
            .position(|l| l.starts_with(&format!("{last} =")))
            .unwrap()
            + 1;
        assert_eq!(err.line, Some(line), "{shown}");
    }
}

#[test]
fn bad_calibration_keys_are_refused() {
    let cases: &[(&str, &str, &str, &str)] = &[
        // (frontal keys, calibration table, expected key, words)
        (
            "",
            "[calibration.frontal]\nk1 = 0.0",
            "calibration.frontal.k1",
            "model = pinhole) has no coefficient k1",
        ),
        (
            "model = \"brown\"",
            "[calibration.frontal]\nk4 = 0.0",
            "calibration.frontal.k4",
            "has no coefficient k4",
        ),
        (
            "",
            "[calibration.frontal]\nfocal_error_percent = 80",
            "calibration.frontal.focal_error_percent",
            "must be in [-50, 50]",
        ),
        (
            "",
            "[calibration.back]\nyaw_error_deg = nan",
            "calibration.back.yaw_error_deg",
            "must be in [-10, 10], got NaN",
        ),
        (
            "",
            "[calibration.frontal]\nzoom = 1",
            "calibration.frontal.zoom",
            "unknown key",
        ),
        (
            "model = \"brown\"",
            "[calibration.frontal]\nk1 = -0.9",
            "calibration.frontal.k1",
            "the calibrated camera: the distortion folds",
        ),
    ];
    for &(frontal, calibration, key, words) in cases {
        let text = format!("{}\n{calibration}\n", with_frontal(frontal));
        let err = parse(&text).expect_err(&format!("`{calibration}` must be rejected"));
        let shown = err.to_string();
        assert_eq!(err.key, key, "{shown}");
        assert!(shown.contains(words), "`{shown}` lacks `{words}`");
        assert!(!shown.contains('\n'), "one line: {shown}");
    }
}

/// das.toml with `frontal` as its `[camera.frontal]` keys and `extra` appended.
fn das_with(frontal: &str, extra: &str) -> RenderContext {
    let path = repo_path("scenes/das.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let old = "[camera.frontal]\nhalf_angle_deg = 45.0        # θ_F\nresolution = [1280, 720]\n";
    assert!(
        text.contains(old),
        "test bug: das.toml's frontal camera changed"
    );
    let text = text.replacen(
        old,
        &format!("[camera.frontal]\n{frontal}\nresolution = [1280, 720]\n"),
        1,
    ) + extra;
    let scene = Scene::from_source(&SourceFile::from_text(&path, text)).unwrap();
    RenderContext::new(scene).unwrap()
}

fn small(display: DisplayModel) -> RunOptions {
    RunOptions {
        width: Some(240),
        frontal_width: Some(640),
        back_width: Some(160),
        spp: 1,
        display,
        ..RunOptions::default()
    }
}

fn misregistration_mean(ctx: &RenderContext, r: &RunResult) -> f64 {
    let (_, m) = measure(ctx, &ctx.scene, ctx.scene.eye(), r.measured_views(), 5);
    let m = m.to_json();
    assert_eq!(m["coverage"], 1.0);
    m["display"]["misregistration_arcmin"]["mean"]
        .as_f64()
        .unwrap()
}

const BROWN: &str = "half_angle_deg = 45.0\nmodel = \"brown\"\nk1 = -0.1\nk2 = 0.01\np1 = 0.001";

#[test]
fn a_distorted_frontal_camera_with_its_calibration_misregisters_as_the_pinhole() {
    let pinhole = RenderContext::new(common::das()).unwrap();
    let brown = das_with(BROWN, "");
    // Ideal display: only the geometry counts, and it is the same ray through a lens.
    let ideal = small(DisplayModel::Ideal);
    let a = misregistration_mean(&pinhole, &run(&pinhole, &ideal).unwrap());
    let b = misregistration_mean(&brown, &run(&brown, &ideal).unwrap());
    assert!(
        (a - b).abs() < 0.01,
        "ideal display: pinhole {a}′, brown {b}′"
    );
    // Physical display: the resampling differs (frontal pixels are denser or sparser through
    // the lens), by less than the angle of one frontal pixel (45°, 640 px; the barrel lens
    // spreads the periphery by at most 1/(1 + 3 k1 r²) ≈ 1.3 at the crop).
    let pixels = small(DisplayModel::Pixels);
    let a = misregistration_mean(&pinhole, &run(&pinhole, &pixels).unwrap());
    let b = misregistration_mean(&brown, &run(&brown, &pixels).unwrap());
    let quantum = 1.3 * (2.0 / 640.0f64).atan().to_degrees() * 60.0;
    assert!(
        (a - b).abs() < quantum,
        "pixels: pinhole {a}′, brown {b}′, quantum {quantum}′"
    );
}

/// Where `camera` sees what a frame pixel shows (its world point, or sky direction).
fn seen_at(camera: &Camera, r: &RunResult, i: usize) -> DVec2 {
    let p = r.seethru.position[i];
    if p.is_finite() {
        camera.project_point(p.as_dvec3()).unwrap()
    } else {
        camera
            .project_direction(-r.seethru.normal[i].as_dvec3())
            .unwrap()
    }
}

#[test]
fn ignoring_k1_costs_the_closed_form_at_the_crop_corners() {
    let k1 = -0.1;
    let frontal = format!("half_angle_deg = 45.0\nmodel = \"brown\"\nk1 = {k1}\nk2 = 0.02");
    let exact = das_with(&frontal, "");
    let ignoring = das_with(&frontal, "\n[calibration.frontal]\nk1 = 0.0\n");
    let options = small(DisplayModel::Ideal);
    let (re, ri) = (
        run(&exact, &options).unwrap(),
        run(&ignoring, &options).unwrap(),
    );
    let camera = resized(
        exact.scene.frontal,
        options.frontal_width,
        None,
        "--frontal-width",
    )
    .unwrap();
    let f = camera.lens.unwrap().fx;
    let obstacle = &exact.scene.obstacle;
    let eye = obstacle.in_obstacle_frame(exact.scene.eye());
    // The driver pixels whose display point is nearest each display corner.
    let (hw, hh) = (obstacle.width / 2.0, obstacle.height / 2.0);
    for corner in [(-hw, hh), (hw, hh), (hw, -hh), (-hw, -hh)] {
        let corner = DVec3::new(corner.0, corner.1, 0.0);
        let (i, on_display) = (0..re.occluded.position.len())
            .filter(|&i| re.occluded.object_id[i] == exact.world.obstacle_id)
            .map(|i| {
                (
                    i,
                    obstacle.in_obstacle_frame(re.occluded.position[i].as_dvec3()),
                )
            })
            .filter(|(_, p)| p.z.abs() < 1e-4)
            .min_by(|a, b| (a.1 - corner).length().total_cmp(&(b.1 - corner).length()))
            .unwrap();
        let measured = (seen_at(&camera, &ri, i) - seen_at(&camera, &re, i)).length();
        let r = model_point_normalised(eye, on_display, None).length();
        let predicted = radial_error_px(f, [k1, 0.02, 0.0], [0.0, 0.02, 0.0], r);
        assert!(
            predicted > 1.0,
            "the corner must see the distortion: {predicted} px"
        );
        assert!(
            (measured - predicted).abs() < 0.05 * predicted,
            "corner {corner}: measured {measured} px, closed form {predicted} px (r = {r})"
        );
    }
}

#[test]
fn a_distorted_back_camera_estimates_the_head_through_its_lens() {
    let estimated = RunOptions {
        head: seethru::system::options::HeadSource::Estimated,
        back_width: Some(320),
        ..small(DisplayModel::Pixels)
    };
    let error = |ctx: &RenderContext| {
        run(ctx, &estimated).unwrap().report["eye_used"]["error_m"]
            .as_f64()
            .unwrap()
    };
    let back = "[camera.back]\nhalf_angle_deg = 35.0\nmodel = \"brown\"\nk1 = -0.15\nk2 = 0.02\n";
    let with_back = |extra: &str| {
        let path = repo_path("scenes/das.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        let old = "[camera.back]\nhalf_angle_deg = 35.0\n";
        assert!(
            text.contains(old),
            "test bug: das.toml's back camera changed"
        );
        let scene = Scene::from_source(&SourceFile::from_text(
            &path,
            text.replacen(old, back, 1) + extra,
        ))
        .unwrap();
        RenderContext::new(scene).unwrap()
    };
    let pinhole = error(&RenderContext::new(common::das()).unwrap());
    let through_lens = error(&with_back(""));
    let ignoring = error(&with_back(
        "\n[calibration.back]\nignore_distortion = true\n",
    ));
    // Through its lens the estimate is as good as the pinhole's (1 cm at 320 px: one pixel
    // of the 64 mm feature is about that); believing a pinhole is not.
    assert!(
        through_lens < pinhole.max(0.01) * 1.5,
        "through the lens {through_lens} m, pinhole {pinhole} m"
    );
    assert!(
        ignoring > 2.0 * through_lens.max(0.005),
        "ignoring the distortion {ignoring} m vs {through_lens} m"
    );
}

#[test]
fn a_bad_calibration_file_is_one_line_naming_its_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    for (text, key, words) in [
        (
            "# comment\n[calibration.frontal]\nfocal_error_percent = 99\n",
            "calibration.frontal.focal_error_percent",
            ":3:",
        ),
        ("[camera.frontal]\nfx = 3\n", "camera", "unknown key"),
    ] {
        let file = dir.path().join("cal.toml");
        std::fs::write(&file, text).unwrap();
        let out = dir.path().join("out");
        let (ok, _, err) = common::seethru(&[
            "run",
            "scenes/das.toml",
            "--out",
            out.to_str().unwrap(),
            "--calibration",
            file.to_str().unwrap(),
            "--width",
            "32",
        ]);
        assert!(!ok);
        let err = err.trim_end();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("error: ") && err.contains("cal.toml"),
            "{err}"
        );
        assert!(err.contains(key) && err.contains(words), "{err}");
        assert!(!out.exists(), "nothing written");
    }
}

/// The model point of a display point at a finite d2 is where the eye's ray through it meets
/// the plane z = −d2: the point the returned normalised coordinates name on that plane (the
/// frontal camera at the origin looking down −z, y down) is on the line from the eye through
/// the display point.
#[test]
fn the_model_point_at_a_finite_d2_is_on_the_eyes_ray() {
    for eye in [
        DVec3::new(0.0, 0.0, 0.8),
        DVec3::new(-0.35, 0.12, 0.6),
        DVec3::new(0.2, -0.05, 1.1),
    ] {
        for on_display in [DVec3::new(0.1, 0.2, 0.0), DVec3::new(-0.125, -0.225, 0.0)] {
            for d2 in [0.5, 3.0, 20.0] {
                let n = model_point_normalised(eye, on_display, Some(d2));
                let on_plane = DVec3::new(n.x * d2, -n.y * d2, -d2);
                let (ray, to_point) = (on_display - eye, on_plane - eye);
                let off_ray = ray.cross(to_point).length() / ray.length();
                assert!(
                    off_ray < 1e-12 * to_point.length(),
                    "eye {eye} display {on_display} d2 {d2}: {off_ray} m off the ray"
                );
                // Beyond the display, not behind the eye.
                assert!(to_point.dot(ray) > ray.length_squared());
            }
        }
    }
}

/// `radial_error_px` is the distance, in pixels, between where the true lens and the believed
/// one put a ray of undistorted radius r: f·|r·(1 + k1 r² + k2 r⁴ + k3 r⁶) − the same with the
/// believed k| (Brown–Conrady, radial terms), here with every coefficient differing.
#[test]
fn the_radial_error_is_the_distance_between_two_distortions() {
    let distorted = |k: [f64; 3], r: f64| {
        let r2 = r * r;
        r * (1.0 + k[0] * r2 + k[1] * r2 * r2 + k[2] * r2 * r2 * r2)
    };
    let f = 900.0;
    for (truth, believed) in [
        ([-0.28, 0.09, -0.012], [-0.2, 0.02, 0.004]),
        ([0.05, -0.3, 0.2], [0.0, 0.1, -0.05]),
    ] {
        for r in [0.1, 0.45, 0.9] {
            let expected = f * (distorted(truth, r) - distorted(believed, r)).abs();
            let got = radial_error_px(f, truth, believed, r);
            assert!(
                (got - expected).abs() <= 1e-9 * expected,
                "{truth:?} vs {believed:?} at r {r}: {got} px, expected {expected}"
            );
        }
    }
}

/// The display's corners, top-left, top-right, bottom-right, bottom-left, are where the
/// display's own pixel coordinates (the renderer's mapping of a point on it) are the image's
/// corners.
#[test]
fn the_display_corners_are_where_its_pixel_coordinates_are_the_image_corners() {
    use seethru::analysis::binocular::display_corners;
    use seethru::system::display::DisplayPlacement;
    let scene = common::das();
    let o = &scene.obstacle;
    let placement = DisplayPlacement::new(o);
    let [w, h] = o.display_resolution.map(|v| v as f64);
    let expected = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)];
    for (corner, (x, y)) in display_corners(o.width, o.height).iter().zip(expected) {
        let world = o.world_from_obstacle.transform_point3(*corner).as_vec3();
        let at = placement.pixel_coords(world);
        assert!(
            (at - DVec2::new(x, y)).length() < 1e-3,
            "corner {corner} is at display pixel {at}, expected ({x}, {y})"
        );
    }
}
