//! The compensation methods beyond one fronto-parallel plane — `plane-fit`, `ground` and
//! `depth` — on scenes whose geometry is known, against ray casting, and the depth-error
//! closed form (`compare` and the bad inputs: `tests/compare.rs`).

mod common;

use glam::{DAffine3, DVec2, DVec3};
use seethru::analysis::depth_error::{mean_misregistration, surface_shift};
use seethru::analysis::physical::ARCMIN_PER_RAD;
use seethru::geometry::camera::Camera;
use seethru::measure::measured_run::{MeasureSettings, MeasuredRun, measure_run};
use seethru::measure::metrics::measure;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::scene::world::view_bit;
use seethru::system::depth_sensor::SensorKind;
use seethru::system::options::{Method, RunOptions, WorkingDistance};
use seethru::system::pipeline::{RunResult, run};
use seethru::system::scene_model::Fill;

/// A scene with an obstacle at the origin facing `facing`, a display of `size` metres at
/// `resolution`, a 640×480 frontal camera and the given objects (material `tex`: the street
/// texture); the driver is placed afterwards by [`with_eye`].
fn scene(facing: [f64; 3], size: [f64; 2], resolution: [u32; 2], objects: &str) -> Scene {
    let text = format!(
        r#"
[obstacle]
center = [0.0, 0.0, 0.0]
facing = [{}, {}, {}]
width = {}
height = {}
display_resolution = [{}, {}]

[camera.driver]
position = [0.0, 0.0, 0.7]
look_at = [0.0, 0.0, -6.0]
half_angle_deg = 30.0
resolution = [200, 150]

[camera.frontal]
half_angle_deg = 45.0
resolution = [640, 480]

[camera.back]
resolution = [32, 24]

[[material]]
name = "tex"
texture = "../assets/street.png"
uv_repeat = [6.0, 4.0]

{objects}
"#,
        facing[0], facing[1], facing[2], size[0], size[1], resolution[0], resolution[1]
    );
    common::parse_in(&common::repo_path("scenes"), "test.toml", &text).unwrap()
}

/// The scene with the driver's eye at `eye_o` (obstacle frame), looking at the display.
fn with_eye(mut scene: Scene, eye_o: DVec3, half_angle_deg: f64) -> RenderContext {
    let w = scene.obstacle.world_from_obstacle;
    scene.driver = Camera::look_at(
        w.transform_point3(eye_o),
        w.transform_point3(DVec3::ZERO),
        w.transform_vector3(DVec3::Y),
        half_angle_deg.to_radians(),
        200,
        150,
    )
    .unwrap();
    RenderContext::new(scene).unwrap()
}

fn options(method: Method) -> RunOptions {
    RunOptions {
        method,
        spp: 1,
        ..RunOptions::default()
    }
}

/// The border band and hazard bound of `seethru run`'s defaults.
const SETTINGS: MeasureSettings = MeasureSettings {
    band: 5,
    hazard_bound_arcmin: 30.0,
};

fn display_mask(ctx: &RenderContext, r: &RunResult) -> Vec<bool> {
    let (maps, _) = measure(ctx, &ctx.scene, ctx.scene.eye(), r.measured_views(), 5);
    maps.display
}

/// Per display pixel of the driver's view on a scene that is the plane `n · p = c`: the
/// distance between the shown and the true point, and the resampling quantum there — half a
/// display pixel carried along the eye's ray to the plane plus half a frontal pixel's
/// footprint on the plane around the true point, both by ray casting from the cameras.
fn errors_and_quanta(ctx: &RenderContext, r: &RunResult, n: DVec3, c: f64) -> Vec<(f64, f64)> {
    let scene = &ctx.scene;
    let obstacle = &scene.obstacle;
    let [dw, dh] = obstacle.display_resolution;
    let half_px = |sx: f64, sy: f64| {
        obstacle.world_from_obstacle.transform_vector3(DVec3::new(
            sx * 0.5 * obstacle.width / dw as f64,
            sy * 0.5 * obstacle.height / dh as f64,
            0.0,
        ))
    };
    let eye = scene.eye();
    let to_plane = |from: DVec3, through: DVec3| {
        let d = through - from;
        from + d * ((c - n.dot(from)) / n.dot(d))
    };
    let frontal = &scene.frontal;
    let mask = display_mask(ctx, r);
    (0..mask.len())
        .filter(|&i| mask[i])
        .map(|i| {
            let t = r.truth.position[i].as_dvec3();
            let s = r.seethru.position[i].as_dvec3();
            let x = r.occluded.position[i].as_dvec3();
            let display = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
                .map(|(sx, sy)| (to_plane(eye, x + half_px(sx, sy)) - to_plane(eye, x)).length())
                .into_iter()
                .fold(0.0, f64::max);
            let q = frontal.project_point(t).unwrap();
            let footprint = [(0.5, 0.5), (0.5, -0.5), (-0.5, 0.5), (-0.5, -0.5)]
                .map(|(du, dv)| {
                    let (o, dir) = frontal.world_ray(q + DVec2::new(du, dv));
                    (to_plane(o, o + dir) - t).length()
                })
                .into_iter()
                .fold(0.0, f64::max);
            ((s - t).length(), display + footprint)
        })
        .collect()
}

