//! Curved displays (`display_shape`): the per-pixel planar compensation agrees with the
//! crop's homography on a flat display, a flat mesh display reproduces today's images, a
//! cylinder display on a wall at d2 is registered within the resampling quantum, and bad
//! display meshes and UVs get one `error:` line.

mod common;

use glam::{DVec2, DVec3};
use seethru::render::frame::Frame;
use seethru::render::integrator::RenderContext;
use seethru::scene::shapes::box_face;
use seethru::system::compensation::ModelPlane;
use seethru::system::options::{RunOptions, WorkingDistance};
use seethru::system::pipeline::{crop_for, frontal_map, run};
use seethru::system::point_model::PointModel;
use seethru::system::surface_map::display_points;

fn wall(keys: &str, d2: f64) -> String {
    common::WallScene {
        wall: d2,
        ..common::WallScene::default()
    }
    .text()
    .replace(
        "display_resolution = [",
        &format!("{keys}\ndisplay_resolution = ["),
    )
}

fn context(text: &str) -> RenderContext {
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", text).unwrap();
    RenderContext::new(scene).unwrap()
}

fn options(d2: WorkingDistance) -> RunOptions {
    RunOptions {
        d2,
        spp: 1,
        ..RunOptions::default()
    }
}

fn display_mask(ctx: &RenderContext, occluded: &Frame) -> Vec<bool> {
    occluded
        .object_id
        .iter()
        .zip(&occluded.part_id)
        .map(|(&o, &p)| o == ctx.world.obstacle_id && p == box_face::POS_Z)
        .collect()
}

#[test]
fn the_per_pixel_path_is_the_homography_on_a_flat_display() {
    let ctx = context(&wall("", 6.0));
    let scene = &ctx.scene;
    let frontal = Frame::new(scene.frontal.width, scene.frontal.height);
    for (eye, d2) in [
        (DVec3::new(0.08, 0.03, 0.7), WorkingDistance::Metres(6.0)),
        (DVec3::new(-0.2, 0.1, 0.5), WorkingDistance::Metres(2.5)),
        (DVec3::new(0.15, -0.05, 0.9), WorkingDistance::Infinity),
    ] {
        let o = options(d2);
        let (crop, d2_used) = crop_for(scene, eye, &frontal, &o).unwrap();
        let map = frontal_map(scene, crop, &o).unwrap();
        let plane = d2_used.map_or(ModelPlane::Infinity, ModelPlane::At);
        let model = PointModel::new(scene, eye, plane).unwrap();
        let [w, h] = scene.obstacle.display_resolution;
        let points = display_points(&scene.obstacle);
        let mut worst: f64 = 0.0;
        for y in 0..h {
            for x in 0..w {
                let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                let by_crop = map.frontal_point(p);
                let by_point = model
                    .frontal_point(points[(y * w + x) as usize].unwrap())
                    .unwrap();
                worst = worst.max((by_crop - by_point).length());
            }
        }
        assert!(worst < 1e-6, "eye {eye}, {d2:?}: {worst} px apart");
    }
}

/// A display mesh: the 0.3 × 0.2 m rectangle at z = 0 as two triangles, UVs over [0, 1]².
const FLAT_QUAD_OBJ: &str = "v -0.15 0.1 0\nv 0.15 0.1 0\nv 0.15 -0.1 0\nv -0.15 -0.1 0\n\
vt 0 1\nvt 1 1\nvt 1 0\nvt 0 0\nf 1/1 4/4 3/3\nf 1/1 3/3 2/2\n";

#[test]
fn a_curved_display_that_is_the_plane_z0_reproduces_the_flat_images() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("flat.obj");
    std::fs::write(&mesh, FLAT_QUAD_OBJ).unwrap();
    let flat = context(&wall("", 6.0));
    let curved = context(&wall(
        &format!(
            "display_shape = \"mesh\"\ndisplay_mesh = {:?}",
            mesh.display().to_string()
        ),
        6.0,
    ));
    assert!(curved.scene.obstacle.display_shape.curved().is_some());
    for d2 in [WorkingDistance::Metres(6.0), WorkingDistance::Infinity] {
        let a = run(&flat, &options(d2)).unwrap();
        let b = run(&curved, &options(d2)).unwrap();
        // The display images: the same frontal points, sampled alike.
        let worst = a
            .display
            .color
            .iter()
            .zip(&b.display.color)
            .map(|(p, q)| (*p - *q).abs().max_element())
            .fold(0.0f32, f32::max);
        assert!(worst < 1e-4, "{d2:?}: display colours differ by {worst}");
        assert_eq!(a.display.object_id, b.display.object_id);
        // The driver's views: only pixels on a display pixel's edge may round either way.
        let differ = |x: &Frame, y: &Frame| {
            x.color
                .iter()
                .zip(&y.color)
                .filter(|(p, q)| (**p - **q).abs().max_element() > 1e-3)
                .count()
        };
        let n = a.seethru.color.len();
        assert!(differ(&a.seethru, &b.seethru) * 500 < n, "{d2:?}: seethru");
        assert!(
            differ(&a.occluded, &b.occluded) * 500 < n,
            "{d2:?}: occluded"
        );
    }
}

