//! Two eyes: the binocular mismatch of a flat display, measured on the rendered display frame
//! of a plane scene against the closed form, and the eyes a run looks with.

mod common;

use seethru::analysis::binocular::disparity_mismatch;
use seethru::measure::binocular::binocular_map;
use seethru::system::eyes::{Eye, Eyes};
use seethru::system::options::{RunOptions, WorkingDistance};
use seethru::system::pipeline::run;

#[test]
fn the_binocular_mismatch_on_a_plane_matches_the_closed_form_at_every_display_pixel() {
    let (d1, d2, ipd) = (1.0, 6.0, 0.064);
    let ctx = common::WallScene {
        wall: d2,
        eye: [0.0, 0.0, d1],
        ..Default::default()
    }
    .context();
    let options = |view| RunOptions {
        d2: WorkingDistance::Metres(d2),
        spp: 1,
        eyes: Eyes {
            view,
            target: Eye::Cyclopean,
            ipd,
        },
        ..RunOptions::default()
    };
    let left = run(&ctx, &options(Eye::Left)).unwrap();
    let right = run(&ctx, &options(Eye::Right)).unwrap();
    // The compensation serves the cyclopean eye in both runs: one display image.
    assert!(left.display.bit_identical(&right.display));
    // The eyes see it from different places.
    assert!(!left.seethru.bit_identical(&right.seethru));
    let driver = &ctx.scene.driver;
    let eyes = options(Eye::Left).eyes;
    let (l, r) = (
        eyes.position(driver, Eye::Left),
        eyes.position(driver, Eye::Right),
    );
    assert!(((r - l).length() - ipd).abs() < 1e-12);
    let map = binocular_map(&left.display, &ctx.scene.obstacle, l, r);
    let expected = disparity_mismatch(ipd, d1, d2).to_degrees() * 60.0;
    let pixel_arcmin = (2.0 * driver.tan_half_x() / driver.width as f64)
        .atan()
        .to_degrees()
        * 60.0;
    let mut worst = 0.0f64;
    for &m in &map.mismatch_arcmin {
        assert!(m.is_finite(), "every display pixel sees the wall");
        worst = worst.max((m as f64 - expected).abs());
    }
    assert!(
        worst < pixel_arcmin,
        "closed form {expected}′, worst deviation {worst}′, one driver pixel {pixel_arcmin}′"
    );
    // And the mismatch is not small: hundreds of arc-minutes.
    assert!(expected > 150.0, "{expected}");
}

#[test]
fn the_ipd_is_checked() {
    let ctx = common::WallScene::default().context();
    for ipd in [0.0, -0.01, 0.2, f64::NAN] {
        let options = RunOptions {
            eyes: Eyes {
                ipd,
                ..Eyes::default()
            },
            ..RunOptions::default()
        };
        let err = run(&ctx, &options)
            .err()
            .expect("bad ipd refused")
            .to_string();
        assert!(err.contains("option `ipd` must be in (0, 0.1] m"), "{err}");
    }
}

#[test]
fn run_with_both_eyes_writes_each_eye_the_mismatch_and_the_anaglyph_of_their_views() {
    let out = tempfile::tempdir().unwrap();
    let (ok, _, err) = common::seethru(&[
        "run",
        "scenes/wall_brown.toml",
        "--out",
        out.path().to_str().unwrap(),
        "--d2",
        "6",
        "--eyes",
        "both",
        "--quiet",
    ]);
    assert!(ok, "{err}");
    let png = |p: &str| image::open(out.path().join(p)).unwrap().to_rgb8();
    let (left, right, anaglyph) = (
        png("left/seethru.png"),
        png("right/seethru.png"),
        png("anaglyph.png"),
    );
    assert_ne!(left, right);
    for ((l, r), a) in left.pixels().zip(right.pixels()).zip(anaglyph.pixels()) {
        assert_eq!(a.0, [l.0[0], r.0[1], r.0[2]]);
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("binocular.json")).unwrap())
            .unwrap();
    // Every display pixel is counted: measured or missing.
    assert_eq!(json["display_pixels"], 300 * 200);
    assert_eq!(json["measured_pixels"], 300 * 200);
    // The wall is 6 m behind the display, the eyes 0.8 m before it: the closed form there.
    let closed = json["closed_form_arcmin"].as_f64().unwrap();
    assert!((closed - disparity_mismatch(0.064, 0.8, 6.0).to_degrees() * 60.0).abs() < 1.0);
    let m = &json["mismatch_arcmin"];
    let off_axis = json["closed_form_off_axis_arcmin"].as_f64().unwrap();
    assert!(
        (m["median"].as_f64().unwrap() - off_axis).abs() < 0.03 * off_axis,
        "{json}"
    );
    // Each eye's run is complete: its metrics, measured from that eye.
    for eye in ["left", "right"] {
        let run: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.path().join(eye).join("run.json")).unwrap(),
        )
        .unwrap();
        let x = run["eyes"]["view_world_m"][0].as_f64().unwrap();
        let side = if eye == "left" { -1.0 } else { 1.0 };
        assert!(side * (x - 0.3) > 0.03, "{eye}: {x}");
        assert!(out.path().join(eye).join("metrics.json").exists());
    }
}