/// Pixels within their quantum (1 % and 10 µm of float slack), how many were checked, and
/// the largest error in quanta.
fn within(errors: &[(f64, f64)]) -> (usize, usize, f64) {
    let inside = errors.iter().filter(|(e, q)| *e <= q * 1.01 + 1e-5).count();
    let worst = errors.iter().map(|(e, q)| e / q).fold(0.0, f64::max);
    eprintln!(
        "{inside} of {} inside, worst {worst:.2} quanta",
        errors.len()
    );
    (inside, errors.len(), worst)
}

#[test]
fn a_tilted_wall_and_a_ground_plane_are_registered_by_plane_fit_and_ground() {
    // A wall turned 40° about the vertical, 6 m behind the display.
    let wall = scene(
        [0.0, 0.0, 1.0],
        [0.5, 0.3],
        [250, 150],
        "[[object]]\nname = \"wall\"\nkind = \"quad\"\nmaterial = \"tex\"\nsize = [80.0, 60.0]\nrotate_deg = [0.0, 40.0, 0.0]\ntranslate = [0.0, 0.0, -6.0]",
    );
    let ctx = with_eye(wall, DVec3::new(0.08, 0.03, 0.7), 25.0);
    let n = DAffine3::from_rotation_y(40f64.to_radians()).transform_vector3(DVec3::Z);
    let c = n.dot(DVec3::new(0.0, 0.0, -6.0));
    let fitted = run(&ctx, &options(Method::PlaneFit)).unwrap();
    let normal = &fitted.report["scene_model"]["plane"]["normal_world"];
    let fitted_n = DVec3::new(
        normal[0].as_f64().unwrap(),
        normal[1].as_f64().unwrap(),
        normal[2].as_f64().unwrap(),
    );
    assert!(fitted_n.dot(n).abs() > 1.0 - 1e-6, "{fitted_n} vs {n}");
    let (inside, checked, worst) = within(&errors_and_quanta(&ctx, &fitted, n, c));
    assert!(checked > 1000, "{checked}");
    assert_eq!(
        inside, checked,
        "plane-fit on the tilted wall, worst {worst}"
    );
    // The best fronto-parallel plane (the median depth) cannot: most pixels leave their quantum.
    let planar = RunOptions {
        d2: WorkingDistance::Auto,
        ..options(Method::Planar)
    };
    let flat = run(&ctx, &planar).unwrap();
    let (inside, checked, worst) = within(&errors_and_quanta(&ctx, &flat, n, c));
    assert!(
        inside < checked * 3 / 4 && worst > 2.0,
        "{inside} of {checked}, worst {worst}"
    );
    // The wall has no road: `ground` says so.
    let err = run(&ctx, &options(Method::Ground))
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("has no ground plane"), "{err}");

    // A road below an obstacle 1.2 m up that faces the driver and tilts up 31°: the display
    // shows only road.
    let road = scene(
        [0.0, 0.6, 1.0],
        [0.5, 0.3],
        [250, 150],
        "[[object]]\nname = \"road\"\nkind = \"plane\"\nmaterial = \"tex\"\nsize = [200.0, 200.0]\ntranslate = [0.0, -1.2, 0.0]",
    );
    let ctx = with_eye(road, DVec3::new(0.05, 0.03, 0.7), 25.0);
    for method in [Method::Ground, Method::PlaneFit] {
        let r = run(&ctx, &options(method)).unwrap();
        let (inside, checked, worst) = within(&errors_and_quanta(&ctx, &r, DVec3::Y, -1.2));
        assert!(checked > 1000, "{checked}");
        assert_eq!(inside, checked, "{method:?} on the road, worst {worst}");
    }
    let flat = run(&ctx, &planar).unwrap();
    let (inside, checked, worst) = within(&errors_and_quanta(&ctx, &flat, DVec3::Y, -1.2));
    assert!(
        inside < checked * 3 / 4 && worst > 2.0,
        "{inside} of {checked}, worst {worst}"
    );
}