#[test]
fn a_cylinder_display_on_the_wall_at_d2_is_registered() {
    let d2 = 6.0;
    let ctx = context(&wall(
        "display_shape = \"cylinder\"\ndisplay_radius = 0.2\ndisplay_segments = 48",
        d2,
    ));
    let r = run(&ctx, &options(WorkingDistance::Metres(d2))).unwrap();
    let mask = display_mask(&ctx, &r.occluded);
    let count = mask.iter().filter(|&&m| m).count();
    assert!(count > 1000, "{count} display pixels");
    // Some of them are well behind z = 0: the surface is curved, not the flat face.
    let deepest = (0..mask.len())
        .filter(|&i| mask[i])
        .map(|i| r.occluded.position[i].z)
        .fold(0.0f32, f32::min);
    assert!(deepest < -0.03, "deepest display point z = {deepest}");
    // The resampling quantum on the wall: half a display pixel (along the arc) carried from the
    // eye to the wall (a point behind z = 0 carries it less far), plus half a frontal pixel.
    let (d1, scene) = (0.7, &ctx.scene);
    let display_px = [scene.obstacle.width / 150.0, scene.obstacle.height / 100.0];
    let frontal_px = [
        2.0 * d2 * scene.frontal.tan_half_x() / 640.0,
        2.0 * d2 * scene.frontal.tan_half_y() / 480.0,
    ];
    let bound = [0, 1].map(|a| 0.5 * display_px[a] * (d1 + d2) / d1 + 0.5 * frontal_px[a]);
    let mut worst = [0.0f64; 2];
    for i in (0..mask.len()).filter(|&i| mask[i]) {
        let (t, s) = (
            r.truth.position[i].as_dvec3(),
            r.seethru.position[i].as_dvec3(),
        );
        assert_eq!(r.seethru.object_id[i], 1, "pixel {i}");
        worst = [
            worst[0].max((s.x - t.x).abs()),
            worst[1].max((s.y - t.y).abs()),
        ];
    }
    for a in 0..2 {
        assert!(
            worst[a] <= bound[a] * 1.001 + 1e-5,
            "axis {a}: {} > bound {}",
            worst[a],
            bound[a]
        );
    }
}

fn one_error(dir: &std::path::Path, scene: &str, words: &[&str]) {
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let (ok, _, stderr) = common::seethru_in(dir, &["render", "scene.toml", "--out", "o"]);
    assert!(!ok, "{scene}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    for w in words {
        assert!(errors[0].contains(w), "`{w}` not in {}", errors[0]);
    }
}

#[test]
fn bad_display_meshes_and_uvs_get_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        common::repo_path("assets/street.png"),
        dir.path().join("street.png"),
    )
    .ok();
    let base = common::MINIMAL;
    let with = |keys: &str| base.replacen("height = 0.4\n", &format!("height = 0.4\n{keys}\n"), 1);
    let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
    write(
        "no_uv.obj",
        "v -0.15 0.2 0\nv 0.15 0.2 0\nv 0.15 -0.2 0\nv -0.15 -0.2 0\nf 1 4 3\nf 1 3 2\n",
    );
    // The second triangle's UVs mirrored: the surface folds over in UV space.
    write(
        "folded.obj",
        "v -0.15 0.2 0\nv 0.15 0.2 0\nv 0.15 -0.2 0\nv -0.15 -0.2 0\n\
vt 0 1\nvt 1 1\nvt 1 0\nvt 0 0\nf 1/1 4/4 3/3\nf 1/1 3/2 2/4\n",
    );
    let d = dir.path();
    one_error(
        d,
        &with("display_shape = \"mesh\"\ndisplay_mesh = \"no_uv.obj\""),
        &["scene.toml", "display_mesh", "no_uv.obj", "no UVs"],
    );
    one_error(
        d,
        &with("display_shape = \"mesh\"\ndisplay_mesh = \"folded.obj\""),
        &["display_mesh", "folded.obj", "folded UVs"],
    );
    one_error(
        d,
        &with("display_shape = \"mesh\"\ndisplay_mesh = \"missing.obj\""),
        &["display_mesh", "missing.obj"],
    );
    one_error(
        d,
        &with("display_shape = \"cylinder\"\ndisplay_resolution = [0, 400]"),
        &["display_resolution", "[1, "],
    );
    one_error(
        d,
        &with("display_shape = \"cylinder\"\ndisplay_radius = 0.01"),
        &["display_radius", "half way round"],
    );
    one_error(
        d,
        &with("display_radius = 0.2"),
        &["display_radius", "cylinder", "flat"],
    );
    one_error(
        d,
        &with("display_shape = \"sphere\""),
        &["display_shape", "cylinder"],
    );
    one_error(d, &with("display_shape = \"mesh\""), &["display_mesh"]);
}