#[test]
fn the_compensation_serves_the_target_eye() {
    let ctx = common::WallScene::default().context();
    let driver = &ctx.scene.driver;
    for target in [Eye::Cyclopean, Eye::Left, Eye::Right] {
        let eyes = Eyes {
            target,
            ..Eyes::default()
        };
        let r = run(
            &ctx,
            &RunOptions {
                spp: 1,
                eyes,
                ..RunOptions::default()
            },
        )
        .unwrap();
        let expected = eyes.position(driver, target);
        assert!((r.eye_used - expected).length() < 1e-12, "{target:?}");
        // The driver's views are still the cyclopean eye's (`--eyes mono`).
        assert_eq!(
            r.report["eyes"]["view_world_m"][0].as_f64().unwrap(),
            driver.position().x
        );
    }
}

#[test]
fn analyze_prints_the_mismatch_the_renderer_measures_on_a_plane() {
    let (ok, stdout, err) = common::seethru(&[
        "analyze", "--json", "--d1", "1", "--d2", "6", "--ipd", "0.064",
    ]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let printed = json["lens_and_eyes"]["disparity_mismatch"]["arcmin"]
        .as_f64()
        .unwrap();
    // The display-centre pixel of the plane scene of the first test, rendered.
    let ctx = common::WallScene {
        wall: 6.0,
        eye: [0.0, 0.0, 1.0],
        ..Default::default()
    }
    .context();
    let r = run(
        &ctx,
        &RunOptions {
            d2: WorkingDistance::Metres(6.0),
            spp: 1,
            ..RunOptions::default()
        },
    )
    .unwrap();
    let eyes = Eyes::default();
    let driver = &ctx.scene.driver;
    let (l, rr) = (
        eyes.position(driver, Eye::Left),
        eyes.position(driver, Eye::Right),
    );
    let map = binocular_map(&r.display, &ctx.scene.obstacle, l, rr);
    let centre = (map.height / 2 * map.width + map.width / 2) as usize;
    let measured = map.mismatch_arcmin[centre] as f64;
    assert!(
        (measured - printed).abs() < 1.0,
        "analyze {printed}′, rendered {measured}′"
    );
}

#[test]
fn measure_recomputes_a_one_eye_run_from_that_eye() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().to_str().unwrap();
    let args = [
        "run",
        "scenes/wall_brown.toml",
        "--out",
        dir,
        "--d2",
        "6",
        "--exr",
        "all",
    ];
    let (ok, _, err) = common::seethru(&[&args[..], &["--eyes", "left", "--quiet"]].concat());
    assert!(ok, "{err}");
    let written = std::fs::read_to_string(out.path().join("metrics.json")).unwrap();
    let (ok, _, err) = common::seethru(&["measure", dir, "--quiet"]);
    assert!(ok, "{err}");
    let recomputed = std::fs::read_to_string(out.path().join("metrics.json")).unwrap();
    assert_eq!(written, recomputed);
    // From the cyclopean eye the same frames would misregister differently.
    let json: serde_json::Value = serde_json::from_str(&written).unwrap();
    assert!(
        json["display"]["misregistration_arcmin"]["mean"]
            .as_f64()
            .unwrap()
            > 60.0
    );
}