/// `plane-fit` fits its plane to the sensor pixels under the display's d2 → ∞ crop, whatever
/// the sensor's resolution: on a wall that fills the frontal view every return there is an
/// inlier, so the inlier count is that rectangle's pixel count — found here from the display's
/// corners seen from the eye, scaled to the sensor (the frontal camera's field of view at
/// another resolution). A region taken in frontal pixels, or shifted, counts other pixels.
#[test]
fn plane_fit_takes_the_sensor_pixels_under_the_crop_at_any_sensor_resolution() {
    let wall = scene(
        [0.0, 0.0, 1.0],
        [0.5, 0.3],
        [250, 150],
        "[[object]]\nname = \"wall\"\nkind = \"quad\"\nmaterial = \"tex\"\nsize = [80.0, 60.0]\nrotate_deg = [0.0, 40.0, 0.0]\ntranslate = [0.0, 0.0, -6.0]",
    );
    let ctx = with_eye(wall, DVec3::new(0.08, 0.03, 0.7), 25.0);
    let scene = &ctx.scene;
    let (eye, frontal) = (scene.eye(), &scene.frontal);
    assert_eq!((frontal.width, frontal.height), (640, 480));
    let corners = scene
        .obstacle
        .display_corners()
        .map(|c| frontal.project_direction(c - eye).unwrap());
    let min = corners.iter().fold(DVec2::INFINITY, |a, c| a.min(*c));
    let max = corners.iter().fold(DVec2::NEG_INFINITY, |a, c| a.max(*c));
    // The region is well inside the frontal view, so no clipping enters the count.
    assert!(min.cmpgt(DVec2::splat(20.0)).all() && max.cmplt(DVec2::new(620.0, 460.0)).all());
    for (kind, width, least) in [
        (SensorKind::Ideal, 640, 1.0),
        (SensorKind::Tof, 320, 0.9),
        (SensorKind::Tof, 160, 0.9),
    ] {
        let mut o = options(Method::PlaneFit);
        o.scene_model.sensor.kind = kind;
        o.scene_model.sensor.width = (kind != SensorKind::Ideal).then_some(width);
        let r = run(&ctx, &o).unwrap();
        let inliers = r.report["scene_model"]["plane_fit_inliers"]
            .as_f64()
            .unwrap();
        let scale = width as f64 / 640.0;
        let (lo, hi) = (min * scale, max * scale);
        let inner = (hi.x.floor() - lo.x.ceil()) * (hi.y.floor() - lo.y.ceil());
        let outer = (hi.x.ceil() - lo.x.floor()) * (hi.y.ceil() - lo.y.floor());
        eprintln!("{kind:?} {width}: {inliers} inliers, region {inner}..{outer} px");
        assert!(inner > 300.0, "{inner}");
        assert!(
            inliers <= outer && inliers >= least * inner,
            "{kind:?} at {width} px: {inliers} inliers, the crop's region has {inner}..{outer} px"
        );
    }
}

/// A wall 8 m behind the display with a box in front of it: `box_size` at `box_at`.
fn wall_and_box(box_size: [f64; 3], box_at: [f64; 3]) -> Scene {
    scene(
        [0.0, 0.0, 1.0],
        [0.3, 0.2],
        [150, 100],
        &format!(
            "[[object]]\nname = \"wall\"\nkind = \"quad\"\nmaterial = \"tex\"\nsize = [80.0, 60.0]\ntranslate = [0.0, 0.0, -8.0]\n\n[[material]]\nname = \"yellow\"\ncolor = [0.9, 0.7, 0.1]\n\n[[object]]\nname = \"box\"\nkind = \"box\"\nmaterial = \"yellow\"\nsize = {box_size:?}\ntranslate = {box_at:?}"
        ),
    )
}