#[test]
fn the_obstruction_angle_of_a_plate_is_2_atan_w_over_2d() {
    let (w, d, ipd) = (0.1, 0.7, 0.064);
    let text = common::WallScene {
        eye: [0.0, 0.0, d],
        ..common::WallScene::default()
    }
    .text()
    .replace("width = 0.3", &format!("width = {w}"));
    let ctx = context(&text);
    let o = seethru::system::obstruction::obstruction(&ctx, DVec3::new(0.0, 0.0, d), ipd);
    let mono = 2.0 * (w / (2.0 * d)).atan().to_degrees();
    // Both eyes are blocked only where the plate hides the direction from each.
    let bino = 2.0 * ((w - ipd) / (2.0 * d)).atan().to_degrees();
    let step = seethru::system::obstruction::STEP_DEG;
    assert!(
        (o.monocular_without_display - mono).abs() <= 2.0 * step,
        "{o:?} vs {mono}"
    );
    assert!(
        (o.binocular_without_display - bino).abs() <= 2.0 * step,
        "{o:?} vs {bino}"
    );
    // Seen head-on the display is the whole face: nothing of the body is left.
    assert!(o.monocular_with_display <= 2.0 * step, "{o:?}");
    assert!(o.binocular_with_display <= 2.0 * step, "{o:?}");
}

fn scratch_wall(text: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    common::scene_file_in(dir.path(), "scene.toml", text);
    dir
}

#[test]
fn a_display_the_driver_sees_a_sliver_of_is_reported_and_warned_about() {
    let run_json = |text: &str| {
        let dir = scratch_wall(text);
        let (ok, _, stderr) = common::seethru_in(
            dir.path(),
            &["run", "scene.toml", "--out", "o", "--d2", "6"],
        );
        assert!(ok, "{stderr}");
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.path().join("o/run.json")).unwrap())
                .unwrap();
        (json["display_seen"].clone(), stderr)
    };
    let eye = "position = [0.0, 0.0, 0.7]";
    let base = wall("", 6.0).replace("position = [0.08, 0.03, 0.7]", eye);
    let (seen, stderr) = run_json(&base);
    assert_eq!(seen["display_pixels"], 150 * 100);
    assert_eq!(seen["seen_by_driver"], 150 * 100, "{seen}");
    assert!(
        !stderr.contains("warning: the driver sees only"),
        "{stderr}"
    );
    // Turned 31° left with a 20° half angle: the view's right edge 11° left of the eye's axis
    // leaves x ≤ 0.7 tan(−11°) = −0.136 m of the display's [−0.15, 0.15] m: 4.7 %.
    let turned = base.replace(
        "look_at = [0.0, 0.0, -6.0]",
        "look_at = [-3.09, 0.0, -4.44]",
    );
    let (seen, stderr) = run_json(&turned);
    let share = seen["share"].as_f64().unwrap();
    assert!((share - 0.047).abs() < 0.01, "{seen}");
    assert!(stderr.contains("warning: the driver sees only"), "{stderr}");
}

