//! The sequence's head tracker renders the back camera only around the last face and detects
//! there (`system/head.rs` `detect_in`, `system/sequence/back_tracker.rs` `BackTracker`): its
//! estimates against the whole image's, bit for bit.

mod common;

use glam::DVec3;
use seethru::render::footprint::PixelRect;
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::RenderSettings;
use seethru::render::views::View;
use seethru::system::head::{DetectError, detect, detect_in};
use seethru::system::options::{HeadSource, Outside, RunOptions};
use seethru::system::sequence::head_motion::HeadMotion;
use seethru::system::sequence::predict::Prediction;
use seethru::system::sequence::system_loop::{SequenceOptions, SystemLoop};
use seethru::system::sequence::timeline::Timeline;

/// The back camera's 320×240 image of das's driver with the head moved by `offset` (m,
/// world frame).
fn back_image(offset: DVec3) -> seethru::render::frame::Frame {
    let mut scene = common::das();
    let head = ["head", "hair", "left_eye", "right_eye"];
    for object in scene
        .objects
        .iter_mut()
        .filter(|o| head.contains(&o.name.as_str()))
    {
        object.world_from_object.translation += offset;
    }
    let ctx = RenderContext::new(scene).unwrap();
    let back = ctx.scene.back.with_resolution(320, 240);
    let settings = RenderSettings {
        spp: 4,
        progress: false,
    };
    ctx.render(
        RenderJob::new(&back, View::Back.bit())
            .settings(settings)
            .label("back"),
    )
    .0
}

/// The pixels `detect_in` says it depended on are enough: searching only them gives the
/// whole image's detection bit for bit, on das's head still and moved. A region one column
/// short of them is reported as not whole, and one away from the face finds no face.
#[test]
fn a_detection_in_the_pixels_it_used_is_the_whole_images() {
    for offset in [
        DVec3::ZERO,
        DVec3::new(-0.08, 0.0, -0.05),
        DVec3::new(0.05, 0.03, 0.0),
    ] {
        let frame = back_image(offset);
        let whole = detect(&frame).unwrap();
        let full = PixelRect {
            x0: 0,
            y0: 0,
            x1: frame.width,
            y1: frame.height,
        };
        let first = detect_in(&frame, full).unwrap();
        assert!(first.whole);
        assert_eq!(first.detection, whole, "{offset}");
        let used = first.used;
        assert!(
            used.pixels() < full.pixels() / 2,
            "{offset}: the face's pixels {used:?} should be a small part of the image"
        );
        let again = detect_in(&frame, used).unwrap();
        assert!(again.whole, "{offset}");
        assert_eq!(again.detection, whole, "{offset}: only the used pixels");
        assert_eq!(again.used, used);
        // One column short on the right: the face is still found, but the detection read
        // that column (where the skin ends), so it is not the whole image's for sure.
        let cut = PixelRect {
            x1: used.x1 - 1,
            ..used
        };
        assert!(
            detect_in(&frame, cut).is_ok_and(|c| !c.whole),
            "{offset}: a region one column short of the pixels used is not whole"
        );
        // One row or column short on any side: not whole (the +2 rings of the pupils'
        // search box, and the skin's edges, are counted).
        for (side, short) in [
            (
                "left",
                PixelRect {
                    x0: used.x0 + 1,
                    ..used
                },
            ),
            (
                "top",
                PixelRect {
                    y0: used.y0 + 1,
                    ..used
                },
            ),
            (
                "bottom",
                PixelRect {
                    y1: used.y1 - 1,
                    ..used
                },
            ),
        ] {
            assert!(
                detect_in(&frame, short).is_ok_and(|c| !c.whole)
                    || detect_in(&frame, short).is_err(),
                "{offset}: a region one {side} line short of the pixels used is not whole"
            );
        }
        // The pupils left to right in the image, each with its own area.
        assert!(
            whole.pupils[0][0] < whole.pupils[1][0],
            "{:?}",
            whole.pupils
        );
        // The pixels outside the region read as black: the region's detection is that of the
        // image blacked outside it, here a region that cuts the face's left eighth away (its
        // side, not its pupil: the cut face is still found, and differently).
        let cut = PixelRect {
            x0: used.x0 + (used.x1 - used.x0) / 8,
            ..used
        };
        let mut blacked = frame.clone();
        for y in 0..frame.height {
            for x in 0..frame.width {
                if !(cut.x0..cut.x1).contains(&x) || !(cut.y0..cut.y1).contains(&y) {
                    let i = blacked.index(x, y);
                    blacked.color[i] = glam::Vec3::ZERO;
                }
            }
        }
        let cut_face = detect(&blacked);
        assert!(
            cut_face.as_ref().is_ok_and(|d| *d != whole),
            "{offset}: the cut face is found, and differently"
        );
        assert_eq!(
            detect_in(&frame, cut).map(|c| c.detection),
            cut_face,
            "{offset}: the face's left eighth cut away"
        );
        // Below the face: no skin there.
        let away = PixelRect {
            x0: 0,
            y0: frame.height - 8,
            x1: 8,
            y1: frame.height,
        };
        assert_eq!(detect_in(&frame, away).err(), Some(DetectError::NoFace));
    }
}

