//! `[road] xodr`: OpenDRIVE maps as the scene's road. The mesh a map becomes against the
//! analytic curves its records describe (a line, an arc, a spiral, lane widths, an elevation
//! profile), the ego placement by ray casts, the route a sequence drives, and refusals.

mod common;

use std::f64::consts::PI;
use std::path::Path;

use glam::{DVec3, Vec3};
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::scene::road_map::road_part;
use seethru::scene::world::{World, view_bit};
use seethru::system::options::RunOptions;
use seethru::util::color::srgb_to_linear;

/// A map of one road, `id`, starting at (x, y) with heading `hdg`.
fn map(roads: &[String]) -> String {
    format!(
        "<?xml version=\"1.0\"?><OpenDRIVE><header revMajor=\"1\" revMinor=\"6\" name=\"t\"/>{}</OpenDRIVE>",
        roads.concat()
    )
}

fn lane(id: i32, kind: &str, width: &str, mark: &str, extra: &str) -> String {
    format!(
        "<lane id=\"{id}\" type=\"{kind}\" level=\"false\"><width sOffset=\"0\" {width}/>\
         <roadMark sOffset=\"0\" type=\"{mark}\" color=\"standard\" width=\"0.12\"/>{extra}</lane>"
    )
}

fn width(a: f64, b: f64) -> String {
    format!("a=\"{a}\" b=\"{b}\" c=\"0\" d=\"0\"")
}

/// A road: its plan view's `<geometry>` records, its length, left and right lanes, and an
/// elevation profile.
fn road(id: &str, geometry: &str, length: f64, left: &str, right: &str, elevation: &str) -> String {
    format!(
        "<road id=\"{id}\" length=\"{length}\" junction=\"-1\"><planView>{geometry}</planView>\
         <elevationProfile>{elevation}</elevationProfile><lateralProfile/><lanes><laneSection s=\"0\">\
         <left>{left}</left><center><lane id=\"0\" type=\"none\" level=\"false\">\
         <roadMark sOffset=\"0\" type=\"solid\" color=\"standard\" width=\"0.12\"/></lane></center>\
         <right>{right}</right></laneSection></lanes></road>"
    )
}