#[test]
fn the_cabin_runs_compares_and_sequences() {
    let dir = tempfile::tempdir().unwrap();
    let cabin = common::repo_path("scenes/cabin.toml");
    let cabin = cabin.to_str().unwrap();
    let (ok, _, stderr) = common::seethru_in(
        dir.path(),
        &[
            "run",
            cabin,
            "--out",
            "run",
            "--width",
            "240",
            "--frontal-width",
            "320",
        ],
    );
    assert!(ok, "{stderr}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("run/run.json")).unwrap())
            .unwrap();
    // The pillar blocks degrees of the driver's view; the display gives most of them back.
    let o = &json["obstruction_deg"];
    let (without, with) = (
        o["monocular_without_display"].as_f64().unwrap(),
        o["monocular_with_display"].as_f64().unwrap(),
    );
    assert!(without > 5.0 && with < 0.5 * without, "{o}");
    let (ok, _, stderr) = common::seethru_in(
        dir.path(),
        &[
            "compare",
            cabin,
            "--out",
            "cmp",
            "--width",
            "160",
            "--methods",
            "none,planar-inf,ground",
        ],
    );
    assert!(ok, "{stderr}");
    let (ok, _, stderr) = common::seethru_in(
        dir.path(),
        &[
            "sequence",
            cabin,
            "--out",
            "seq",
            "--width",
            "120",
            "--frontal-width",
            "200",
            "--duration",
            "0.2",
            "--fps",
            "10",
        ],
    );
    assert!(ok, "{stderr}");
}

/// The point of a `segments`-facet cylinder display (radius `r`, `width` × `height`, obstacle
/// frame) at UV (u, v), written out from the shape's definition: u is linear along each flat
/// facet between the arc's columns at angles (u − ½)·width/r.
fn cylinder_point(u: f64, v: f64, [width, height, r]: [f64; 3], segments: usize) -> DVec3 {
    let half = width / (2.0 * r);
    let column = |k: usize| {
        let a = (k as f64 / segments as f64 - 0.5) * 2.0 * half;
        DVec3::new(r * a.sin(), 0.0, r * a.cos() - r)
    };
    let k = ((u * segments as f64) as usize).min(segments - 1);
    let t = u * segments as f64 - k as f64;
    column(k).lerp(column(k + 1), t) + DVec3::Y * (0.5 - v) * height
}

fn ideal(d2: WorkingDistance) -> RunOptions {
    RunOptions {
        display: seethru::system::display::DisplayModel::Ideal,
        ..options(d2)
    }
}

/// The ideal display on a curved display shows, at every point of its surface, what the
/// planar model says the eye sees through that point: the eye's ray through the point meets
/// the model plane, and the frontal camera's ray through that model point meets the wall.
/// Checked by ray casting for the model plane on the wall (then the truth itself), in front of
/// it and at infinity, at every display pixel of the driver's view.
#[test]
fn the_ideal_display_on_a_curved_display_shows_the_ray_cast_model_point() {
    let wall_z = -6.0;
    let ctx = context(&wall(
        "display_shape = \"cylinder\"\ndisplay_radius = 0.2\ndisplay_segments = 48",
        -wall_z,
    ));
    let scene = &ctx.scene;
    // The obstacle frame is the world's here.
    let probe = DVec3::new(0.3, -0.2, 0.7);
    assert!((scene.obstacle.world_from_obstacle.transform_point3(probe) - probe).length() < 1e-12);
    let eye = scene.eye();
    let camera = scene.frontal.position();
    let to_wall = |from: DVec3, dir: DVec3| from + dir * ((wall_z - from.z) / dir.z);
    for (d2, worst_allowed) in [
        (WorkingDistance::Metres(6.0), 2e-4),
        (WorkingDistance::Metres(2.5), 2e-4),
        (WorkingDistance::Infinity, 2e-4),
    ] {
        let r = run(&ctx, &ideal(d2)).unwrap();
        let mask = display_mask(&ctx, &r.occluded);
        let (mut checked, mut worst, mut largest_shift) = (0, 0.0f64, 0.0f64);
        for i in (0..mask.len()).filter(|&i| mask[i]) {
            // Where the driver's ray meets the display's surface.
            let on_surface = r.occluded.position[i].as_dvec3();
            let ray = on_surface - eye;
            let expected = match d2 {
                WorkingDistance::Metres(d2) => {
                    let model = eye + ray * ((-d2 - eye.z) / ray.z);
                    to_wall(camera, model - camera)
                }
                _ => to_wall(camera, ray),
            };
            assert_eq!(r.seethru.object_id[i], 1, "pixel {i} shows the wall");
            let shown = r.seethru.position[i].as_dvec3();
            worst = worst.max((shown - expected).length());
            largest_shift = largest_shift.max((expected - r.truth.position[i].as_dvec3()).length());
            checked += 1;
        }
        assert!(checked > 1000, "{checked}");
        assert!(
            worst < worst_allowed,
            "{d2:?}: {worst} m from the ray-cast point"
        );
        // Off the wall the model misregisters by centimetres: the check above is not vacuous.
        if d2 != WorkingDistance::Metres(6.0) {
            assert!(largest_shift > 0.05, "{d2:?}: {largest_shift}");
        } else {
            assert!(largest_shift < worst_allowed, "{largest_shift}");
        }
    }
}

/// The binocular mismatch on a curved display is, per display pixel, the vergence of the
/// pixel's point on the curved surface minus that of the scene point it shows — not of the
/// flat reference rectangle's point (on this cylinder up to 5.4 cm nearer or farther).
#[test]
fn the_binocular_map_of_a_curved_display_uses_the_surface_points() {
    use seethru::measure::binocular::binocular_map;
    use seethru::system::eyes::{Eye, Eyes};
    let (width, height, radius, segments) = (0.3, 0.2, 0.2, 48);
    let ctx = context(&wall(
        &format!(
            "display_shape = \"cylinder\"\ndisplay_radius = {radius}\ndisplay_segments = {segments}"
        ),
        6.0,
    ));
    let scene = &ctx.scene;
    let eyes = Eyes::default();
    let (left, right) = (
        eyes.position(&scene.driver, Eye::Left),
        eyes.position(&scene.driver, Eye::Right),
    );
    let mut o = options(WorkingDistance::Metres(6.0));
    o.eyes.view = Eye::Left;
    let r = run(&ctx, &o).unwrap();
    let map = binocular_map(&r.display, &scene.obstacle, left, right);
    // The vergence at p: the angle between the directions to the two eyes, arc-minutes.
    let vergence = |p: DVec3| {
        let (a, b) = (left - p, right - p);
        a.cross(b).length().atan2(a.dot(b)).to_degrees() * 60.0
    };
    let [w, h] = scene.obstacle.display_resolution;
    let (mut checked, mut worst, mut flat_gap) = (0, 0.0f64, 0.0f64);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (u, v) = ((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let surface = cylinder_point(u, v, [width, height, radius], segments);
            let flat = DVec3::new((u - 0.5) * width, (0.5 - v) * height, 0.0);
            let shown = r.display.position[i].as_dvec3();
            let expected = vergence(surface) - vergence(shown);
            let got = map.mismatch_arcmin[i] as f64;
            assert!(got.is_finite(), "pixel ({x}, {y})");
            worst = worst.max((got - expected).abs());
            flat_gap = flat_gap.max((vergence(flat) - vergence(shown) - expected).abs());
            checked += 1;
        }
    }
    assert_eq!(checked, (w * h) as usize);
    assert!(worst < 0.01, "{worst}′ from the vergence geometry");
    // The flat rectangle's points would be many arc-minutes off at the display's edges.
    assert!(flat_gap > 5.0, "{flat_gap}′");
}

/// The metrics of `run` on `scene` with `options`, as `seethru run` writes them.
fn run_metrics(scene: &seethru::scene::Scene, options: &RunOptions) -> serde_json::Value {
    let ctx = RenderContext::new(scene.clone()).unwrap();
    let r = run(&ctx, options).unwrap();
    let (_, metrics) = seethru::measure::metrics::measure(
        &ctx,
        &ctx.scene,
        ctx.scene.eye(),
        r.measured_views(),
        5,
    );
    metrics.to_json()
}

/// `sequence --display ideal` on a curved display: a still head and vehicle with the model
/// plane on the wall show the wall exactly in every frame (no resampling quantum, and the
/// curved surface's own points through the model), as `run` does. With 2 samples a pixel,
/// the display's pixels show what `run`'s do: the same misregistration and PSNR.
#[test]
fn a_sequence_shows_the_ideal_curved_display_exactly() {
    use seethru::measure::image_metrics::Flip;
    use seethru::measure::sequence::run_sequence;
    let text = wall(
        "display_shape = \"cylinder\"\ndisplay_radius = 0.2\ndisplay_segments = 48",
        6.0,
    );
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
    let spp = 2;
    let largest_over_frames = |display| {
        let run = RunOptions {
            display,
            spp,
            ..options(WorkingDistance::Metres(6.0))
        };
        let o = common::still_sequence(run, 0.1, 30.0, 0.05);
        let how = common::measuring(Flip::Skipped);
        let run = run_sequence(&scene, o, how, &mut |_| Ok(())).unwrap();
        assert!(run.records.len() >= 3);
        let metrics: Vec<_> = run.records.iter().map(|r| r.metrics.unwrap()).collect();
        let largest = |f: fn(&FrameMetrics) -> f64| metrics.iter().map(f).fold(0.0, f64::max);
        (largest(|m| m.mean_arcmin), largest(|m| m.psnr_db))
    };
    use seethru::measure::sequence_records::FrameMetrics;
    use seethru::system::display::DisplayModel;
    let (ideal, _) = largest_over_frames(DisplayModel::Ideal);
    let (pixels, pixels_psnr) = largest_over_frames(DisplayModel::Pixels);
    assert!(ideal < 0.01, "ideal: {ideal}′");
    // The sequence renders only the frontal pixels the curved display reads; its still
    // frames are `run`'s, which renders the whole frontal image.
    let once = RunOptions {
        spp,
        ..options(WorkingDistance::Metres(6.0))
    };
    let metrics = run_metrics(&scene, &once);
    let single = metrics["display"]["misregistration_arcmin"]["mean"]
        .as_f64()
        .unwrap();
    assert!(
        (pixels - single).abs() < 1e-9 * single,
        "sequence {pixels}′, run {single}′"
    );
    // The colours too: a frontal or see-through view rendered with another sample count
    // would change the PSNR.
    let single_psnr = metrics["display"]["psnr_db"].as_f64().unwrap();
    assert!(
        (pixels_psnr - single_psnr).abs() < 1e-9 * single_psnr,
        "sequence PSNR {pixels_psnr} dB, run {single_psnr} dB"
    );
    // The physical display's pixels leave their quantum: the check above can tell.
    assert!(pixels > 20.0 * ideal && pixels > 0.1, "pixels: {pixels}′");
}

/// A scene whose obstacle at the origin faces `facing` with a cylinder display (`radius`,
/// 48 facets, 0.3 × 0.2 m at 150 × 100), the driver's eye at `eye_o` (obstacle frame) looking
/// at the display, and `objects` (material `tex`: the street texture).
fn curved_scene(facing: [f64; 3], radius: f64, eye_o: DVec3, objects: &str) -> RenderContext {
    let text = format!(
        r#"
[obstacle]
center = [0.0, 0.0, 0.0]
facing = {facing:?}
width = 0.3
height = 0.2
display_resolution = [150, 100]
display_shape = "cylinder"
display_radius = {radius}
display_segments = 48

[camera.driver]
position = [0.0, 0.0, 0.7]
look_at = [0.0, 0.0, -6.0]
half_angle_deg = 25.0
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
"#
    );
    let mut scene = common::parse_in(&common::repo_path("scenes"), "test.toml", &text).unwrap();
    let w = scene.obstacle.world_from_obstacle;
    scene.driver = seethru::geometry::camera::Camera::look_at(
        w.transform_point3(eye_o),
        w.transform_point3(DVec3::ZERO),
        w.transform_vector3(DVec3::Y),
        25f64.to_radians(),
        200,
        150,
    )
    .unwrap();
    RenderContext::new(scene).unwrap()
}

/// Per display pixel of the driver's view of a cylinder display (`radius`, 48 facets) on a
/// scene that is the plane `n · p = c`: the distance between the shown and the true point, and
/// the resampling quantum there — half a display pixel along the pixel's facet (u) and the
/// cylinder's axis (v), carried along the eye's ray to the plane, plus half a frontal pixel's
/// footprint on the plane around the true point, all by ray casting.
fn curved_errors_and_quanta(
    ctx: &RenderContext,
    r: &seethru::system::pipeline::RunResult,
    radius: f64,
    n: DVec3,
    c: f64,
) -> Vec<(f64, f64)> {
    let scene = &ctx.scene;
    let obstacle = &scene.obstacle;
    let world_from_obstacle = obstacle.world_from_obstacle;
    let obstacle_from_world = world_from_obstacle.inverse();
    let [dw, dh] = obstacle.display_resolution.map(f64::from);
    let segments = 48.0;
    let half_angle = obstacle.width / (2.0 * radius);
    let column = |k: f64| {
        let a = (k / segments - 0.5) * 2.0 * half_angle;
        DVec3::new(radius * a.sin(), 0.0, radius * a.cos() - radius)
    };
    let eye = scene.eye();
    let to_plane = |from: DVec3, through: DVec3| {
        let d = through - from;
        from + d * ((c - n.dot(from)) / n.dot(d))
    };
    let frontal = &scene.frontal;
    let mask = display_mask(ctx, &r.occluded);
    (0..mask.len())
        .filter(|&i| mask[i])
        .map(|i| {
            let t = r.truth.position[i].as_dvec3();
            let s = r.seethru.position[i].as_dvec3();
            let x = r.occluded.position[i].as_dvec3();
            let local = obstacle_from_world.transform_point3(x);
            let u = local.x.atan2(local.z + radius) / (2.0 * half_angle) + 0.5;
            let k = (u * segments).floor().clamp(0.0, segments - 1.0);
            let facet = column(k + 1.0) - column(k);
            // One display pixel spans facet · segments / W along the facet.
            let du = world_from_obstacle.transform_vector3(facet * (0.5 * segments / dw));
            let dv = world_from_obstacle.transform_vector3(DVec3::Y * (0.5 * obstacle.height / dh));
            let display = [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)]
                .map(|(a, b)| (to_plane(eye, x + du * a + dv * b) - to_plane(eye, x)).length())
                .into_iter()
                .fold(0.0, f64::max);
            let q = frontal.project_point(t).unwrap();
            let footprint = [(0.5, 0.5), (0.5, -0.5), (-0.5, 0.5), (-0.5, -0.5)]
                .map(|(a, b)| {
                    let (o, dir) = frontal.world_ray(q + DVec2::new(a, b));
                    (to_plane(o, o + dir) - t).length()
                })
                .into_iter()
                .fold(0.0, f64::max);
            ((s - t).length(), display + footprint)
        })
        .collect()
}

