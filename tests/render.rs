//! The renderer against analytic answers, and its determinism.

mod common;

use glam::{DVec2, DVec3};
use seethru::io::frame_files::{read_exr, write_exr};
use seethru::render::frame::Frame;
use seethru::render::views::View;
use seethru::render::{integrator::RenderContext, render_job::RenderJob, settings::RenderSettings};
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
    let (frame, _) = ctx.render(RenderJob::new(&camera, view_bit::TRUTH).label("test"));
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
            pool.install(|| {
                ctx.render(
                    RenderJob::new(&camera, view.bit())
                        .settings(settings)
                        .label("test"),
                )
                .0
            })
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
        RenderJob::new(&ctx.scene.driver, view_bit::TRUTH)
            .settings(RenderSettings {
                spp: 2,
                progress: false,
            })
            .label("test"),
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
    let (frame, _) = ctx.render(RenderJob::new(&ctx.scene.driver, view_bit::TRUTH).label("test"));
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
            RenderJob::new(&ctx.scene.driver, view_bit::TRUTH)
                .settings(RenderSettings {
                    spp: 1,
                    progress: false,
                })
                .label("t"),
        )
        .0;
    let many = ctx
        .render(
            RenderJob::new(&ctx.scene.driver, view_bit::TRUTH)
                .settings(RenderSettings {
                    spp: 16,
                    progress: false,
                })
                .label("t"),
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

/// Every tracer: one ray at a time, and 4×4 packets on each instruction set this CPU has.
fn tracers() -> Vec<seethru::render::render_job::Tracer> {
    use seethru::render::render_job::Tracer;
    use seethru::render::simd::Isa;
    let mut out = vec![Tracer::PerRay];
    out.extend(
        Isa::ALL
            .into_iter()
            .filter(|i| i.available())
            .map(Tracer::Packets),
    );
    out
}

/// `job` on a pool of `threads` worker threads.
fn on_threads<T: Send>(threads: usize, job: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(job)
}

#[test]
fn packets_render_every_view_as_the_per_ray_path_does_on_every_isa_and_thread_count() {
    use seethru::system::display::{DisplayModel, DisplayPlacement, DisplaySurface, IdealMap};
    use seethru::system::{options::RunOptions, pipeline::run};
    let ctx = RenderContext::new(common::das()).unwrap();
    // Sizes that cut the last tiles of a band; three samples per pixel.
    let settings = RenderSettings {
        spp: 3,
        progress: false,
    };
    let tracers = tracers();
    for view in [View::Truth, View::Occluded, View::Frontal, View::Back] {
        let camera = view.camera(&ctx.scene).with_resolution(70, 41);
        let want = on_threads(1, || {
            ctx.render(
                RenderJob::new(&camera, view.bit())
                    .settings(settings)
                    .tracer(tracers[0]),
            )
            .0
        });
        for &tracer in &tracers {
            for threads in [1, 3] {
                let got = on_threads(threads, || {
                    ctx.render(
                        RenderJob::new(&camera, view.bit())
                            .settings(settings)
                            .tracer(tracer),
                    )
                    .0
                });
                assert!(
                    got.bit_identical(&want),
                    "{view:?} {tracer:?} on {threads} threads"
                );
            }
        }
    }
    // The seethru view: where a ray meets the display, its image (pixels) or the frontal
    // camera's own ray and shading (ideal), traced one by one inside the packets.
    for display in [DisplayModel::Pixels, DisplayModel::Ideal] {
        let options = RunOptions {
            width: Some(64),
            display,
            back_width: Some(32),
            frontal_width: Some(160),
            ..RunOptions::default()
        };
        let r = run(&ctx, &options).unwrap();
        let placement = DisplayPlacement::new(&ctx.scene.obstacle);
        let mut frontal = ctx.scene.frontal;
        frontal = frontal.with_resolution(160, 160 * frontal.height / frontal.width);
        let surface = match display {
            DisplayModel::Pixels => DisplaySurface::Pixels {
                image: r.display.clone(),
                placement,
                scan: None,
            },
            DisplayModel::Ideal => DisplaySurface::Ideal {
                map: IdealMap::Crop {
                    crop: r.crop,
                    lens: None,
                },
                frontal,
                placement,
            },
        };
        let driver = ctx.scene.driver.with_resolution(70, 41);
        let want = ctx
            .render(
                RenderJob::seethru(&driver, &surface)
                    .settings(settings)
                    .tracer(tracers[0]),
            )
            .0;
        // The display covers some pixels: the comparison sees it.
        let shown = want
            .object_id
            .iter()
            .zip(
                &ctx.render(
                    RenderJob::new(&driver, View::Occluded.bit())
                        .settings(settings)
                        .tracer(tracers[0]),
                )
                .0
                .object_id,
            )
            .filter(|(a, b)| a != b)
            .count();
        assert!(shown > 20, "{display:?}: {shown}");
        for &tracer in &tracers {
            let got = on_threads(2, || {
                ctx.render(
                    RenderJob::seethru(&driver, &surface)
                        .settings(settings)
                        .tracer(tracer),
                )
                .0
            });
            assert!(got.bit_identical(&want), "{display:?} {tracer:?}");
        }
    }
}

#[test]
fn packets_trace_a_sequences_moving_part_as_the_per_ray_path_does() {
    use seethru::system::options::RunOptions;
    use seethru::system::sequence::head_motion::HeadMotion;
    use seethru::system::sequence::predict::Prediction;
    use seethru::system::sequence::system_loop::{SequenceOptions, SystemLoop};
    use seethru::system::sequence::timeline::Timeline;
    // The ball rolls, the head leans and the rig drives and turns: as tests/sequence.rs.
    let options = SequenceOptions {
        run: RunOptions {
            speed_kmh: 50.0,
            yaw_rate_deg_s: 0.1f64.to_degrees(),
            ..RunOptions::default()
        },
        timeline: Timeline {
            duration: 2.0,
            fps: 10.0,
            display_hz: 10.0,
            latency_camera: 0.0,
            latency_tracking: 0.0,
        },
        head: HeadMotion::Lean {
            distance: 0.1,
            duration: 0.3,
            start: 0.0,
        },
        predict: Prediction::None,
        reproject: false,
        byo: Default::default(),
    };
    let mut system = SystemLoop::new(&common::das(), options).unwrap();
    let layered = system.context_at(1.5).unwrap();
    assert!(layered.moving.is_some());
    let settings = RenderSettings::default();
    let s = &layered.scene;
    let tracers = tracers();
    for (camera, view) in [
        (s.frontal.with_resolution(90, 50), view_bit::FRONTAL),
        (s.driver.with_resolution(90, 50), view_bit::OCCLUDED),
        (s.back.with_resolution(66, 50), view_bit::BACK),
    ] {
        let want = layered
            .render(
                RenderJob::new(&camera, view)
                    .settings(settings)
                    .tracer(tracers[0]),
            )
            .0;
        for &tracer in &tracers[1..] {
            let got = layered
                .render(
                    RenderJob::new(&camera, view)
                        .settings(settings)
                        .tracer(tracer),
                )
                .0;
            assert!(got.bit_identical(&want), "view {view} {tracer:?}");
        }
    }
}

/// `trace_fan`, up to 16 rays as one packet, meets what `trace` meets ray by ray, with a
/// sequence's moving part (the ball rolled, the rig driven), rays left out and a short last
/// fan.
#[test]
fn a_fan_of_rays_meets_what_each_ray_meets() {
    use seethru::render::bvh_packet::{PACKET, PacketStack};
    use seethru::system::sequence::system_loop::SystemLoop;
    let mut options = common::still_sequence(Default::default(), 2.0, 10.0, 0.0);
    options.run.speed_kmh = 50.0;
    let mut system = SystemLoop::new(&common::das(), options).unwrap();
    let layered = system.context_at(1.5).unwrap();
    assert!(layered.moving.is_some(), "das's ball rolls");
    let eye = layered.scene.driver.position().as_vec3();
    let driver = layered.scene.driver.with_resolution(97, 53);
    // Every third ray left out; 97 × 53 rays end in a fan of 5.
    let dirs: Vec<Option<glam::Vec3>> = (0..97 * 53)
        .map(|i| {
            let pixel = DVec2::new((i % 97) as f64 + 0.5, (i / 97) as f64 + 0.5);
            (i % 3 != 1).then(|| driver.world_ray(pixel).1.as_vec3())
        })
        .collect();
    let mut stack = PacketStack::new();
    let mut got = Vec::new();
    for fan in dirs.chunks(PACKET) {
        let hits = layered.trace_fan(eye, fan, view_bit::OCCLUDED, &mut stack);
        assert!(hits[fan.len()..].iter().all(Option::is_none));
        got.extend_from_slice(&hits[..fan.len()]);
    }
    let want: Vec<_> = dirs
        .iter()
        .map(|d| d.and_then(|d| layered.trace(eye, d, view_bit::OCCLUDED)))
        .collect();
    assert_eq!(got, want);
    let moved = want
        .iter()
        .filter(|h| h.is_some_and(|h| h.material >= layered.world.materials.len() as u32))
        .count();
    let missed = want
        .iter()
        .zip(&dirs)
        .filter(|(h, d)| d.is_some() && h.is_none())
        .count();
    assert!(
        moved > 0 && missed > 0,
        "{moved} on the moving part, {missed} to the sky"
    );
}
