//! The renderer against analytic answers, and its determinism.

mod common;

use glam::{DVec2, DVec3};
use seethru::io::frame_files::{read_exr, write_exr};
use seethru::render::frame::Frame;
use seethru::render::views::View;
use seethru::render::{integrator::RenderContext, settings::RenderSettings};
use seethru::scene::world::view_bit;

fn minimal_context() -> RenderContext {
    RenderContext::new(common::parse(common::MINIMAL).unwrap()).unwrap()
}

/// Ray–sphere distance in f64, or None.
fn sphere_distance(origin: DVec3, dir: DVec3, centre: DVec3, radius: f64) -> Option<f64> {
    let oc = origin - centre;
    let b = oc.dot(dir);
    let disc = b * b - (oc.length_squared() - radius * radius);
    (disc >= 0.0).then(|| -b - disc.sqrt())
}

#[test]
fn sphere_and_plane_depths_are_analytic() {
    let ctx = minimal_context();
    let camera = ctx.scene.driver.with_resolution(160, 90);
    let (frame, _) = ctx.render(&camera, view_bit::TRUTH, RenderSettings::default(), "test");
    let (mut sphere_pixels, mut ground_pixels) = (0, 0);
    for y in 0..frame.height {
        for x in 0..frame.width {
            let px = frame.pixel(x, y);
            let (origin, dir) = camera.world_ray(DVec2::new(x as f64 + 0.5, y as f64 + 0.5));
            let sphere = sphere_distance(origin, dir, DVec3::new(0.0, 1.0, -10.0), 1.0);
            let ground = (dir.y < 0.0).then(|| -origin.y / dir.y).filter(|&t| {
                let p = origin + dir * t;
                p.x.abs() < 50.0 && p.z.abs() < 50.0
            });
            let expected = match (sphere, ground) {
                (Some(s), Some(g)) => Some((s.min(g), if s < g { 2 } else { 1 })),
                (Some(s), None) => Some((s, 2)),
                (None, Some(g)) => Some((g, 1)),
                (None, None) => None,
            };
            match expected {
                None => assert_eq!(px.object_id, 0, "pixel {x},{y} should be sky"),
                Some((t, id)) => {
                    assert_eq!(px.object_id, id, "pixel {x},{y}");
                    // f32 ray tracing: relative error of a few ulps of the coordinates.
                    assert!(
                        (px.depth as f64 - t).abs() < 2e-5 * t.max(1.0),
                        "pixel {x},{y}: {} vs {t}",
                        px.depth
                    );
                    let expected_z = camera.axial_depth(origin + dir * t);
                    assert!((px.camera_z as f64 - expected_z).abs() < 2e-5 * t.max(1.0));
                    let p = (origin + dir * t).as_vec3();
                    assert!((px.position - p).length() < 2e-5 * t.max(1.0) as f32);
                    if id == 2 {
                        sphere_pixels += 1;
                        let n = (origin + dir * t - DVec3::new(0.0, 1.0, -10.0)).as_vec3();
                        assert!((px.normal - n).length() < 1e-3, "{} vs {n}", px.normal);
                    } else {
                        ground_pixels += 1;
                        assert!((px.normal - glam::Vec3::Y).length() < 1e-6);
                    }
                }
            }
        }
    }
    assert!(
        sphere_pixels > 50 && ground_pixels > 1000,
        "{sphere_pixels} {ground_pixels}"
    );
}

#[test]
fn images_do_not_depend_on_the_thread_count() {
    let ctx = RenderContext::new(common::das()).unwrap();
    let settings = RenderSettings {
        spp: 3,
        progress: false,
    };
    for view in [View::Truth, View::Occluded] {
        let camera = view.camera(&ctx.scene).with_resolution(120, 68);
        let render = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| ctx.render(&camera, view.bit(), settings, "test").0)
        };
        let (one, two, three) = (render(1), render(2), render(3));
        assert!(
            one.bit_identical(&two) && one.bit_identical(&three),
            "{view:?}"
        );
        // Not a trivially constant image.
        assert!(one.object_id.iter().any(|&i| i != one.object_id[0]));
    }
}

#[test]
fn exr_round_trip_keeps_every_aov_bit_exact() {
    let ctx = minimal_context();
    let (frame, _) = ctx.render(
        &ctx.scene.driver,
        view_bit::TRUTH,
        RenderSettings {
            spp: 2,
            progress: false,
        },
        "test",
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame.exr");
    write_exr(&frame, &path).unwrap();
    let back: Frame = read_exr(&path).unwrap();
    assert!(frame.bit_identical(&back));
    // Only the file itself: the temporary was renamed, not left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn simple_exr_readers_find_the_colour_as_plain_rgba() {
    // What OpenCV, imageio and "first RGBA layer" readers do: take R, G, B (and A) of the
    // first part. They must get the linear colour, bit for bit, and the AOV layers must sit
    // under the names docs/reference/outputs.md documents.
    let ctx = minimal_context();
    let (frame, _) = ctx.render(
        &ctx.scene.driver,
        view_bit::TRUTH,
        RenderSettings::default(),
        "test",
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame.exr");
    write_exr(&frame, &path).unwrap();
    let width = frame.width as usize;
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |resolution, _| vec![[0f32; 4]; resolution.width() * resolution.height()],
        move |pixels, position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * width + position.x()] = [r, g, b, a];
        },
    )
    .unwrap();
    let rgba = &image.layer_data.channel_data.pixels;
    assert_eq!(rgba.len(), frame.color.len());
    for (pixel, color) in rgba.iter().zip(&frame.color) {
        assert_eq!(pixel[..3], color.to_array());
        assert_eq!(pixel[3], 1.0);
    }
    let meta = exr::meta::MetaData::read_from_file(&path, false).unwrap();
    assert_eq!(meta.headers.len(), 1, "one part");
    let names: Vec<String> = meta.headers[0]
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    for name in [
        "R",
        "G",
        "B",
        "A",
        "Z",
        "camera_z.Z",
        "P.X",
        "P.Y",
        "P.Z",
        "N.X",
        "N.Y",
        "N.Z",
        "id.object",
        "id.part",
    ] {
        assert!(
            names.iter().any(|n| n == name),
            "{name} missing from {names:?}"
        );
    }
}

#[test]
fn more_samples_smooth_edges_but_keep_centre_aovs() {
    let ctx = minimal_context();
    let one = ctx
        .render(
            &ctx.scene.driver,
            view_bit::TRUTH,
            RenderSettings {
                spp: 1,
                progress: false,
            },
            "t",
        )
        .0;
    let many = ctx
        .render(
            &ctx.scene.driver,
            view_bit::TRUTH,
            RenderSettings {
                spp: 16,
                progress: false,
            },
            "t",
        )
        .0;
    assert_eq!(one.object_id, many.object_id);
    assert_eq!(one.depth, many.depth);
    // Anti-aliasing changes colours on silhouettes only.
    let changed = one
        .color
        .iter()
        .zip(&many.color)
        .filter(|(a, b)| (**a - **b).abs().max_element() > 0.02)
        .count();
    assert!(changed > 0 && changed < one.color.len() / 4, "{changed}");
}