/// Every compensation method works per display pixel on a curved display: with the scene
/// model right (the plane on the wall, plane-fit on the wall, the ideal depth sensor, the
/// ground on a road) every display pixel of the driver's view shows the true point within its
/// resampling quantum; with the model wrong (d2 → ∞ before a wall 6 m away) most do not.
#[test]
fn every_compensation_method_registers_a_curved_display() {
    use seethru::system::depth_sensor::SensorKind;
    use seethru::system::options::Method;
    let radius = 0.15;
    let within = |errors: &[(f64, f64)]| {
        let inside = errors.iter().filter(|(e, q)| *e <= q * 1.02 + 1e-5).count();
        let worst = errors.iter().map(|(e, q)| e / q).fold(0.0, f64::max);
        (inside, errors.len(), worst)
    };
    let method = |m: Method, d2: WorkingDistance| RunOptions {
        method: m,
        ..options(d2)
    };
    let wall = curved_scene(
        [0.0, 0.0, 1.0],
        radius,
        DVec3::new(0.08, 0.03, 0.7),
        "[[object]]\nname = \"wall\"\nkind = \"quad\"\nmaterial = \"tex\"\nsize = [80.0, 60.0]\ntranslate = [0.0, 0.0, -6.0]",
    );
    let mut depth = method(Method::Depth, WorkingDistance::Infinity);
    depth.scene_model.sensor.kind = SensorKind::Ideal;
    for (name, o) in [
        (
            "planar d2 = 6",
            method(Method::Planar, WorkingDistance::Metres(6.0)),
        ),
        (
            "plane-fit",
            method(Method::PlaneFit, WorkingDistance::Infinity),
        ),
        ("depth", depth),
    ] {
        let r = run(&wall, &o).unwrap();
        let (inside, checked, worst) =
            within(&curved_errors_and_quanta(&wall, &r, radius, DVec3::Z, -6.0));
        eprintln!("{name}: {inside} of {checked}, worst {worst:.2} quanta");
        assert!(checked > 1000, "{name}: {checked}");
        assert_eq!(inside, checked, "{name} on the wall, worst {worst} quanta");
    }
    let r = run(&wall, &method(Method::Planar, WorkingDistance::Infinity)).unwrap();
    let (inside, checked, worst) =
        within(&curved_errors_and_quanta(&wall, &r, radius, DVec3::Z, -6.0));
    assert!(
        inside < checked / 2 && worst > 2.0,
        "planar d2 → ∞: {inside} of {checked}, worst {worst}"
    );
    // A road below an obstacle 1.2 m up that faces the driver and tilts up 31°: the display
    // shows only road.
    let road = curved_scene(
        [0.0, 0.6, 1.0],
        radius,
        DVec3::new(0.05, 0.03, 0.7),
        "[[object]]\nname = \"road\"\nkind = \"plane\"\nmaterial = \"tex\"\nsize = [200.0, 200.0]\ntranslate = [0.0, -1.2, 0.0]",
    );
    for m in [Method::Ground, Method::PlaneFit] {
        let r = run(&road, &method(m, WorkingDistance::Infinity)).unwrap();
        let (inside, checked, worst) =
            within(&curved_errors_and_quanta(&road, &r, radius, DVec3::Y, -1.2));
        eprintln!("{m:?} on the road: {inside} of {checked}, worst {worst:.2} quanta");
        assert!(checked > 1000, "{m:?}: {checked}");
        assert_eq!(inside, checked, "{m:?} on the road, worst {worst} quanta");
    }
}

