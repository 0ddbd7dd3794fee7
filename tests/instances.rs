//! Instanced meshes (`[[object]] instances`): the two-level hierarchy against the same world
//! flattened, bit for bit (the images of every view, each query's primitive and distance),
//! and against the brute force; placements read and refused; a hundred million instanced
//! triangles held in little memory.

mod common;

use glam::Vec3;
use seethru::render::accel::{Accel, closest_brute_force, make_ray, occluded_brute_force};
use seethru::render::bvh_packet::{PACKET, PacketStack, RayPacket};
use seethru::render::integrator::RenderContext;
use seethru::render::render_job::RenderJob;
use seethru::render::settings::RenderSettings;
use seethru::render::simd::Isa;
use seethru::render::views::View;
use seethru::scene::Scene;
use seethru::scene::world::World;
use seethru::util::sampling::{hash_words, unit_float};
use std::path::Path;

/// das (absolute asset paths) and `extra`, written with `files` into `dir`.
fn das_with(dir: &Path, extra: &str, files: &[(&str, &str)]) -> std::path::PathBuf {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let das = std::fs::read_to_string(common::repo_path("scenes/das.toml")).unwrap();
    let das = das.replace("../assets", common::repo_path("assets").to_str().unwrap());
    common::scene_file_in(dir, "scene.toml", &format!("{das}{extra}"))
}

/// The car mesh placed along both sides of das's street, turned every which way, shrunk to
/// 0.9 by the object's own scale: near the pillar, in its shadow and far off.
const CARS: &str = "x,y,z,yaw_deg\n\
    -4.2,0,-9,0\n4.0,0,-12.5,180\n-4.4,0,-18,37.5\n3.9,0,-24,-90\n\
    -1.2,0,-31,12\n4.4,0,-40,270.25\n-4.3,0,-55,90\n2.5,0.01,-70,133\n";

fn instanced_cars() -> String {
    let car = common::repo_path("assets/car.obj");
    format!(
        "\n[[object]]\nname = \"parked\"\nkind = \"mesh\"\npath = \"{}\"\ninstances = \"cars.csv\"\nscale = [0.9, 0.9, 0.9]\nrotate_deg = [0.0, 90.0, 0.0]\n",
        car.display()
    )
}

fn instanced_das() -> (tempfile::TempDir, Scene) {
    let dir = tempfile::tempdir().unwrap();
    let path = das_with(dir.path(), &instanced_cars(), &[("cars.csv", CARS)]);
    let scene = Scene::load(&path).unwrap();
    (dir, scene)
}

/// The instanced world's context, and the same world flattened in a context of its own.
fn both_contexts(scene: Scene) -> (RenderContext, RenderContext) {
    let instanced = RenderContext::new(scene.clone()).unwrap();
    assert_eq!(instanced.world.instanced.len(), 1);
    let flattened = RenderContext::new(scene).unwrap().flattened().unwrap();
    assert!(flattened.world.instanced.is_empty());
    (instanced, flattened)
}

#[test]
fn an_instanced_world_renders_every_view_bit_identical_to_it_flattened() {
    let (_dir, scene) = instanced_das();
    let (instanced, flattened) = both_contexts(scene);
    let cars = instanced.world.instanced[0].len();
    assert_eq!(cars, 8 * instanced.world.instanced[0].triangles.len());
    assert!(cars > 80_000, "{cars}");
    for view in View::ALL {
        let camera = view.camera(&instanced.scene).with_resolution(96, 54);
        let job = || {
            RenderJob::new(&camera, view.bit())
                .settings(RenderSettings {
                    spp: 2,
                    progress: false,
                })
                .label("truth")
        };
        let (a, _) = instanced.render(job());
        let (b, _) = flattened.render(job());
        let bits = |f: &seethru::render::frame::Frame| -> Vec<u32> {
            f.color
                .iter()
                .flat_map(|c| c.to_array().map(f32::to_bits))
                .chain(f.depth.iter().map(|d| d.to_bits()))
                .chain(f.object_id.iter().copied())
                .chain(f.part_id.iter().copied())
                .collect()
        };
        assert!(bits(&a) == bits(&b), "{view:?}: the images differ");
        // The cars are in the picture (the object after das's own).
        let shown = a
            .object_id
            .iter()
            .filter(|&&id| {
                instanced
                    .scene
                    .objects
                    .get(id as usize - 1)
                    .is_some_and(|o| o.name == "parked")
            })
            .count();
        if view == View::Truth {
            assert!(shown > 50, "{view:?}: {shown} car pixels");
        }
    }
}