fn depth(kind: SensorKind) -> RunOptions {
    let mut o = options(Method::Depth);
    o.scene_model.sensor.kind = kind;
    o
}

#[test]
fn ideal_depth_registers_every_seen_pixel_when_nothing_is_disoccluded() {
    // A box 0.2 m deep standing on the wall (its front 7.8 m away), the eye near the camera's
    // axis: what the eye sees beside the box's edges the camera sees too.
    let ctx = with_eye(
        wall_and_box([1.0, 0.8, 0.2], [0.1, -0.1, -7.9]),
        DVec3::new(0.02, 0.01, 0.7),
        20.0,
    );
    let r = run(&ctx, &depth(SensorKind::Ideal)).unwrap();
    let holes = r.holes.as_ref().unwrap();
    assert_eq!(holes.iter().filter(|&&h| h).count(), 0);
    let eye = ctx.scene.eye();
    let mask = display_mask(&ctx, &r);
    let [dw, _] = ctx.scene.obstacle.display_resolution;
    let display_px = ctx.scene.obstacle.width / dw as f64;
    let frontal = &ctx.scene.frontal;
    let frontal_tan_px = 2.0 * frontal.tan_half_x() / frontal.width as f64;
    let (mut checked, mut worst, mut on_box) = (0, 0.0f64, 0);
    for i in (0..mask.len()).filter(|&i| mask[i]) {
        let t = r.truth.position[i].as_dvec3();
        let s = r.seethru.position[i].as_dvec3();
        let x = r.occluded.position[i].as_dvec3();
        let angle = (s - eye).angle_between(t - eye);
        // The quantum as an angle at the eye: half a display pixel's diagonal seen from the
        // eye, plus half a frontal pixel's diagonal seen from the camera and carried to the eye
        // (a lateral offset at depth z from the camera is seen from the eye, z + d1 away).
        let z = frontal.axial_depth(t);
        let quantum = std::f64::consts::SQRT_2
            * 0.5
            * (display_px / (x - eye).length() + frontal_tan_px * z / (t - eye).length());
        worst = worst.max(angle / quantum);
        on_box += (r.truth.object_id[i] == 2) as usize;
        checked += 1;
    }
    assert!(checked > 1000 && on_box > 300, "{checked} {on_box}");
    eprintln!("checked {checked} on box {on_box} worst {worst}");
    assert!(worst <= 1.01, "worst {worst} quanta");
}