/// A scene of das's cameras and obstacle over the map `xodr` with the `[road]` keys `keys`,
/// written with its map into `dir`.
fn scene_with_road(dir: &Path, xodr: &str, keys: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("map.xodr"), xodr).unwrap();
    // das without its objects: the road is the only thing to hit.
    let text = format!(
        "{}\n[road]\nxodr = \"map.xodr\"\n{keys}\n",
        common::das_without_objects()
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn world_of(path: &Path) -> World {
    World::build(&Scene::load(path).unwrap_or_else(|e| panic!("{e}"))).unwrap()
}

/// Every distinct vertex of the road's triangles of `part`, in OpenDRIVE's frame (the map
/// placed without an ego lane: world = (x, z, −y)).
fn map_vertices(world: &World, part: u32) -> Vec<DVec3> {
    let road = 1 + world.objects.iter().position(|o| o.name == "road").unwrap() as u32;
    let mut out: Vec<DVec3> = Vec::new();
    for (tri, attr) in world.triangles.iter().zip(&world.tri_attrs) {
        if attr.object != road || attr.part != part {
            continue;
        }
        for v in [tri.v0, tri.v0 - tri.e1, tri.v0 + tri.e2] {
            let w = Vec3::from(v).as_dvec3();
            let p = DVec3::new(w.x, -w.z, w.y);
            if !out.iter().any(|q| q.distance(p) < 1e-4) {
                out.push(p);
            }
        }
    }
    out
}

/// A reference line from `start` heading `hdg`, its curvature `curvature(s)`, integrated
/// at 5 mm steps (midpoint rule on the heading: the chord error is far below a micrometre).
fn reference_line(
    start: DVec3,
    hdg: f64,
    length: f64,
    curvature: impl Fn(f64) -> f64,
) -> Vec<DVec3> {
    let steps = (length / 0.005).ceil() as usize;
    let ds = length / steps as f64;
    let (mut p, mut theta) = (start, hdg);
    let mut line = vec![p];
    for i in 0..steps {
        let s = i as f64 * ds;
        // Heading at the step's middle: θ + κ(s + ds/4)·ds/2 (exact for a linear κ).
        let mid = theta + curvature(s + ds / 4.0) * ds / 2.0;
        p += ds * DVec3::new(mid.cos(), mid.sin(), 0.0);
        theta += curvature(s + ds / 2.0) * ds;
        line.push(p);
    }
    line
}

/// The horizontal distance from `p` to the polyline `line`, and the arc length there.
fn distance_to(line: &[DVec3], p: DVec3) -> (f64, f64) {
    let flat = |v: DVec3| DVec3::new(v.x, v.y, 0.0);
    let (mut best, mut at, mut along) = (f64::INFINITY, 0.0, 0.0);
    for w in line.windows(2) {
        let (a, b) = (flat(w[0]), flat(w[1]));
        let ab = b - a;
        let f = ((flat(p) - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        let d = (flat(p) - (a + f * ab)).length();
        if d < best {
            (best, at) = (d, along + f * ab.length());
        }
        along += ab.length();
    }
    (best, at)
}

/// Curvature of the circle through three points (signed: positive turning left).
fn circle_curvature(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, bc, ca) = (b - a, c - b, a - c);
    let cross = ab.x * bc.y - ab.y * bc.x;
    2.0 * cross / (ab.length() * bc.length() * ca.length())
}

#[test]
fn a_line_an_arc_and_a_spiral_are_meshed_on_their_analytic_curves() {
    let dir = tempfile::tempdir().unwrap();
    // 20 m of line, 30 m of arc (R = 40 m, left), 40 m of spiral back to straight.
    let (r, start, hdg): (f64, DVec3, f64) = (40.0, DVec3::new(5.0, -3.0, 0.0), 0.3);
    let geometry = format!(
        "<geometry s=\"0\" x=\"{}\" y=\"{}\" hdg=\"{hdg}\" length=\"20\"><line/></geometry>\
         <geometry s=\"20\" x=\"{}\" y=\"{}\" hdg=\"{hdg}\" length=\"30\"><arc curvature=\"{}\"/></geometry>",
        start.x,
        start.y,
        start.x + 20.0 * hdg.cos(),
        start.y + 20.0 * hdg.sin(),
        1.0 / r
    );
    let curvature = |s: f64| {
        if s < 20.0 {
            0.0
        } else if s < 50.0 {
            1.0 / r
        } else {
            (1.0 / r) * (1.0 - (s - 50.0) / 40.0)
        }
    };
    let line = reference_line(start, hdg, 90.0, curvature);
    // The spiral starts where the analytic line has reached at s = 50.
    let at50 = line[(50.0 / 0.005) as usize];
    let theta50 = hdg + 30.0 / r;
    let geometry = format!(
        "{geometry}<geometry s=\"50\" x=\"{}\" y=\"{}\" hdg=\"{theta50}\" length=\"40\"><spiral curvStart=\"{}\" curvEnd=\"0\"/></geometry>",
        at50.x,
        at50.y,
        1.0 / r
    );
    let lanes_left = lane(1, "driving", &width(3.5, 0.0), "none", "");
    let lanes_right = lane(-1, "driving", &width(3.5, 0.0), "none", "");
    let xodr = map(&[road("1", &geometry, 90.0, &lanes_left, &lanes_right, "")]);
    let world = world_of(&scene_with_road(dir.path(), &xodr, ""));
    let vertices = map_vertices(&world, road_part::ASPHALT);
    assert!(vertices.len() > 60, "{} vertices", vertices.len());
    // Every vertex on the reference line or 3.5 m beside it, within a millimetre.
    let mut on_line: Vec<(f64, DVec3)> = Vec::new();
    for &v in &vertices {
        let (d, s) = distance_to(&line, v);
        let off = d.min((d - 3.5).abs());
        assert!(
            off < 1e-3,
            "vertex {v} at s = {s:.3}: {d:.5} m from the line"
        );
        if d < 1e-3 {
            on_line.push((s, v));
        }
    }
    on_line.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(on_line.first().unwrap().0 < 1e-3 && on_line.last().unwrap().0 > 90.0 - 1e-3);
    // The two lanes' edges along the line are sampled apart (a few millimetres, where a
    // rib is square to its own lane): one vertex per station, the stations ≥ 0.2 m apart
    // (the crate samples every 0.25–2 m), so that three of them span a measurable arc.
    let mut stations: Vec<(f64, DVec3)> = Vec::new();
    for &(s, v) in &on_line {
        if stations.last().is_none_or(|&(last, _)| s - last >= 0.2) {
            stations.push((s, v));
        }
    }
    assert!(on_line.windows(2).all(|w| w[1].0 - w[0].0 <= 2.0 + 1e-3));
    let on_line = stations;
    // The curvature of each three consecutive vertices against the records': zero on the
    // line, 1/R on the arc, falling linearly on the spiral. Vertices are f32 (a few µm at
    // 100 m) on chords of 0.25–2 m: the circle through three of them is good to ~1e-4 /m.
    let mut checked = [0; 3];
    for w in on_line.windows(3) {
        let (s0, s1, s2) = (w[0].0, w[1].0, w[2].0);
        // Triples that straddle a change of record carry both records' curvature.
        if [20.0, 50.0].iter().any(|&b| s0 < b && s2 > b) {
            continue;
        }
        let measured = circle_curvature(w[0].1, w[1].1, w[2].1);
        let expected = curvature((s0 + s1 + s2) / 3.0);
        assert!(
            (measured - expected).abs() < 2e-4,
            "s = {s1:.2}: curvature {measured:.6} /m, the map's {expected:.6} /m"
        );
        checked[if s1 < 20.0 {
            0
        } else if s1 < 50.0 {
            1
        } else {
            2
        }] += 1;
    }
    assert!(
        checked.iter().all(|&n| n >= 3),
        "triples per record: {checked:?}"
    );
}

#[test]
fn lane_widths_and_the_elevation_profile_follow_the_map() {
    let dir = tempfile::tempdir().unwrap();
    // Road 1 climbs on a cubic with lanes of constant width; road 2, 100 m north, is flat
    // with a right lane widening from 3.0 m by 2 cm per metre. (The crate sets each rib
    // square to its lane's centre line: on a lane that widens along a grade a vertex takes
    // the height of a station up to w/2 · dw/ds further on — 1.2 mm here — so each road
    // tests one.)
    let climbing = road(
        "1",
        "<geometry s=\"0\" x=\"0\" y=\"0\" hdg=\"0\" length=\"60\"><line/></geometry>",
        60.0,
        &lane(1, "driving", &width(3.5, 0.0), "none", ""),
        &lane(-1, "driving", &width(3.0, 0.0), "none", ""),
        "<elevation s=\"0\" a=\"1.0\" b=\"0.03\" c=\"0.001\" d=\"-0.00001\"/>",
    );
    let widening = road(
        "2",
        "<geometry s=\"0\" x=\"0\" y=\"100\" hdg=\"0\" length=\"60\"><line/></geometry>",
        60.0,
        &lane(1, "driving", &width(3.5, 0.0), "none", ""),
        &lane(-1, "driving", &width(3.0, 0.02), "none", ""),
        "",
    );
    let world = world_of(&scene_with_road(
        dir.path(),
        &map(&[climbing, widening]),
        "",
    ));
    let (mut heights, mut right_edge, mut left_edge) = (0, 0, 0);
    for v in map_vertices(&world, road_part::ASPHALT) {
        let s = v.x;
        if v.y < 50.0 {
            let z = 1.0 + 0.03 * s + 0.001 * s * s - 0.00001 * s * s * s;
            assert!(
                (v.z - z).abs() < 1e-3,
                "s = {s}: height {} against {z}",
                v.z
            );
            heights += 1;
            continue;
        }
        let t = v.y - 100.0;
        if t < -1e-3 {
            let w = 3.0 + 0.02 * s;
            assert!(
                (-t - w).abs() < 1e-3,
                "s = {s}: right edge at {t}, width {w}"
            );
            right_edge += 1;
        } else if t > 1e-3 {
            assert!((t - 3.5).abs() < 1e-3, "s = {s}: left edge at {t}");
            left_edge += 1;
        }
    }
    assert!(heights >= 60 && right_edge >= 2 && left_edge >= 2);
}

/// A straight road `7` from (100, −40) at heading 0.7 rad: lane 1 (left) 3.0 m, lane −1
/// (right) 3.5 m, solid lines at the centre and both outer edges.
fn slanted_road() -> String {
    let geometry =
        "<geometry s=\"0\" x=\"100\" y=\"-40\" hdg=\"0.7\" length=\"80\"><line/></geometry>";
    map(&[road(
        "7",
        geometry,
        80.0,
        &lane(1, "driving", &width(3.0, 0.0), "solid", ""),
        &lane(-1, "driving", &width(3.5, 0.0), "solid", ""),
        "",
    )])
}

/// What a ray straight down at world (x, z) finds: the part of the road it hits and its
/// height, or `None`.
fn down(ctx: &RenderContext, x: f32, z: f32) -> Option<(u32, f32)> {
    let hit = ctx.trace(Vec3::new(x, 5.0, z), Vec3::NEG_Y, view_bit::TRUTH)?;
    Some((hit.part, hit.position.y))
}

#[test]
fn the_ego_lane_lands_on_lane_center_at_and_runs_along_minus_z() {
    let dir = tempfile::tempdir().unwrap();
    let keys = "ego_road = \"7\"\nego_lane = -1\nego_s = 30.0\nlane_center_at = [1.75, 0.25, 0.0]";
    let path = scene_with_road(dir.path(), &slanted_road(), keys);
    let ctx = RenderContext::new(Scene::load(&path).unwrap()).unwrap();
    // Lane −1 (3.5 m, traffic along s): its centre under lane_center_at, its surface at
    // lane_center_at's height; the centre line 1.75 m to the left, the edge line 1.75 m to
    // the right, here and 20 m ahead; lane 1 (3.0 m) beyond the centre line, nothing past
    // either edge.
    for z in [0.0, -20.0] {
        let (part, y) = down(&ctx, 1.75, z).unwrap();
        assert_eq!(part, road_part::ASPHALT);
        assert!((y - 0.25).abs() < 1e-4, "height {y}");
        assert_eq!(down(&ctx, 0.0, z).unwrap().0, road_part::MARKING, "z {z}");
        assert_eq!(down(&ctx, 3.5, z).unwrap().0, road_part::MARKING, "z {z}");
        assert_eq!(down(&ctx, 0.3, z).unwrap().0, road_part::ASPHALT);
        assert_eq!(down(&ctx, -2.7, z).unwrap().0, road_part::ASPHALT);
        assert!(down(&ctx, -3.3, z).is_none());
        assert!(down(&ctx, 4.0, z).is_none());
    }
    // Lane 1 (3.0 m) runs against s: facing its traffic the centre line is on the left
    // too, at x = 1.5 − 1.5, with lane −1 (3.5 m) beyond it; the edge line on the right.
    let keys = "ego_road = \"7\"\nego_lane = 1\nego_s = 30.0\nlane_center_at = [1.5, 0.0, 0.0]";
    let path = scene_with_road(dir.path(), &slanted_road(), keys);
    let ctx = RenderContext::new(Scene::load(&path).unwrap()).unwrap();
    for z in [0.0, -20.0] {
        assert_eq!(down(&ctx, 0.0, z).unwrap().0, road_part::MARKING, "z {z}");
        assert_eq!(down(&ctx, 3.0, z).unwrap().0, road_part::MARKING, "z {z}");
        assert_eq!(down(&ctx, -3.2, z).unwrap().0, road_part::ASPHALT, "z {z}");
        assert!(down(&ctx, -3.8, z).is_none());
        assert!(down(&ctx, 3.5, z).is_none());
    }
}

#[test]
fn a_raised_sidewalk_has_a_kerb_face_towards_the_road() {
    let dir = tempfile::tempdir().unwrap();
    let geometry = "<geometry s=\"0\" x=\"-20\" y=\"0\" hdg=\"0\" length=\"60\"><line/></geometry>";
    let height = "<height sOffset=\"0\" inner=\"0.15\" outer=\"0.15\"/>";
    let right = lane(-1, "driving", &width(3.5, 0.0), "none", "")
        + &lane(-2, "sidewalk", &width(2.0, 0.0), "none", height);
    let xodr = map(&[road("1", geometry, 60.0, "", &right, "")]);
    let keys = "ego_road = \"1\"\nego_lane = -1\nego_s = 20.0\nlane_center_at = [0.0, 0.0, 0.0]";
    let path = scene_with_road(dir.path(), &xodr, keys);
    let ctx = RenderContext::new(Scene::load(&path).unwrap()).unwrap();
    // The sidewalk lies right of the lane: x ∈ [1.75, 3.75], 15 cm up.
    let (part, y) = down(&ctx, 2.75, -5.0).unwrap();
    assert_eq!(part, road_part::SIDEWALK);
    assert!((y - 0.15).abs() < 1e-4);
    // Looking right from the lane at kerb height: its face at x = 1.75; above it, nothing.
    let face = ctx
        .trace(Vec3::new(0.0, 0.07, -5.0), Vec3::X, view_bit::TRUTH)
        .unwrap();
    assert_eq!(face.part, road_part::KERB);
    assert!((face.position.x - 1.75).abs() < 1e-4);
    assert!(
        ctx.trace(Vec3::new(0.0, 0.2, -5.0), Vec3::X, view_bit::TRUTH)
            .is_none()
    );
}

#[test]
fn a_wet_map_coats_its_lanes_sidewalks_kerbs_and_marks_but_not_its_verges() {
    let dir = tempfile::tempdir().unwrap();
    let geometry = "<geometry s=\"0\" x=\"-20\" y=\"0\" hdg=\"0\" length=\"60\"><line/></geometry>";
    let height = "<height sOffset=\"0\" inner=\"0.15\" outer=\"0.15\"/>";
    let right = lane(-1, "driving", &width(3.5, 0.0), "solid", "")
        + &lane(-2, "sidewalk", &width(2.0, 0.0), "none", height)
        + &lane(-3, "border", &width(1.0, 0.0), "none", "");
    let xodr = map(&[road("1", geometry, 60.0, "", &right, "")]);
    for (keys, f0, alpha) in [
        ("", 0.0, 0.2),
        ("specular = 0.02\nroughness = 0.15", 0.02, 0.15),
    ] {
        let world = world_of(&scene_with_road(dir.path(), &xodr, keys));
        let road = 1 + world.objects.iter().position(|o| o.name == "road").unwrap() as u32;
        let mut parts = std::collections::BTreeSet::new();
        for attr in world.tri_attrs.iter().filter(|a| a.object == road) {
            let m = &world.materials[attr.material as usize];
            let paved = attr.part != road_part::VERGE;
            let (want_f0, want_alpha) = if paved { (f0, alpha) } else { (0.0, 0.2) };
            assert_eq!(
                (m.specular, m.roughness),
                (want_f0 as f32, want_alpha as f32),
                "part {} with `{keys}`",
                attr.part
            );
            parts.insert(attr.part);
        }
        let all = [
            road_part::ASPHALT,
            road_part::SIDEWALK,
            road_part::KERB,
            road_part::MARKING,
        ];
        assert!(
            all.iter()
                .chain([&road_part::VERGE])
                .all(|p| parts.contains(p)),
            "{parts:?}"
        );
    }
}

#[test]
fn what_the_importer_skips_in_a_map_is_a_warning_naming_the_map() {
    // A road with a `<geometry>` of no length (which xodr drops, and says so) renders, with
    // one `warning:` line naming the map and the geometry; the bundled map has none. So do
    // `capture` and `dataset`, which read the scene their own way (`dataset` also when a
    // sample then fails), `score`, which captures again, and `reproduce`, which says it
    // before it refuses a scene without das's car.
    let dir = tempfile::tempdir().unwrap();
    let geometry = "<geometry s=\"0\" x=\"-20\" y=\"0\" hdg=\"0\" length=\"60\"><line/></geometry>";
    let right = lane(-1, "driving", &width(3.5, 0.0), "none", "");
    let plain = road("1", geometry, 60.0, "", &right, "");
    let dropped = "<geometry s=\"60\" x=\"40\" y=\"0\" hdg=\"0\" length=\"0\"><line/></geometry>";
    let with_dropped = plain.replacen("</planView>", &format!("{dropped}</planView>"), 1);
    for (xodr, warned) in [(map(&[plain]), false), (map(&[with_dropped]), true)] {
        let scene = scene_with_road(dir.path(), &xodr, "");
        let scene = scene.to_str().unwrap();
        let spec = dir.path().join("spec.toml");
        std::fs::write(
            &spec,
            format!("scene = {scene:?}\nsamples = 1\nseed = 1\n[options]\nwidth = 16\nspp = 1\n"),
        )
        .unwrap();
        let spec = spec.to_str().unwrap();
        let out = dir.path().join(format!("out_{warned}"));
        let at = |name: &str| out.join(name).to_str().unwrap().to_string();
        let small = ["--width", "16", "--frontal-width", "16", "--quiet"];
        // A display image of the wrong size: `score` captures again (and says the warning)
        // before it finds that out.
        let image = dir.path().join("one_pixel.png");
        image::RgbImage::new(1, 1).save(&image).unwrap();
        let (captured, image) = (at("capture"), image.to_str().unwrap().to_string());
        std::fs::create_dir_all(out.join("dataset_blocked/samples")).unwrap();
        std::fs::write(out.join("dataset_blocked/samples/000000"), "").unwrap();
        let commands: Vec<(Vec<String>, bool)> = [
            (
                vec![
                    "render", scene, "--view", "truth", "--width", "16", "--quiet", "--out",
                ],
                "render",
                true,
            ),
            (
                [&["capture", scene][..], &small, &["--out"]].concat(),
                "capture",
                true,
            ),
            (vec!["dataset", spec, "--quiet", "--out"], "dataset", true),
            // A sample that cannot be written (its folder's name taken by a file): the map's
            // warning is said before the error, not lost with the samples' at the end.
            (
                vec!["dataset", spec, "--quiet", "--out"],
                "dataset_blocked",
                false,
            ),
            (
                vec!["reproduce", "--quick", "--scene", scene, "--out"],
                "reproduce",
                false,
            ),
            (
                vec!["score", &captured, "--display-image", &image, "--out"],
                "score",
                false,
            ),
        ]
        .into_iter()
        .map(|(args, folder, succeeds)| {
            let mut args: Vec<String> = args.into_iter().map(String::from).collect();
            args.push(at(folder));
            (args, succeeds)
        })
        .collect();
        for (args, succeeds) in commands {
            let words: Vec<&str> = args.iter().map(String::as_str).collect();
            let (ok, _, stderr) = common::seethru(&words);
            assert_eq!(ok, succeeds, "{}: {stderr}", args[0]);
            let warnings: Vec<&str> = stderr
                .lines()
                .filter(|l| l.starts_with("warning: "))
                .collect();
            if warned {
                assert_eq!(warnings.len(), 1, "{}: {stderr}", args[0]);
                assert!(
                    warnings[0].contains("map.xodr") && warnings[0].contains("<geometry> at s 60"),
                    "{}: {stderr}",
                    args[0]
                );
            } else {
                assert!(warnings.is_empty(), "{}: {stderr}", args[0]);
            }
        }
    }
    let bundled = Scene::load(&common::repo_path("scenes/intersection.toml")).unwrap();
    assert!(bundled.warnings.is_empty(), "{:?}", bundled.warnings);
}

#[test]
fn the_map_is_read_once_with_the_scene() {
    // The world is built from the map the scene read: a map file changed (here spoiled)
    // after the scene was read does not reach it, and the road is the one read.
    let dir = tempfile::tempdir().unwrap();
    let geometry = "<geometry s=\"0\" x=\"-20\" y=\"0\" hdg=\"0\" length=\"60\"><line/></geometry>";
    let right = lane(-1, "driving", &width(3.5, 0.0), "none", "");
    let path = scene_with_road(
        dir.path(),
        &map(&[road("1", geometry, 60.0, "", &right, "")]),
        "",
    );
    let scene = Scene::load(&path).unwrap();
    let before = World::build(&scene).unwrap();
    std::fs::write(dir.path().join("map.xodr"), "not a map").unwrap();
    let after = World::build(&scene).unwrap();
    let asphalt = map_vertices(&before, road_part::ASPHALT);
    assert!(!asphalt.is_empty());
    assert_eq!(map_vertices(&after, road_part::ASPHALT), asphalt);
    assert_eq!(after.triangles.len(), before.triangles.len());
    // Two reads of one text are equal scenes; a different text is not.
    let again = scene_with_road(
        dir.path(),
        &map(&[road("1", geometry, 60.0, "", &right, "")]),
        "",
    );
    assert_eq!(Scene::load(&again).unwrap(), scene);
    let wider = lane(-1, "driving", &width(3.6, 0.0), "none", "");
    let other = scene_with_road(
        dir.path(),
        &map(&[road("1", geometry, 60.0, "", &wider, "")]),
        "",
    );
    assert_ne!(Scene::load(&other).unwrap(), scene);
}

#[test]
fn signals_are_boards_of_their_size_at_their_place_facing_their_heading() {
    // A sign 3 m right of the reference line at s = 20 (x = 0), 2 m up, 0.8 × 0.5 m, facing
    // the traffic; a traffic light at s = 30 (x = 10) turned a quarter turn by its hOffset,
    // of the default size.
    let dir = tempfile::tempdir().unwrap();
    let geometry = "<geometry s=\"0\" x=\"-20\" y=\"0\" hdg=\"0\" length=\"60\"><line/></geometry>";
    let right = lane(-1, "driving", &width(3.5, 0.0), "none", "");
    let signals = "<signals>\
        <signal s=\"20\" t=\"-3\" id=\"1\" dynamic=\"no\" orientation=\"+\" zOffset=\"2\" \
         type=\"274\" subtype=\"-1\" country=\"DE\" width=\"0.8\" height=\"0.5\" hOffset=\"0\"/>\
        <signal s=\"30\" t=\"-3\" id=\"2\" dynamic=\"yes\" orientation=\"+\" zOffset=\"2\" \
         type=\"1000001\" subtype=\"-1\" country=\"OpenDRIVE\" hOffset=\"1.5707963\"/></signals>";
    let xodr =
        map(&[road("1", geometry, 60.0, "", &right, "")
            .replace("</road>", &format!("{signals}</road>"))]);
    let world = world_of(&scene_with_road(
        dir.path(),
        &xodr,
        "signal_color = [0.9, 0.1, 0.1]",
    ));
    let boards = map_vertices(&world, road_part::SIGNAL);
    let bounds = |near_x: f64| {
        let corners: Vec<DVec3> = boards
            .iter()
            .copied()
            .filter(|p| (p.x - near_x).abs() < 2.0)
            .collect();
        assert_eq!(corners.len(), 8, "{corners:?}");
        let lo = corners.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
        let hi = corners.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
        (lo, hi)
    };
    let close = |a: DVec3, b: [f64; 3]| (a - DVec3::from_array(b)).abs().max_element() < 1e-4;
    let (lo, hi) = bounds(0.0);
    assert!(
        close(lo, [-0.025, -3.4, 2.0]) && close(hi, [0.025, -2.6, 2.5]),
        "{lo} {hi}"
    );
    let (lo, hi) = bounds(10.0);
    assert!(
        close(lo, [9.7, -3.025, 2.0]) && close(hi, [10.3, -2.975, 2.6]),
        "{lo} {hi}"
    );
    // Each takes its colour.
    let road = 1 + world.objects.iter().position(|o| o.name == "road").unwrap() as u32;
    let colours: std::collections::BTreeSet<[u32; 3]> = (world.tri_attrs.iter())
        .filter(|a| a.object == road && a.part == road_part::SIGNAL)
        .map(|a| {
            world.materials[a.material as usize]
                .albedo
                .to_array()
                .map(f32::to_bits)
        })
        .collect();
    let want = |srgb: f32| srgb_to_linear(srgb).to_bits();
    let expected = [[want(0.9), want(0.1), want(0.1)], [want(0.08); 3]];
    assert_eq!(colours, expected.into_iter().collect());
}

/// The vehicle's lane centre and heading at `t` for the scene at `path` at 10 km/h.
fn driven(scene: &Scene, t: f64) -> (DVec3, f64) {
    let options = RunOptions {
        speed_kmh: 10.0,
        ..RunOptions::default()
    };
    let motion = options.vehicle_motion(scene).unwrap();
    let start = scene.ego_route.as_ref().unwrap().pose_at(0.0).position;
    (
        motion.world_from_rig(t).transform_point3(start),
        motion.yaw_at(t),
    )
}

#[test]
fn a_sequence_drives_the_left_turn_through_the_junction_and_on_down_the_west_arm() {
    let scene = Scene::load(&common::repo_path("scenes/intersection.toml")).unwrap();
    // The connecting road's lane centre turns on 11.75 m about the junction's south-west
    // corner, which the ego placement puts at world (−10, 0, 0); 10 km/h is 2.78 m/s.
    let (v, r, corner) = (10.0 / 3.6, 11.75, DVec3::new(-10.0, 0.0, 0.0));
    let quarter = PI / 2.0 * r / v;
    for k in 0..=10 {
        let t = quarter * f64::from(k) / 10.0;
        let (p, yaw) = driven(&scene, t);
        assert!((p.distance(corner) - r).abs() < 5e-3, "t {t}: {p}");
        // The heading at a vertex is the mean of the chords beside it: where the arc meets
        // the straight arm (k = 10) that is a quarter of a chord's turn (~0.3°) short.
        let bound = if k == 10 { 0.5 } else { 0.2 };
        assert!(
            (yaw - v * t / r).abs() < f64::to_radians(bound),
            "t {t}: yaw {yaw}"
        );
    }
    // Then west along the arm's lane −1, 1.75 m north of its reference line (z = −10).
    let (p, yaw) = driven(&scene, quarter + 5.0);
    assert!(
        (p.z + 11.75).abs() < 5e-3 && (p.x - (-10.0 - 5.0 * v)).abs() < 0.02,
        "{p}"
    );
    assert!((yaw - PI / 2.0).abs() < 1e-3);
}

#[test]
fn turns_choose_the_way_through_a_junction() {
    let dir = tempfile::tempdir().unwrap();
    let xodr =
        std::fs::read_to_string(common::repo_path("assets/roads/intersection.xodr")).unwrap();
    // 5 m before the junction on the south arm (road 1, lane 1 runs north into it).
    let place = "ego_road = \"1\"\nego_lane = 1\nego_s = 5.0\nlane_center_at = [1.75, 0.0, 0.0]";
    let heading_after = |turns: &str| {
        let path = scene_with_road(dir.path(), &xodr, &format!("{place}\n{turns}"));
        let scene = Scene::load(&path).unwrap();
        // 5 m to the junction, a quarter circle (at most 18.5 m), then 10 m on.
        driven(&scene, 35.0 / (10.0 / 3.6)).1.to_degrees()
    };
    assert!((heading_after("turns = [\"left\"]") - 90.0).abs() < 0.1);
    assert!((heading_after("turns = [\"right\"]") + 90.0).abs() < 0.1);
    assert!(heading_after("turns = [\"straight\"]").abs() < 0.1);
    assert!(heading_after("").abs() < 0.1, "straight on by default");
}

#[test]
fn bad_maps_and_bad_keys_are_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = slanted_road();
    let ego = "ego_road = \"7\"\nego_lane = -1\nego_s = 30.0";
    let cases: Vec<(String, String, Vec<&str>)> = vec![
        (
            "<OpenDRIVE><road".into(),
            String::new(),
            vec!["xodr", "map.xodr", "OpenDRIVE"],
        ),
        (String::new(), String::new(), vec!["xodr", "map.xodr"]),
        (
            "\u{0}\u{1}binary".into(),
            String::new(),
            vec!["xodr", "map.xodr"],
        ),
        (map(&[]), String::new(), vec!["xodr", "no lanes"]),
        (
            good.clone(),
            "ego_road = \"8\"\nego_lane = -1\nego_s = 3.0".into(),
            vec!["ego_road", "no road `8`", "7"],
        ),
        (
            good.clone(),
            "ego_road = \"7\"\nego_lane = 0\nego_s = 3.0".into(),
            vec!["ego_lane", "reference line"],
        ),
        (
            good.clone(),
            "ego_road = \"7\"\nego_lane = -2\nego_s = 3.0".into(),
            vec!["ego_lane", "no lane -2", "-1, 1"],
        ),
        (
            good.clone(),
            "ego_road = \"7\"\nego_lane = -1\nego_s = 81.0".into(),
            vec!["ego_s", "80.000"],
        ),
        (
            good.clone(),
            "ego_road = \"7\"\nego_lane = -1".into(),
            vec!["ego_road", "ego_s"],
        ),
        (
            good.clone(),
            "lane_center_at = [1.0, 0.0, 0.0]".into(),
            vec!["lane_center_at", "ego_road"],
        ),
        (
            good.clone(),
            format!("{ego}\nturns = [\"back\"]"),
            vec!["turns", "back", "left, straight, right"],
        ),
        (
            good.clone(),
            format!("{ego}\nasphalt_color = [2.0, 0.0, 0.0]"),
            vec!["asphalt_color"],
        ),
        (
            good.clone(),
            format!("{ego}\nspecular = 1.5"),
            vec!["specular", "1.5", "[0, 1]"],
        ),
        (
            good.clone(),
            format!("{ego}\nroughness = 0.001"),
            vec!["roughness", "0.001", "[0.01, 1]"],
        ),
        (
            good.clone(),
            format!("{ego}\nlanes = 2"),
            vec!["lanes", "unknown"],
        ),
    ];
    for (xodr, keys, words) in cases {
        scene_with_road(dir.path(), &xodr, &keys);
        let mut words = words;
        words.push("scene.toml");
        common::refusal::render_refused(dir.path(), &words);
    }
    // A map named by another extension, and one that is not there.
    let path = dir.path().join("scene.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    for (name, word) in [("map.xml", ".xodr"), ("gone.xodr", "cannot read")] {
        std::fs::write(&path, text.replace("map.xodr", name)).unwrap();
        common::refusal::render_refused(dir.path(), &["xodr", word]);
    }
}

#[test]
fn a_yaw_rate_is_refused_where_the_vehicle_follows_its_lane() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::repo_path("scenes/intersection.toml");
    common::refusal::refused(
        dir.path(),
        &[
            "sequence",
            scene.to_str().unwrap(),
            "--speed",
            "10",
            "--yaw-rate",
            "13.5",
            "--duration",
            "1",
            "--width",
            "16",
            "--out",
            "o",
        ],
        1,
        &["yaw-rate", "lane"],
    );
}