/// Rays from around the street in random directions, a third aimed at a car.
fn rays(n: u32) -> Vec<(Vec3, Vec3)> {
    let targets = [
        Vec3::new(-4.2, 0.7, -9.0),
        Vec3::new(4.0, 0.6, -12.5),
        Vec3::new(-1.2, 0.5, -31.0),
    ];
    (0..n)
        .map(|i| {
            let u = |k| unit_float(hash_words(&[i, k]));
            let origin = Vec3::new(-8.0 + 16.0 * u(1), 0.05 + 3.0 * u(2), 2.0 - 50.0 * u(3));
            let dir = if i % 3 == 0 {
                targets[i as usize % 3] + Vec3::new(u(7) - 0.5, u(8) - 0.5, u(9) - 0.5) * 3.0
                    - origin
            } else {
                let z = 2.0 * u(4) - 1.0;
                let a = std::f32::consts::TAU * u(5);
                let r = (1.0 - z * z).sqrt();
                Vec3::new(r * a.cos(), z, r * a.sin())
            };
            (origin, dir.normalize())
        })
        .collect()
}

#[test]
fn every_query_on_instances_equals_the_flattened_world_and_the_brute_force() {
    let (_dir, scene) = instanced_das();
    let (instanced, flattened) = both_contexts(scene);
    let view = seethru::scene::world::view_bit::TRUTH;
    let mut hit_cars = 0;
    let mut expected = Vec::new();
    for (i, (o, d)) in rays(3000).into_iter().enumerate() {
        let tmax = if i % 5 == 0 { 9.5 } else { f32::INFINITY };
        let ray = make_ray(o, d, 0.0, tmax);
        let got = instanced.accel.closest(&ray, view);
        let flat = flattened.accel.closest(&ray, view);
        let brute = closest_brute_force(&instanced.world, &ray, view);
        let bits = |h: Option<seethru::render::accel::Hit>| h.map(|h| (h.prim, h.t.to_bits()));
        assert_eq!(bits(got), bits(flat), "ray {i} ({o}, {d})");
        assert_eq!(bits(got), bits(brute), "ray {i} ({o}, {d})");
        if let Some(h) = got
            && h.prim >= instanced.world.triangles.len()
            && h.prim < instanced.world.ellipsoid_base()
        {
            hit_cars += 1;
        }
        let blocked = occluded_brute_force(&instanced.world, &ray, view);
        assert_eq!(instanced.accel.occluded(&ray, view), blocked, "ray {i}");
        assert_eq!(flattened.accel.occluded(&ray, view), blocked, "ray {i}");
        expected.push((ray, bits(brute), blocked));
    }
    assert!(hit_cars > 300, "{hit_cars} rays hit a car");
    // Packets of 16 on every instruction set this CPU has: lane by lane the same.
    let mut stack = PacketStack::new();
    for isa in Isa::ALL.into_iter().filter(|i| i.available()) {
        for chunk in expected.chunks(PACKET) {
            let mut packet = RayPacket::new();
            for (lane, (ray, _, _)) in chunk.iter().enumerate() {
                packet.set(lane, ray);
            }
            let mut closest = packet;
            instanced
                .accel
                .closest_packet(&mut closest, view, isa, &mut stack);
            let blocked = instanced
                .accel
                .occluded_packet(&packet, view, isa, &mut stack);
            for (lane, (_, hit, shadow)) in chunk.iter().enumerate() {
                let got = closest.hit(lane).map(|h| (h.prim, h.t.to_bits()));
                assert_eq!(got, *hit, "{isa:?} lane {lane}");
                assert_eq!(
                    blocked >> lane & 1 != 0,
                    *shadow,
                    "{isa:?} lane {lane} shadow"
                );
            }
        }
    }
}