/// The border bands of a curved display are its pixel grid's (from the UVs), not the
/// reference rectangle's: the driver's pixels in the left and right bands are those whose
/// point lies within `band` display pixels of the arc's ends.
#[test]
fn the_border_bands_of_a_curved_display_follow_its_uvs() {
    let (radius, band) = (0.12, 5u32);
    let ctx = context(&wall(
        &format!("display_shape = \"cylinder\"\ndisplay_radius = {radius}\ndisplay_segments = 48"),
        6.0,
    ));
    let r = run(&ctx, &options(WorkingDistance::Metres(6.0))).unwrap();
    let (_, metrics) = seethru::measure::metrics::measure(
        &ctx,
        &ctx.scene,
        ctx.scene.eye(),
        r.measured_views(),
        band,
    );
    let obstacle = &ctx.scene.obstacle;
    let half = obstacle.width / (2.0 * radius);
    let w = obstacle.display_resolution[0] as f64;
    let mask = display_mask(&ctx, &r.occluded);
    // u along the arc, from the point's angle round the cylinder's axis (the facets' chords
    // differ from the arc by under a thousandth of a pixel's share here).
    let u = |i: usize| {
        let p = r.occluded.position[i].as_dvec3();
        (p.x.atan2(p.z + radius) / (2.0 * half) + 0.5) * w
    };
    let count = |keep: &dyn Fn(f64) -> bool| {
        (0..mask.len()).filter(|&i| mask[i] && keep(u(i))).count() as f64
    };
    let (left, right) = (
        count(&|u| u < band as f64),
        count(&|u| u >= w - band as f64),
    );
    let metrics = metrics.to_json();
    let sides = &metrics["border_per_side"];
    let (got_left, got_right) = (
        sides["left"]["pixels"].as_f64().unwrap(),
        sides["right"]["pixels"].as_f64().unwrap(),
    );
    assert!(left > 50.0 && right > 50.0, "{left} {right}");
    assert!(
        (got_left - left).abs() <= 0.03 * left + 2.0,
        "left {got_left} vs {left}"
    );
    assert!(
        (got_right - right).abs() <= 0.03 * right + 2.0,
        "right {got_right} vs {right}"
    );
}

