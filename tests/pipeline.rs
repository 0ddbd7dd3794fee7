//! The see-through system end to end: a scene that is the model plane comes out right, the
//! head tracker recovers the eye, out-of-view crops behave as chosen, run.json is truthful.

mod common;

use glam::DVec3;
use seethru::analysis::paper::{CropParams, Side};
use seethru::render::views::View;
use seethru::render::{integrator::RenderContext, render_job::RenderJob, settings::RenderSettings};
use seethru::scene::shapes::box_face;
use seethru::system::display::{
    DisplayModel, DisplayPlacement, DisplaySurface, IdealMap, MISSING_ID,
};
use seethru::system::head::{detect, eye_from_detection};
use seethru::system::{
    options::{HeadSource, Outside, RunOptions, WorkingDistance},
    pipeline::run,
};

/// The wall scene with the wall at `d2` and the frontal half angle `frontal_half_angle`.
fn context(d2: f64, frontal_half_angle: f64) -> RenderContext {
    common::WallScene {
        wall: d2,
        frontal_half_angle,
        ..common::WallScene::default()
    }
    .context()
}

/// Pixels of the driver's view where the display is (from the `occluded` frame's ids).
fn display_mask(ctx: &RenderContext, occluded: &seethru::render::frame::Frame) -> Vec<bool> {
    occluded
        .object_id
        .iter()
        .zip(&occluded.part_id)
        .map(|(&o, &p)| o == ctx.world.obstacle_id && p == box_face::POS_Z)
        .collect()
}

#[test]
fn a_scene_that_is_the_model_plane_comes_out_registered() {
    let d2 = 6.0;
    let ctx = context(d2, 45.0);
    let options = RunOptions {
        d2: WorkingDistance::Metres(d2),
        spp: 1,
        ..RunOptions::default()
    };
    let r = run(&ctx, &options).unwrap();
    let mask = display_mask(&ctx, &r.occluded);
    let count = mask.iter().filter(|&&m| m).count();
    assert!(count > 1000, "{count} display pixels");
    // Resampling bound on the wall, per axis: half a display pixel seen from the eye through
    // the display to the plane, plus half a frontal pixel's footprint on the plane.
    let (d1, scene) = (0.7, &ctx.scene);
    let display_px = [scene.obstacle.width / 150.0, scene.obstacle.height / 100.0];
    let frontal_px = [
        2.0 * d2 * scene.frontal.tan_half_x() / 640.0,
        2.0 * d2 * scene.frontal.tan_half_y() / 480.0,
    ];
    let bound = [0, 1].map(|a| 0.5 * display_px[a] * (d1 + d2) / d1 + 0.5 * frontal_px[a]);
    let (mut worst, mut sum) = ([0.0f64; 2], 0.0);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        let (t, s) = (
            r.truth.position[i].as_dvec3(),
            r.seethru.position[i].as_dvec3(),
        );
        assert_eq!(
            r.seethru.object_id[i], 1,
            "pixel {i} shows object {}",
            r.seethru.object_id[i]
        );
        assert!((s.z + d2).abs() < 1e-4 && (t.z + d2).abs() < 1e-4);
        worst = [
            worst[0].max((s.x - t.x).abs()),
            worst[1].max((s.y - t.y).abs()),
        ];
        sum += (s - t).length();
    }
    for a in 0..2 {
        assert!(
            worst[a] <= bound[a] * 1.001 + 1e-5,
            "axis {a}: {} > bound {}",
            worst[a],
            bound[a]
        );
    }
    // On average far inside the bound: the error is quantisation, not a systematic offset.
    assert!(
        sum / (count as f64) < 0.6 * bound[0].hypot(bound[1]),
        "mean {}",
        sum / count as f64
    );

    // A wrong working distance shows up as a larger, systematic error.
    let wrong = run(
        &ctx,
        &RunOptions {
            d2: WorkingDistance::Infinity,
            spp: 1,
            ..RunOptions::default()
        },
    )
    .unwrap();
    let mean_wrong = mask
        .iter()
        .enumerate()
        .filter(|(_, m)| **m)
        .map(|(i, _)| (wrong.seethru.position[i] - r.truth.position[i]).length() as f64)
        .sum::<f64>()
        / count as f64;
    assert!(mean_wrong > 3.0 * bound[0], "{mean_wrong}");
}

