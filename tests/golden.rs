//! Golden images of each view of the das scene, small. They catch regressions only; what is
//! right is tested against analytic answers elsewhere.

mod common;

use common::golden;

use seethru::render::views::View;
use seethru::render::{integrator::RenderContext, render_job::RenderJob, settings::RenderSettings};
use seethru::system::{options::RunOptions, pipeline::run};
use seethru::util::color::encode_srgb8;

#[test]
fn views_match_their_goldens() {
    let ctx = RenderContext::new(common::das()).unwrap();
    for view in View::ALL {
        let camera = view.camera(&ctx.scene);
        let camera = if view == View::Back {
            camera.with_resolution(96, 72)
        } else {
            camera.with_resolution(192, 108)
        };
        let (frame, _) = ctx.render(
            RenderJob::new(&camera, view.bit())
                .settings(RenderSettings {
                    spp: 4,
                    progress: false,
                })
                .label(view.name()),
        );
        let img = image::RgbImage::from_fn(frame.width, frame.height, |x, y| {
            image::Rgb(encode_srgb8(frame.color[frame.index(x, y)]))
        });
        golden::check(view.name(), &img);
    }
}

fn to_image(frame: &seethru::render::frame::Frame) -> image::RgbImage {
    image::RgbImage::from_fn(frame.width, frame.height, |x, y| {
        image::Rgb(encode_srgb8(frame.color[frame.index(x, y)]))
    })
}

#[test]
fn display_and_seethru_match_their_goldens() {
    let ctx = RenderContext::new(common::das()).unwrap();
    let options = RunOptions {
        width: Some(192),
        frontal_width: Some(320),
        back_width: Some(160),
        spp: 4,
        ..RunOptions::default()
    };
    let result = run(&ctx, &options).unwrap();
    golden::check("display", &to_image(&result.display));
    golden::check("seethru", &to_image(&result.seethru));
}

#[test]
fn the_comparison_catches_a_small_regression() {
    let golden = image::open(common::repo_path("golden/truth.png"))
        .unwrap()
        .to_rgb8();
    assert!(golden::compare(&golden, &golden).is_ok());
    // A 12×12 patch recoloured (an object moved by a few pixels) must fail.
    let mut changed = golden.clone();
    for y in 40..52 {
        for x in 60..72 {
            changed.put_pixel(x, y, image::Rgb([255, 0, 255]));
        }
    }
    assert!(golden::compare(&changed, &golden).is_err());
    // One pixel off by a lot is within tolerance (a silhouette pixel flipping).
    let mut speck = golden.clone();
    speck.put_pixel(5, 5, image::Rgb([255, 0, 255]));
    assert!(golden::compare(&speck, &golden).is_ok());
}

#[test]
fn a_missing_golden_fails_and_is_not_written() {
    // In a folder without goldens, blessing another name: `truth` is compared, not written.
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbImage::new(4, 4);
    let checked =
        std::panic::catch_unwind(|| golden::check_in(dir.path(), "truth", &img, &["seethru"]));
    assert!(checked.is_err());
    assert!(!dir.path().join("truth.png").exists());
    assert!(common::repo_path("target/golden-failures/truth-actual.png").exists());
    // A name no test checks is refused before anything is compared or written.
    let unknown =
        std::panic::catch_unwind(|| golden::check_in(dir.path(), "no-such-view", &img, &[]));
    assert!(unknown.is_err());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn bless_rewrites_only_the_goldens_it_names() {
    // The variable's values: names (spaces ignored), `all`, unset; a typo lists the known.
    assert_eq!(
        golden::blessed(Some("truth, seethru")),
        Ok(vec!["truth", "seethru"])
    );
    assert_eq!(golden::blessed(Some("all")), Ok(golden::GOLDENS.to_vec()));
    assert_eq!(golden::blessed(None), Ok(vec![]));
    for typo in ["1", "truht", "truth,", "truth,seethru,displya"] {
        let e = golden::blessed(Some(typo)).unwrap_err();
        let bad = typo.rsplit(',').next().unwrap().trim();
        assert!(
            e.contains(&format!("unknown golden `{bad}`")),
            "{typo}: {e}"
        );
        assert!(golden::GOLDENS.iter().all(|g| e.contains(g)), "{typo}: {e}");
    }
    // Every golden the tests check is listed, and each listed one is in golden/.
    for name in golden::GOLDENS {
        assert!(
            common::repo_path(&format!("golden/{name}.png")).exists(),
            "{name}"
        );
    }
    // Blessing `seethru` in a folder holding both: only seethru.png is rewritten.
    let dir = tempfile::tempdir().unwrap();
    let old = image::RgbImage::from_pixel(4, 4, image::Rgb([10, 20, 30]));
    let new = image::RgbImage::from_pixel(4, 4, image::Rgb([200, 100, 0]));
    for name in ["truth", "seethru"] {
        old.save(dir.path().join(format!("{name}.png"))).unwrap();
    }
    let bless = golden::blessed(Some("seethru")).unwrap();
    golden::check_in(dir.path(), "seethru", &new, &bless);
    let truth = std::panic::catch_unwind(|| golden::check_in(dir.path(), "truth", &new, &bless));
    assert!(
        truth.is_err(),
        "truth differs and was not asked to be blessed"
    );
    let read = |name: &str| {
        image::open(dir.path().join(format!("{name}.png")))
            .unwrap()
            .to_rgb8()
    };
    assert_eq!(read("seethru"), new);
    assert_eq!(read("truth"), old);
}

#[test]
fn a_fisheye_frontal_render_matches_its_golden() {
    let scene = seethru::scene::Scene::load(&common::repo_path("scenes/das_fisheye.toml")).unwrap();
    let ctx = RenderContext::new(scene).unwrap();
    let camera = ctx.scene.frontal.with_resolution(192, 108);
    let settings = RenderSettings {
        spp: 4,
        progress: false,
    };
    let (frame, _) = ctx.render(
        RenderJob::new(&camera, View::Frontal.bit())
            .settings(settings)
            .label("frontal"),
    );
    // Every pixel's centre ray came through the lens: its world point projects back onto
    // the pixel's centre through the forward model.
    for y in 0..frame.height {
        for x in 0..frame.width {
            let p = frame.position[frame.index(x, y)];
            if p.is_finite() {
                let q = camera.project_point(p.as_dvec3()).unwrap();
                let centre = glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                assert!((q - centre).length() < 0.01, "({x}, {y}): {q}");
            }
        }
    }
    // Straight lines are curved: a line across the road 5 m ahead (not through the
    // principal point, which radial distortion keeps straight) does not project onto one
    // image line; through a pinhole it does.
    let across = [-4.0, 1.0, 6.0].map(|x| glam::DVec3::new(x, 0.0, -5.0));
    let edge = across.map(|p| camera.project_point(p).unwrap());
    let bend = |[a, b, c]: [glam::DVec2; 3]| (b - a).perp_dot(c - a).abs() / (c - a).length();
    assert!(
        bend(edge) > 2.0,
        "the fisheye bends the edge by {} px",
        bend(edge)
    );
    let pinhole = seethru::geometry::camera::Camera {
        lens: None,
        ..camera
    };
    let straight = across.map(|p| pinhole.project_point(p).unwrap());
    assert!(bend(straight) < 1e-6);
    golden::check("frontal_fisheye", &to_image(&frame));
}
