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
use seethru::system::surface_map::{PointModel, display_points};

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
    let street = common::repo_path("assets/street.png");
    let text = text.replace("../assets/street.png", &street.display().to_string());
    std::fs::write(dir.path().join("scene.toml"), text).unwrap();
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
