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
        assert!(err.contains("--ipd must be in (0, 0.1] m"), "{err}");
    }
}
