//! A `--calibration` file (a `[calibration]` table) → the believed cameras: no panic; an
//! accepted calibration applies to its true camera; an error is one line.
#![no_main]

use std::path::Path;

use glam::{DAffine3, DVec3};
use libfuzzer_sys::fuzz_target;
use seethru::geometry::camera::Camera;
use seethru::geometry::lens::{Distortion, Lens};
use seethru::scene::lens_keys::calibration_from_source;
use seethru::scene::source::SourceFile;

/// The true cameras: a pinhole, a Brown and a fisheye lens, so that every coefficient key
/// is admissible for one of them and refused for another.
fn cameras() -> [Camera; 3] {
    let pose = DAffine3::from_translation(DVec3::new(0.0, 1.0, 0.5));
    let pinhole = Camera::look_at(DVec3::ZERO, -DVec3::Z, DVec3::Y, 0.7, 64, 48).unwrap();
    let lens = |distortion| Lens {
        fx: 40.0,
        fy: 40.0,
        cx: 31.5,
        cy: 23.5,
        distortion,
    };
    let brown = Distortion::Brown {
        k1: -0.1,
        k2: 0.01,
        k3: 0.0,
        p1: 0.001,
        p2: -0.001,
    };
    let fisheye = Distortion::Fisheye {
        k1: -0.01,
        k2: 0.001,
        k3: 0.0,
        k4: 0.0,
    };
    [
        pinhole,
        Camera::with_lens(pose, lens(brown), 64, 48).unwrap(),
        Camera::with_lens(pose, lens(fisheye), 64, 48).unwrap(),
    ]
}

fuzz_target!(|data: &[u8]| {
    let Some((&pick, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    // Built once: each lens camera checks its distortion over the whole image, which
    // dominated an execution when rebuilt for every input.
    static CAMERAS: std::sync::LazyLock<[Camera; 3]> = std::sync::LazyLock::new(cameras);
    let cameras = &*CAMERAS;
    let frontal = &cameras[pick as usize % 3];
    let back = &cameras[(pick as usize / 3) % 3];
    let file = SourceFile::from_text(Path::new("calibration.toml"), text.to_string());
    match calibration_from_source(&file, frontal, back) {
        Ok(c) => {
            for (calibration, truth) in [(c.frontal, frontal), (c.back, back)] {
                let believed = calibration
                    .apply(truth)
                    .expect("an accepted calibration applies");
                assert!(believed.world_from_camera.is_finite());
                let centre = glam::DVec2::new(32.0, 24.0);
                assert!(believed.world_ray(centre).1.is_finite());
            }
        }
        Err(e) => {
            let shown = e.to_string();
            assert!(
                shown.starts_with("calibration.toml") && !shown.contains('\n'),
                "{shown}"
            );
        }
    }
});