#[test]
fn holes_of_a_sideways_eye_are_the_disoccluded_area() {
    // A box floating 2.5 m away in front of the wall at 8 m; the eye 20 cm to the side of the
    // camera sees a strip of wall beside the box that the camera cannot. The metrics find
    // that strip by ray casting (`missing`: truth points hidden from the frontal camera); the
    // search finds it as holes. Equal up to one pixel per edge of the strip.
    let ctx = with_eye(
        wall_and_box([0.6, 0.5, 0.4], [-0.6, 0.0, -2.5]),
        DVec3::new(0.2, 0.0, 0.7),
        20.0,
    );
    let options = depth(SensorKind::Ideal);
    let r = run(&ctx, &options).unwrap();
    let MeasuredRun {
        maps,
        metrics,
        holes,
        ..
    } = measure_run(&ctx, &options, &r, SETTINGS).unwrap();
    let holes = holes.unwrap();
    let metrics = metrics.to_json();
    assert_eq!(metrics["missing"]["outside_frontal_view"], 0);
    let hidden = metrics["missing"]["hidden_from_frontal"].as_u64().unwrap() as i64;
    let found = holes.iter().filter(|&&h| h).count() as i64;
    // The disoccluded strip's edge pixels: in it with a 4-neighbour outside, or the reverse.
    let w = maps.width as usize;
    let edge = (0..holes.len())
        .filter(|&i| {
            let (x, y) = (i % w, i / w);
            maps.display[i]
                && maps.missing[i]
                && [
                    (x > 0).then(|| i - 1),
                    Some(i + 1),
                    (y > 0).then(|| i - w),
                    Some(i + w),
                ]
                .into_iter()
                .flatten()
                .any(|j| j < holes.len() && maps.display[j] && !maps.missing[j])
        })
        .count() as i64;
    eprintln!("hidden {hidden}, holes {found}, edge {edge}");
    assert!(hidden > 100, "{hidden}");
    assert!(
        (found - hidden).abs() <= edge,
        "holes {found} vs disoccluded {hidden} ± {edge}"
    );
    // And they are the same pixels, up to the edges.
    let differ = (0..holes.len())
        .filter(|&i| maps.display[i] && holes[i] != maps.missing[i])
        .count() as i64;
    assert!(differ <= edge, "{differ} pixels differ, edge {edge}");
    let fraction = metrics["holes"]["fraction"].as_f64().unwrap();
    assert!((fraction - found as f64 / metrics["display_pixels"].as_f64().unwrap()).abs() < 1e-12);
    // Without a fill the holes are blank; the seen pixels' metrics leave them out.
    assert_eq!(metrics["holes"]["filled"]["coverage"], 0.0);
    assert_eq!(metrics["holes"]["seen"]["coverage"], 1.0);
    // The background fill shows the farther surface beside the silhouette — the wall (id 1),
    // never the box (id 2) — in every hole; the seen pixels are unchanged.
    let mut background = depth(SensorKind::Ideal);
    background.scene_model.fill = Fill::Background;
    let filled = run(&ctx, &background).unwrap();
    let hole_pixels: Vec<usize> = (0..holes.len()).filter(|&i| holes[i]).collect();
    assert!(
        hole_pixels
            .iter()
            .all(|&i| filled.seethru.object_id[i] == 1)
    );
    assert!(
        (0..holes.len())
            .filter(|&i| maps.display[i] && !holes[i])
            .all(|i| filled.seethru.position[i] == r.seethru.position[i])
    );
}

#[test]
fn depth_reprojection_is_the_same_for_any_thread_count() {
    let ctx = with_eye(
        wall_and_box([0.6, 0.5, 0.4], [-0.6, 0.0, -2.5]),
        DVec3::new(0.2, 0.0, 0.7),
        20.0,
    );
    let mut o = depth(SensorKind::Stereo);
    o.scene_model.fill = Fill::Inpaint;
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run(&ctx, &o).unwrap())
    };
    let (one, three) = (on(1), on(3));
    assert!(one.display == three.display && one.holes == three.holes);
    // And plane-fit's RANSAC with it.
    let fit = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            run(&ctx, &options(Method::PlaneFit)).unwrap().report["scene_model"].clone()
        })
    };
    assert_eq!(fit(1), fit(3));
}