#[test]
fn run_json_reports_the_crop_of_eq_ratio1() {
    let ctx = context(6.0, 45.0);
    let r = run(
        &ctx,
        &RunOptions {
            d2: WorkingDistance::Metres(6.0),
            spp: 1,
            width: Some(40),
            ..RunOptions::default()
        },
    )
    .unwrap();
    // Paper convention: the eye at x = 0.08 has b_h = −0.08.
    let p = CropParams {
        d1: 0.7,
        d2: 6.0,
        b_h: -0.08,
        width: 0.3,
        theta_f: 45f64.to_radians(),
    };
    let crop = &r.report["crop"];
    assert!((crop["R1_left"].as_f64().unwrap() - p.cutting_ratio(Side::Left)).abs() < 1e-12);
    assert!((crop["R2_right"].as_f64().unwrap() - p.cutting_ratio(Side::Right)).abs() < 1e-12);
    assert_eq!(
        crop["K_px"]["left"].as_i64().unwrap(),
        (p.cutting_ratio(Side::Left) * 640.0).round() as i64
    );
    assert_eq!(
        r.report["eye_true"]["paper"]["b_h_m"].as_f64().unwrap(),
        -0.08
    );
    assert_eq!(r.report["missing_fraction"].as_f64().unwrap(), 0.0);
}

#[test]
fn out_of_view_crops_error_or_show_black() {
    // θ_F = 8°: the display's view from the eye needs more than the frontal camera sees.
    let ctx = context(6.0, 8.0);
    let err = run(
        &ctx,
        &RunOptions {
            spp: 1,
            width: Some(40),
            ..RunOptions::default()
        },
    )
    .err()
    .unwrap()
    .to_string();
    // No eye position fits: the message says so instead of printing ranges high to low.
    assert!(
        err.contains("leaves the frontal camera's view on the")
            && err.contains("px")
            && err.contains("no eye position keeps the whole crop inside the frontal view")
            && !err.contains("must stay within"),
        "{err}"
    );
    // θ_F = 30° fits the true eye; an eye a metre to the side does not, and the message
    // gives the admissible region, each range low to high.
    let err = run(
        &context(6.0, 30.0),
        &RunOptions {
            spp: 1,
            width: Some(40),
            head_bias_cm: [100.0, 0.0, 0.0],
            ..RunOptions::default()
        },
    )
    .err()
    .unwrap()
    .to_string();
    let region = err
        .split("must stay within")
        .nth(1)
        .unwrap_or_else(|| panic!("{err}"));
    let bounds: Vec<f64> = region
        .split(['[', ']', ','])
        .filter_map(|t| t.trim().parse().ok())
        .collect();
    assert!(
        bounds.len() == 4 && bounds[0] < bounds[1] && bounds[2] < bounds[3],
        "{err}"
    );
    let r = run(
        &ctx,
        &RunOptions {
            spp: 1,
            width: Some(40),
            outside: Outside::Black,
            ..RunOptions::default()
        },
    )
    .unwrap();
    let missing = r.report["missing_fraction"].as_f64().unwrap();
    assert!(missing > 0.05 && missing < 0.95, "{missing}");
    let dark = r
        .display
        .object_id
        .iter()
        .zip(&r.display.color)
        .filter(|(id, _)| **id == MISSING_ID)
        .all(|(_, c)| *c == glam::Vec3::ZERO);
    assert!(dark);
}