#[test]
fn a_hundred_million_instanced_triangles_are_held_in_little_memory() {
    // 8 704 placements of the 11 504-triangle car: a grid of 68 × 128, 6 m apart.
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("x,y,z,yaw_deg\n");
    for row in 0..128 {
        for column in 0..68 {
            let x = -200.0 + 6.0 * column as f64;
            let z = -20.0 - 6.0 * row as f64;
            csv.push_str(&format!("{x},0,{z},{}\n", (row * 68 + column) % 360));
        }
    }
    let path = das_with(dir.path(), &instanced_cars(), &[("cars.csv", &csv)]);
    let scene = Scene::load(&path).unwrap();
    let world = World::build(&scene).unwrap();
    let instanced = world.instanced_count();
    assert!(instanced >= 100_000_000, "{instanced}");
    let accel = Accel::build(&world).unwrap();
    // The flattened world's hierarchy alone would take some 60 bytes a triangle (6 GB).
    assert!(accel.bytes() < 32 << 20, "{} bytes", accel.bytes());
    // And it answers: a ray down onto a car's roof and one between the cars.
    let roof = make_ray(Vec3::new(-200.0, 10.0, -20.0), -Vec3::Y, 0.0, f32::INFINITY);
    let hit = accel
        .closest(&roof, seethru::scene::world::view_bit::TRUTH)
        .unwrap();
    assert!(hit.prim >= world.triangles.len() && hit.prim < world.ellipsoid_base());
    assert!(hit.t > 8.0 && hit.t < 10.0, "{}", hit.t);
    let gap = make_ray(Vec3::new(-197.0, 10.0, -23.0), -Vec3::Y, 0.0, f32::INFINITY);
    let ground = accel
        .closest(&gap, seethru::scene::world::view_bit::TRUTH)
        .unwrap();
    assert!(ground.prim < world.triangles.len(), "{ground:?}");
}

#[test]
fn bad_placements_are_refused_in_one_line_naming_the_file_the_line_and_the_key() {
    let car = common::repo_path("assets/car.obj");
    let mesh = |extra: &str| {
        format!(
            "\n[[object]]\nname = \"parked\"\nkind = \"mesh\"\npath = \"{}\"\ninstances = \"cars.csv\"\n{extra}",
            car.display()
        )
    };
    let cases: [(String, &str, &[&str]); 6] = [
        (mesh(""), "1,2,3\n", &["cars.csv:1", "expected 4 values", "instances"]),
        (mesh(""), "0,0,-9,0\n0,0,x,0\n", &["cars.csv:2", "`z`", "[-1000000, 1000000]"]),
        (mesh(""), "x,y,z,yaw_deg\n", &["no placements"]),
        (mesh(""), "0,0,-9,0\n0,0,-999999,0\n", &["placement 1", "row 2", "outside the world"]),
        (
            "\n[[object]]\nname = \"b\"\nkind = \"box\"\nmaterial = \"street\"\ninstances = \"cars.csv\"\n"
                .to_string(),
            "0,0,-9,0\n",
            &["object[", "instances", "only a mesh object"],
        ),
        (
            mesh("moves_with = \"vehicle\"\n"),
            "0,0,-9,0\n",
            &["instances", "cannot move"],
        ),
    ];
    for (extra, csv, words) in cases {
        let dir = tempfile::tempdir().unwrap();
        das_with(dir.path(), &extra, &[("cars.csv", csv)]);
        let out = dir.path().join("out");
        let args = [
            "run",
            "scene.toml",
            "--width",
            "32",
            "--out",
            out.to_str().unwrap(),
        ];
        common::refusal::refused(dir.path(), &args, 1, words);
        assert!(!out.exists());
    }
}

/// A glTF of one box mesh (12 triangles) placed by four nodes: a parent moved and turned
/// with three children (one turned and stretched unevenly, one moved, one scaled to nothing,
/// as files hide a node), and a second root.
fn three_boxes_gltf() -> String {
    use base64::Engine;
    let c = |i: usize| -> [f32; 3] { [0, 1, 2].map(|a| if i >> a & 1 == 1 { 0.5 } else { -0.5 }) };
    let faces = [
        [0, 2, 6, 4],
        [1, 5, 7, 3],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 6, 7, 5],
    ];
    let mut bytes = Vec::new();
    for f in faces {
        for i in [f[0], f[1], f[2], f[0], f[2], f[3]] {
            bytes.extend(c(i).iter().flat_map(|v| v.to_le_bytes()));
        }
    }
    let uri = base64::engine::general_purpose::STANDARD.encode(&bytes);
    format!(
        r#"{{"asset": {{"version": "2.0"}},
  "buffers": [{{"byteLength": {n}, "uri": "data:application/octet-stream;base64,{uri}"}}],
  "bufferViews": [{{"buffer": 0, "byteLength": {n}}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 36, "type": "VEC3",
                  "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}}],
  "materials": [{{"name": "paint", "pbrMetallicRoughness": {{"baseColorFactor": [0.8, 0.3, 0.1, 1]}}}}],
  "meshes": [{{"name": "box", "primitives": [{{"attributes": {{"POSITION": 0}}, "material": 0}}]}}],
  "nodes": [
    {{"translation": [-2.0, 0.5, -9.0], "rotation": [0, 0.38268343, 0, 0.92387953], "children": [1, 2, 4]}},
    {{"mesh": 0, "rotation": [0.25881905, 0, 0, 0.96592583], "scale": [1.0, 2.0, 0.5]}},
    {{"mesh": 0, "translation": [1.5, 0.0, 0.0]}},
    {{"mesh": 0, "translation": [2.5, 0.75, -14.0], "scale": [1.5, 1.5, 1.5]}},
    {{"mesh": 0, "translation": [0.0, 1.0, 0.0], "scale": [0.0, 0.0, 0.0]}}
  ],
  "scenes": [{{"nodes": [0, 3]}}], "scene": 0}}"#,
        n = bytes.len()
    )
}

