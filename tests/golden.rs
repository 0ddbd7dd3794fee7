//! Golden images of each view of the das scene, small. They catch regressions only; what is
//! right is tested against analytic answers elsewhere.

mod common;

use common::golden;

use seethru::render::views::View;
use seethru::render::{integrator::RenderContext, settings::RenderSettings};
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
            &camera,
            view.bit(),
            RenderSettings {
                spp: 4,
                progress: false,
            },
            view.name(),
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
    if std::env::var("SEETHRU_BLESS").is_ok_and(|v| v == "1") {
        return; // Blessing writes goldens by design.
    }
    let img = image::RgbImage::new(4, 4);
    assert!(std::panic::catch_unwind(|| golden::check("no-such-view", &img)).is_err());
    assert!(!common::repo_path("golden/no-such-view.png").exists());
    assert!(common::repo_path("target/golden-failures/no-such-view-actual.png").exists());
}