#[test]
fn the_head_tracker_recovers_the_eye_better_at_higher_resolution() {
    let scene = common::das();
    let ctx = RenderContext::new(scene).unwrap();
    let truth = ctx.scene.eye();
    let obstacle_from_world = ctx.scene.obstacle.world_from_obstacle.inverse();
    let back_from_world =
        |back: &seethru::geometry::camera::Camera| back.world_from_camera.inverse();
    let mut errors = Vec::new();
    for (w, h) in [(320, 240), (640, 480), (1280, 960)] {
        let back = ctx.scene.back.with_resolution(w, h);
        let frame = ctx
            .render(
                RenderJob::new(&back, View::Back.bit())
                    .settings(RenderSettings {
                        spp: 1,
                        progress: false,
                    })
                    .label("back"),
            )
            .0;
        let detection = detect(&frame).unwrap();
        let estimate = eye_from_detection(&detection, &back, 0.064);
        // Error bound from eqs. d1 and b_h: one pixel of feature width gives d/A_px of
        // distance; one pixel of centre gives 2 d tan θ / E_px of offset, plus the distance
        // error carried into the offset.
        let cam = back_from_world(&back).transform_point3(truth);
        let d = -cam.z;
        let a_px = detection.feature_px();
        let depth_bound = d / a_px;
        let offset_bound = 2.0 * d * back.half_angle_x.tan() / w as f64
            + depth_bound * cam.x.abs().max(cam.y.abs()) / d;
        let err_cam = back_from_world(&back).transform_point3(estimate) - cam;
        assert!(
            err_cam.z.abs() <= depth_bound,
            "{w}: depth error {} > {depth_bound}",
            err_cam.z
        );
        assert!(
            err_cam.x.abs() <= offset_bound && err_cam.y.abs() <= offset_bound,
            "{w}: offset error {err_cam} > {offset_bound}"
        );
        let err_obstacle = obstacle_from_world.transform_vector3(estimate - truth);
        errors.push(err_obstacle.length());
    }
    assert!(errors[2] < errors[0], "{errors:?}");
    assert!(errors[1] < 0.01, "640×480 within 1 cm: {errors:?}");
}

#[test]
fn estimated_head_and_injected_errors_move_the_eye() {
    let ctx = RenderContext::new(common::das()).unwrap();
    let base = RunOptions {
        spp: 1,
        width: Some(64),
        ..RunOptions::default()
    };
    let estimated = run(
        &ctx,
        &RunOptions {
            head: HeadSource::Estimated,
            ..base.clone()
        },
    )
    .unwrap();
    let error = estimated.report["eye_used"]["error_m"].as_f64().unwrap();
    assert!(error > 0.0 && error < 0.01, "{error}");
    assert!(
        estimated.report["head_detection"]["feature_px"]
            .as_f64()
            .unwrap()
            > 20.0
    );
    let biased = run(
        &ctx,
        &RunOptions {
            head_bias_cm: [1.0, 0.0, -2.0],
            ..base.clone()
        },
    )
    .unwrap();
    let moved = biased.eye_used - ctx.scene.eye();
    assert!(
        (moved - DVec3::new(0.01, 0.0, -0.02)).length() < 1e-12,
        "{moved}"
    );
    let jitter = |seed| {
        run(
            &ctx,
            &RunOptions {
                head_jitter_cm: 0.5,
                seed,
                ..base.clone()
            },
        )
        .unwrap()
        .eye_used
    };
    assert_eq!(jitter(3), jitter(3));
    assert_ne!(jitter(3), jitter(4));
}

#[test]
fn d2_auto_finds_the_wall() {
    let ctx = context(6.0, 45.0);
    let r = run(
        &ctx,
        &RunOptions {
            d2: WorkingDistance::Auto,
            spp: 1,
            width: Some(40),
            ..RunOptions::default()
        },
    )
    .unwrap();
    let d2 = r.report["d2_m"].as_f64().unwrap();
    assert!((d2 - 6.0).abs() < 1e-4, "{d2}");
}

#[test]
fn a_back_image_without_a_face_is_a_clear_error() {
    let ctx = context(6.0, 45.0);
    let err = run(
        &ctx,
        &RunOptions {
            head: HeadSource::Estimated,
            spp: 1,
            width: Some(40),
            ..RunOptions::default()
        },
    )
    .err()
    .unwrap();
    assert!(err.to_string().contains("no face found"), "{err}");
}