#[test]
fn a_gltf_mesh_that_several_nodes_place_is_instanced_and_traced_as_its_flattened_copies() {
    use seethru::scene::mesh_io::{load_mesh, load_mesh_sharing};
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("boxes.gltf"), three_boxes_gltf()).unwrap();
    let file = dir.path().join("boxes.gltf");
    // Loaded for the world: the mesh once, at the three nodes' placements; elsewhere flat.
    let shared = load_mesh_sharing(&file).unwrap();
    assert!(shared.tris.is_empty());
    assert_eq!(shared.shared.len(), 1);
    assert_eq!(shared.shared[0].file_from_mesh.len(), 4);
    let flat = load_mesh(&file).unwrap();
    assert!(flat.shared.is_empty());
    assert_eq!(flat.tris.len(), 48);
    // Both place the same corners (the node hierarchy composed either way), to f32 rounding.
    let corners = |tris: &[seethru::scene::shapes::Tri]| {
        let mut v: Vec<[i64; 3]> = tris
            .iter()
            .flat_map(|t| t.p)
            .map(|p| p.to_array().map(|c| (c as f64 * 1e4).round() as i64))
            .collect();
        v.sort();
        v
    };
    assert_eq!(corners(&shared.flat_tris()), corners(&flat.tris));
    // In a scene: one instanced set of the three placements that show something (the one
    // scaled to nothing is left out), traced as the world flattened.
    let extra = "\n[[object]]\nname = \"boxes\"\nkind = \"mesh\"\npath = \"boxes.gltf\"\n";
    let path = das_with(dir.path(), extra, &[]);
    let (instanced, flattened) = both_contexts(Scene::load(&path).unwrap());
    let set = &instanced.world.instanced[0];
    assert_eq!((set.triangles.len(), set.world_from_object.len()), (12, 3));
    for view in View::ALL {
        let camera = view.camera(&instanced.scene).with_resolution(96, 54);
        let job = || {
            RenderJob::new(&camera, view.bit()).settings(RenderSettings {
                spp: 1,
                progress: false,
            })
        };
        let (a, _) = instanced.render(job());
        let (b, _) = flattened.render(job());
        let bits = |f: &seethru::render::frame::Frame| -> Vec<u32> {
            f.color
                .iter()
                .flat_map(|c| c.to_array().map(f32::to_bits))
                .chain(f.object_id.iter().copied())
                .collect()
        };
        assert!(bits(&a) == bits(&b), "{view:?}: the images differ");
        let boxes = instanced.scene.objects.len() as u32; // the last object's id
        let shown = a.object_id.iter().filter(|&&id| id == boxes).count();
        if view == View::Truth {
            assert!(shown > 40, "{shown} pixels of the boxes");
        }
    }
}

/// A scene's fingerprint (what captures and datasets match scenes by) holds its placements:
/// the same scene text with one car moved 1 cm in its placements file differs; the same files
/// in another folder do not (das's keyframes once carried their file's path into it).
#[test]
fn the_fingerprint_holds_the_placements_and_not_the_folder() {
    use seethru::scene::fingerprint::fingerprint;
    let of = |csv: &str| {
        let dir = tempfile::tempdir().unwrap();
        let path = das_with(dir.path(), &instanced_cars(), &[("cars.csv", csv)]);
        fingerprint(&Scene::load(&path).unwrap()).unwrap()
    };
    let base = of(CARS);
    assert_eq!(base, of(CARS));
    assert_ne!(base, of(&CARS.replace("-4.2,0,-9,0", "-4.21,0,-9,0")));
}