/// A curved display one pixel wide: all its points lie in one frontal column, and the
/// sequence still renders the frontal pixels they read, so its display shows what `run`'s
/// does (the same PSNR and misregistration).
#[test]
fn a_one_column_curved_display_shows_in_a_sequence_what_run_shows() {
    use seethru::measure::image_metrics::Flip;
    use seethru::measure::sequence::run_sequence;
    let text = common::WallScene {
        display_resolution: [1, 100],
        ..common::WallScene::default()
    }
    .text()
    .replace(
        "display_resolution = [",
        "display_shape = \"cylinder\"\ndisplay_radius = 0.2\ndisplay_segments = 48\ndisplay_resolution = [",
    );
    let scene = common::parse_in(&common::repo_path("scenes"), "wall.toml", &text).unwrap();
    let once = options(WorkingDistance::Metres(6.0));
    let o = common::still_sequence(once.clone(), 0.05, 20.0, 0.0);
    let how = common::measuring(Flip::Skipped);
    let sequence = run_sequence(&scene, o, how, &mut |_| Ok(()))
        .unwrap()
        .records[0]
        .metrics
        .unwrap();
    let metrics = run_metrics(&scene, &once);
    let display = &metrics["display"];
    assert!(sequence.display_pixels > 0);
    assert_eq!(sequence.psnr_db, display["psnr_db"].as_f64().unwrap());
    assert_eq!(
        sequence.mean_arcmin,
        display["misregistration_arcmin"]["mean"].as_f64().unwrap()
    );
}