#[test]
fn the_depth_error_formula_matches_ray_casting() {
    // The camera at the origin looking down −z at a wall 6 m away. For eyes and display points
    // around, the eye's ray meets the wall at P; a depth read δ too far stops it at P' on the
    // same ray, and the camera's ray through P' meets the wall (by the renderer's ray cast) at
    // Q. Q − P must be the closed form's −c·δ/(Z + δ).
    let ctx = with_eye(
        wall_and_box([0.01, 0.01, 0.01], [0.0, 20.0, -7.0]),
        DVec3::new(0.0, 0.0, 0.7),
        20.0,
    );
    let camera = ctx.scene.frontal.position();
    assert!(camera.length() < 1e-12);
    let z = 8.0;
    let mut checked = 0;
    for (k, (eye, on_display, delta)) in [
        (
            DVec3::new(0.1, 0.05, 0.7),
            DVec3::new(-0.12, 0.08, 0.0),
            0.5,
        ),
        (
            DVec3::new(-0.2, 0.0, 0.5),
            DVec3::new(0.1, -0.09, 0.0),
            -0.8,
        ),
        (DVec3::new(0.3, -0.1, 0.9), DVec3::new(0.14, 0.02, 0.0), 1.6),
        (
            DVec3::new(0.0, 0.2, 0.6),
            DVec3::new(-0.05, -0.1, 0.0),
            -0.3,
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let u = on_display - eye;
        let at_depth = |d: f64| eye + u * ((-d - eye.z) / u.z);
        let (p, p_wrong) = (at_depth(z), at_depth(z + delta));
        let hit = ctx
            .trace(
                camera.as_vec3(),
                (p_wrong - camera).normalize().as_vec3(),
                view_bit::FRONTAL,
            )
            .unwrap();
        let q = (camera + (p_wrong - camera).normalize() * hit.t as f64) - p;
        let c = at_depth(0.0);
        let predicted = surface_shift(c, z, delta);
        assert!(
            (q - predicted).length() < 2e-4,
            "case {k}: {q} vs {predicted}"
        );
        checked += 1;
    }
    assert_eq!(checked, 4);
}

#[test]
fn depth_noise_grows_the_misregistration_as_the_formula_predicts() {
    // A wall 6 m behind a 1 m × 0.6 m display of 1600 × 960 pixels and a 1920 × 1440
    // frontal camera (so that the resampling quantum is small beside the noise's effect); no
    // quantisation, a range past the wall. The sensor is 96 px wide: each line of sight then
    // crosses the noisy surface inside one sensor tile, and reads one depth — the closed
    // form's premise. (A sensor of 960 px puts several tiles within the noise band along a
    // ray, which stops at the first reading nearer than itself: a first-passage bias the
    // one-reading form does not model, +8 to +13 % here.) For each seen display pixel the
    // closed form gives the mean angle for its ray's crossing c of the camera's plane; the
    // mean over the seen pixels must match the pipeline's within 10 %, for time-of-flight
    // noise (σ/Z = σ₁) at two σ₁ and for stereo noise (σ/Z = σ₁·Z).
    let ctx = with_eye(
        {
            let mut s = scene(
                [0.0, 0.0, 1.0],
                [1.0, 0.6],
                [1600, 960],
                "[[object]]\nname = \"wall\"\nkind = \"quad\"\nmaterial = \"tex\"\nsize = [80.0, 60.0]\ntranslate = [0.0, 0.0, -6.0]",
            );
            s.frontal = s.frontal.with_resolution(1920, 1440);
            s
        },
        DVec3::new(0.05, 0.03, 0.7),
        42.0,
    );
    let eye = ctx.scene.eye();
    for (kind, sigma_1m) in [
        (SensorKind::Tof, 0.0),
        (SensorKind::Tof, 0.05),
        (SensorKind::Tof, 0.08),
        (SensorKind::Stereo, 0.012),
    ] {
        let mut o = depth(kind);
        o.scene_model.sensor.width = Some(96);
        o.scene_model.sensor.range_m = Some(50.0);
        o.scene_model.sensor.quantum_1m = Some(0.0);
        o.scene_model.sensor.noise_1m = Some(sigma_1m);
        let r = run(&ctx, &o).unwrap();
        let MeasuredRun {
            maps,
            metrics,
            holes,
            ..
        } = measure_run(&ctx, &o, &r, SETTINGS).unwrap();
        let holes = holes.unwrap();
        let (mut measured, mut predicted, mut n) = (0.0, 0.0, 0);
        for i in (0..maps.display.len()).filter(|&i| maps.display[i] && !holes[i]) {
            let t = r.truth.position[i].as_dvec3();
            let u = t - eye;
            let c = eye + u * (-eye.z / u.z);
            let z = -t.z;
            let s = match kind {
                SensorKind::Stereo => sigma_1m * z,
                _ => sigma_1m,
            };
            predicted += mean_misregistration(c, u.normalize(), u.length(), s) * ARCMIN_PER_RAD;
            measured += maps.misregistration[i] as f64;
            n += 1;
        }
        let (measured, predicted) = (measured / n as f64, predicted / n as f64);
        eprintln!(
            "{kind:?} σ₁ = {sigma_1m}: measured {measured:.3}′, predicted {predicted:.3}′ over {n}, holes {}",
            metrics.holes.as_ref().unwrap()["fraction"]
        );
        assert!(n > 5000, "{n}");
        if sigma_1m == 0.0 {
            // The resampling alone: well below the noise's effects tested next.
            assert!(measured < 1.6, "{measured}");
            continue;
        }
        assert!(
            (measured - predicted).abs() <= 0.1 * predicted,
            "{kind:?} σ₁ = {sigma_1m}: measured {measured}′, predicted {predicted}′"
        );
    }
}