#[test]
fn a_rotated_obstacle_and_a_turned_frontal_camera_stay_within_the_resampling_quantum() {
    // The homography path end to end: the obstacle turned about two axes (yaw 25°, pitch
    // −12°), the frontal camera on it turned by yaw 10° and pitch 6°, the wall parallel to
    // the display at d2 = 6 m (the model plane). Every display pixel's shown point must lie
    // within the resampling quantum of the truth's: half a display pixel carried from the
    // display to the wall along the eye's ray, plus half a frontal pixel's footprint on the
    // wall at that point (both computed here from the cameras, not from the compensation).
    let d2 = 6.0;
    let mut scene = common::WallScene::default().context().scene;
    let world_from_obstacle = glam::DAffine3::from_translation(DVec3::new(0.4, 1.1, -0.3))
        * glam::DAffine3::from_rotation_y(25f64.to_radians())
        * glam::DAffine3::from_rotation_x(-12f64.to_radians());
    scene.obstacle.world_from_obstacle = world_from_obstacle;
    scene.objects[0].world_from_object =
        world_from_obstacle * glam::DAffine3::from_translation(DVec3::new(0.0, 0.0, -d2));
    let (theta_f, [fw, fh]) = (scene.frontal.half_angle_x, [640, 480]);
    scene.frontal = seethru::geometry::camera::Camera::new(
        world_from_obstacle
            * glam::DAffine3::from_rotation_y(10f64.to_radians())
            * glam::DAffine3::from_rotation_x(6f64.to_radians()),
        theta_f,
        fw,
        fh,
    )
    .unwrap();
    let eye_o = DVec3::new(0.06, 0.04, 0.7);
    scene.driver = seethru::geometry::camera::Camera::look_at(
        world_from_obstacle.transform_point3(eye_o),
        world_from_obstacle.transform_point3(DVec3::ZERO),
        world_from_obstacle.transform_vector3(DVec3::Y),
        scene.driver.half_angle_x,
        scene.driver.width,
        scene.driver.height,
    )
    .unwrap();
    let ctx = RenderContext::new(scene).unwrap();
    let options = |d2| RunOptions {
        d2: WorkingDistance::Metres(d2),
        spp: 1,
        ..RunOptions::default()
    };
    let r = run(&ctx, &options(d2)).unwrap();
    assert!(
        !r.crop.is_axis_aligned(0.5),
        "the homography path is not exercised"
    );
    let scene = &ctx.scene;
    let [dw, dh] = scene.obstacle.display_resolution;
    let display_px = DVec3::new(
        scene.obstacle.width / dw as f64,
        scene.obstacle.height / dh as f64,
        0.0,
    );
    let obstacle_from_world = world_from_obstacle.inverse();
    let frontal = &scene.frontal;
    // Where the ray from `from` through `through` (obstacle frame) meets the wall z = −d2.
    let to_wall = |from: DVec3, through: DVec3| {
        from + (through - from) * ((-d2 - from.z) / (through.z - from.z))
    };
    let origin_o = obstacle_from_world.transform_point3(frontal.position());
    let mask = display_mask(&ctx, &r.occluded);
    let (mut checked, mut sum_ratio) = (0, 0.0);
    for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
        let t = obstacle_from_world.transform_point3(r.truth.position[i].as_dvec3());
        let s = obstacle_from_world.transform_point3(r.seethru.position[i].as_dvec3());
        assert!(
            (t.z + d2).abs() < 1e-4 && (s.z + d2).abs() < 1e-4,
            "{t} {s}"
        );
        // Half a display pixel, in x and y, carried along the eye's ray to the wall.
        let x = obstacle_from_world.transform_point3(r.occluded.position[i].as_dvec3());
        let display = (to_wall(eye_o, x + 0.5 * display_px) - to_wall(eye_o, x)).length();
        // Half a frontal pixel around the truth's point, on the wall.
        let q = frontal
            .project_point(world_from_obstacle.transform_point3(t))
            .unwrap();
        let footprint = [(0.5, 0.5), (0.5, -0.5), (-0.5, 0.5), (-0.5, -0.5)]
            .map(|(du, dv)| {
                let (_, dir) = frontal.world_ray(q + glam::DVec2::new(du, dv));
                let through = obstacle_from_world.transform_point3(frontal.position() + dir);
                (to_wall(origin_o, through) - t).length()
            })
            .into_iter()
            .fold(0.0, f64::max);
        let bound = display + footprint;
        let error = (s - t).length();
        assert!(error <= bound * 1.01 + 1e-5, "pixel {i}: {error} > {bound}");
        sum_ratio += error / bound;
        checked += 1;
    }
    assert!(checked > 1000, "{checked}");
    // Quantisation, not a systematic offset: on average well inside the bound.
    assert!(
        sum_ratio / (checked as f64) < 0.6,
        "{}",
        sum_ratio / checked as f64
    );
    // A model plane at the wrong distance leaves it.
    let wrong = run(&ctx, &options(3.0)).unwrap();
    let outside = mask
        .iter()
        .enumerate()
        .filter(|(i, m)| **m && (wrong.seethru.position[*i] - r.truth.position[*i]).length() > 0.05)
        .count();
    assert!(outside > checked / 2, "{outside} of {checked}");
}