/// A leaning, estimated-head sequence (das, 320×240 back camera, 30 refreshes): tracking
/// the face gives every frame's eye estimate and confidence bit for bit as rendering and
/// searching the whole back image each time, and renders under half its back pixels. Every
/// estimate is confident, so `--require-confident-head` refuses none; the head stage's time
/// is counted.
#[test]
fn the_tracked_head_estimates_are_the_whole_images() {
    let options = SequenceOptions {
        run: RunOptions {
            head: HeadSource::Estimated,
            width: Some(160),
            height: Some(90),
            frontal_width: Some(160),
            back_width: Some(320),
            spp: 1,
            outside: Outside::Black,
            require_confident_head: true,
            speed_kmh: 50.0,
            ..RunOptions::default()
        },
        timeline: Timeline {
            duration: 0.5,
            fps: 60.0,
            display_hz: 60.0,
            latency_camera: 0.05,
            latency_tracking: 0.01,
        },
        head: HeadMotion::Lean {
            distance: 0.1,
            duration: 0.3,
            start: 0.1,
        },
        predict: Prediction::None,
        reproject: false,
        byo: Default::default(),
    };
    let scene = common::das();
    let estimates = |track: bool| {
        let mut system = SystemLoop::new(&scene, options.clone()).unwrap();
        system.track_face = track;
        let start = std::time::Instant::now();
        let shown: Vec<_> = (0..system.options.timeline.frames())
            .map(|k| {
                let s = system.show(k).unwrap();
                (s.eye_estimated.to_array(), s.head_confidence)
            })
            .collect();
        let head = system.seconds.head;
        assert!(
            head > 0.0 && head < start.elapsed().as_secs_f64(),
            "head stage {head} s"
        );
        (shown, system.back_pixels)
    };
    let (tracked, tracked_pixels) = estimates(true);
    let (whole, whole_pixels) = estimates(false);
    assert_eq!(tracked.len(), 30);
    for (k, (t, w)) in tracked.iter().zip(&whole).enumerate() {
        assert_eq!(t.0.map(f64::to_bits), w.0.map(f64::to_bits), "frame {k}");
        assert_eq!(t.1.map(f64::to_bits), w.1.map(f64::to_bits), "frame {k}");
    }
    // The lean moves the eye 10 cm: the estimates follow it.
    let moved = DVec3::from_array(tracked[29].0) - DVec3::from_array(tracked[0].0);
    assert!(moved.length() > 0.05, "{moved}");
    assert_eq!(whole_pixels, 30 * 320 * 240);
    // The first refresh renders the whole image, each later one the face's region (about
    // 90 × 90 pixels here): counted too.
    assert!(
        tracked_pixels > 320 * 240 + 29 * 50 * 50,
        "tracked {tracked_pixels} back pixels"
    );
    assert!(
        2 * tracked_pixels < whole_pixels,
        "tracked {tracked_pixels} of {whole_pixels} back pixels"
    );
}

/// The box `turned_reads` bounds the mesh face's detector's reads with, for the back tracker
/// to render and search only there: it holds every pixel the detector read (blanking the
/// rest of the back image leaves the detection bit for bit), and not much more: the
/// smallest box that does so, found side by side by brute force (each side moved in while
/// the detection stays the same), lies inside it, and it is at most 1.6 times that box's area
/// (1.4 on das's mesh face: the margins of its rules).
/// Two yaws of the face: turned to the camera, and 35° from it.
#[test]
fn the_mesh_faces_reads_are_bounded_tightly() {
    use seethru::render::frame::Frame;
    use seethru::scene::DriverFace;
    use seethru::system::head_estimate::{detect_face, turned_reads};
    for yaw in ["0.0", "35.0"] {
        let text = common::das_with_mesh_head_text().replace(
            "face = \"mesh\"\n",
            &format!("face = \"mesh\"\nface_yaw_deg = {yaw}\n"),
        );
        let scene = common::parse_in(&common::repo_path("scenes"), "mesh.toml", &text).unwrap();
        let face = scene.face;
        assert!(matches!(face, DriverFace::Mesh { .. }));
        let ctx = RenderContext::new(scene).unwrap();
        let back = ctx.scene.back.with_resolution(320, 240);
        let settings = RenderSettings {
            spp: 4,
            progress: false,
        };
        let (frame, _) = ctx.render(RenderJob::new(&back, View::Back.bit()).settings(settings));
        let detection = detect_face(face, &frame).unwrap();
        let only = |r: PixelRect| -> Frame {
            let mut f = frame.clone();
            for y in 0..f.height {
                for x in 0..f.width {
                    if x < r.x0 || x >= r.x1 || y < r.y0 || y >= r.y1 {
                        let i = f.index(x, y);
                        f.color[i] = glam::Vec3::ZERO;
                    }
                }
            }
            f
        };
        let same = |r: PixelRect| detect_face(face, &only(r)).is_ok_and(|d| d == detection);
        let reads = turned_reads(&detection, &back);
        assert!(
            same(reads),
            "yaw {yaw}: {reads:?} leaves out a pixel the detector read"
        );
        // Each side moved in by a pixel at a time, while a pixel is left and the detection
        // stays the same.
        let steps: [fn(PixelRect) -> PixelRect; 4] = [
            |r| PixelRect { x0: r.x0 + 1, ..r },
            |r| PixelRect { x1: r.x1 - 1, ..r },
            |r| PixelRect { y0: r.y0 + 1, ..r },
            |r| PixelRect { y1: r.y1 - 1, ..r },
        ];
        let mut least = PixelRect::full(&back);
        for step in steps {
            while !step(least).is_empty() && same(step(least)) {
                least = step(least);
            }
        }
        let inside = reads.x0 <= least.x0
            && reads.y0 <= least.y0
            && reads.x1 >= least.x1
            && reads.y1 >= least.y1;
        assert!(inside, "yaw {yaw}: {least:?} is not inside {reads:?}");
        assert!(
            reads.pixels() * 5 <= least.pixels() * 8,
            "yaw {yaw}: {reads:?} is {} px, the least box {least:?} {} px",
            reads.pixels(),
            least.pixels()
        );
    }
}