#[test]
fn driver_views_rendered_over_the_truth_equal_separate_renders() {
    // `run` traces `occluded` and `seethru` again only where the obstacle can be seen; every
    // pixel must come out exactly as a render of the whole view gives it, for both displays.
    let ctx = RenderContext::new(common::das()).unwrap();
    for display in [DisplayModel::Pixels, DisplayModel::Ideal] {
        let options = RunOptions {
            width: Some(160),
            spp: 2,
            display,
            back_width: Some(32),
            frontal_width: Some(320),
            ..RunOptions::default()
        };
        let r = run(&ctx, &options).unwrap();
        let driver = ctx.scene.driver.with_resolution(160, 90);
        let settings = RenderSettings {
            spp: 2,
            progress: false,
        };
        let (truth, _) = ctx.render(
            RenderJob::new(&driver, View::Truth.bit())
                .settings(settings)
                .label("truth"),
        );
        let (occluded, _) = ctx.render(
            RenderJob::new(&driver, View::Occluded.bit())
                .settings(settings)
                .label("occluded"),
        );
        assert!(r.truth.bit_identical(&truth), "{display:?} truth");
        assert!(r.occluded.bit_identical(&occluded), "{display:?} occluded");
        let mut frontal = ctx.scene.frontal;
        frontal = frontal.with_resolution(320, 320 * frontal.height / frontal.width);
        let placement = DisplayPlacement::new(&ctx.scene.obstacle);
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
        let (seethru, _) = ctx.render(RenderJob::seethru(&driver, &surface).settings(settings));
        assert!(r.seethru.bit_identical(&seethru), "{display:?} seethru");
        // The views do differ, and only inside the display's neighbourhood was traced again.
        assert!(!truth.bit_identical(&occluded) && !occluded.bit_identical(&seethru));
        let (over, stats) = ctx.render_over(
            RenderJob::new(&driver, View::Occluded.bit())
                .settings(settings)
                .label("occluded"),
            &r.truth,
            View::Truth.bit(),
        );
        assert!(stats.primary_rays < 160 * 90 * 2 / 4, "{stats:?}");
        // Only the traced rectangle is the view's own; the rest is truth's, not a copy.
        let rect = over.rect();
        let traced = u64::from((rect.x1 - rect.x0) * (rect.y1 - rect.y0)) * 2;
        assert_eq!(stats.primary_rays, traced);
        assert!(std::sync::Arc::ptr_eq(over.base(), &r.truth));
        assert!(over.whole().bit_identical(&occluded));
        // run.json's peak memory holds at least the three driver frames.
        let frame_bytes = (truth.color.len() * 52) as u64;
        let peak = r.report["peak_rss_bytes"].as_u64().unwrap();
        assert!(peak > 3 * frame_bytes, "{peak}");
    }
}
