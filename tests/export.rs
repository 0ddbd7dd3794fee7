//! `export` writes the very scene the renderer traces, readable by other tools: glTF (re-read
//! with the `gltf` crate), OBJ (re-read with tobj) and Mitsuba 3 XML + PLY (parsed back).

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

use glam::{DVec2, DVec3, Mat4, Vec3};
use seethru::io::export::content::SPHERE_BANDS;
use seethru::io::export::{ExportFormat, export};
use seethru::render::sky::SkyModel;
use seethru::scene::mesh_io::load_mesh;
use seethru::scene::world::World;

/// The IEC 61966-2-1 sRGB decoding, written out here so that the test does not check the
/// code's conversion against itself.
fn srgb_decode(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

type Key = Vec<u32>;

fn key(t: &[Vec3; 3]) -> Key {
    t.iter()
        .flat_map(|v| v.to_array())
        .map(f32::to_bits)
        .collect()
}

/// The triangles the renderer traces, read from the world, and the ellipsoids' count.
fn traced(world: &World) -> (Vec<Key>, usize) {
    let mut keys: Vec<Key> = world
        .triangles
        .iter()
        .map(|t| {
            let v0 = Vec3::from(t.v0);
            key(&[v0, v0 - Vec3::from(t.e1), v0 + Vec3::from(t.e2)])
        })
        .collect();
    keys.sort_unstable();
    (keys, world.ellipsoids.len())
}

/// Checks that `loaded` holds exactly the traced triangles plus one tessellation per
/// ellipsoid whose vertices lie on the analytic surface.
fn assert_traced(world: &World, loaded: &[[Vec3; 3]], what: &str) {
    let (expected, ellipsoids) = traced(world);
    let (lat, lon) = SPHERE_BANDS;
    let per_sphere = 2 * lat * lon - 2 * lon;
    assert_eq!(
        loaded.len(),
        expected.len() + ellipsoids * per_sphere,
        "{what}: triangle count"
    );
    let on_an_ellipsoid = |v: Vec3| {
        world.ellipsoids.iter().any(|e| {
            // f32 positions: 1e-7 m of rounding is 1e-5 of the eyes' 11 mm radius.
            (e.object_from_world.transform_point3(v).length() - 1.0).abs() < 1e-4
        })
    };
    let mut flat = Vec::new();
    let mut sphere_tris = 0;
    for t in loaded {
        let k = key(t);
        if expected.binary_search(&k).is_ok() {
            flat.push(k);
        } else {
            assert!(
                t.iter().all(|v| on_an_ellipsoid(*v)),
                "{what}: a triangle neither traced nor on a sphere: {t:?}"
            );
            sphere_tris += 1;
        }
    }
    flat.sort_unstable();
    assert!(flat == expected, "{what}: the traced triangles differ");
    assert_eq!(sphere_tris, ellipsoids * per_sphere, "{what}");
}

#[test]
fn obj_and_glb_exports_reload_to_the_traced_triangles() {
    // Textures: an export of das's textured street reloads, as OBJ (`map_Kd` and a PNG beside
    // it) or GLB (an embedded PNG), with the street's texels, bit for bit.
    let textured = common::das();
    let dir = tempfile::tempdir().unwrap();
    let world = World::build(&textured).unwrap();
    for name in ["das.obj", "das.glb"] {
        let path = dir.path().join(name);
        export(&textured, &world, &path, None).unwrap();
        let loaded = load_mesh(&path).unwrap();
        let street = loaded
            .materials
            .iter()
            .find(|m| m.name.ends_with("street"))
            .expect("the street's material");
        let texture = &loaded.textures[street.texture.expect("its texture")];
        let original = &world.textures[0];
        assert_eq!(
            (texture.width, texture.height),
            (original.width, original.height)
        );
        assert!(
            texture.texels == original.texels,
            "{name}: the street's texels changed"
        );
    }
    let mut scene = common::das();
    for m in &mut scene.materials {
        m.texture = None;
    }
    let world = World::build(&scene).unwrap();
    assert!(
        !world.ellipsoids.is_empty(),
        "das has spheres to tessellate"
    );
    let dir = tempfile::tempdir().unwrap();
    for name in ["das.obj", "das.glb"] {
        let path = dir.path().join(name);
        let exported = export(&scene, &world, &path, None).unwrap();
        let loaded = load_mesh(&path).unwrap();
        assert_eq!(exported.triangles, loaded.tris.len(), "{name}");
        let tris: Vec<[Vec3; 3]> = loaded.tris.iter().map(|t| t.p).collect();
        assert_traced(&world, &tris, name);
        let cameras: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(path.with_extension("cameras.json")).unwrap(),
        )
        .unwrap();
        let eye: Vec<f64> = serde_json::from_value(cameras["driver"]["position"].clone()).unwrap();
        assert_eq!(eye, scene.eye().to_array());
    }
}

fn extras(e: &gltf::json::Extras) -> serde_json::Value {
    serde_json::from_str(e.as_ref().expect("extras").get()).unwrap()
}

/// Pixel coordinates of a world point through a glTF perspective camera (looking down −z of
/// its node, +y up, image y downwards), computed from the glTF data alone.
fn gltf_project(node: &Mat4, yfov: f64, aspect: f64, size: (u32, u32), p: DVec3) -> DVec2 {
    let q = node.inverse().as_dmat4().transform_point3(p);
    let t = (yfov / 2.0).tan();
    let ndc = DVec2::new(q.x / -q.z / (aspect * t), q.y / -q.z / t);
    DVec2::new(
        (ndc.x + 1.0) / 2.0 * size.0 as f64,
        (1.0 - ndc.y) / 2.0 * size.1 as f64,
    )
}

/// das exported to `<temp dir>/<name>` in `format` (None: by the extension).
struct Exported {
    scene: seethru::scene::Scene,
    world: World,
    dir: tempfile::TempDir,
    path: std::path::PathBuf,
}

fn export_das(name: &str, format: Option<ExportFormat>) -> Exported {
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    export(&scene, &world, &path, format).unwrap();
    Exported {
        scene,
        world,
        dir,
        path,
    }
}

#[test]
fn gltf_export_has_the_cameras_materials_display_and_ids() {
    let Exported {
        scene,
        path,
        dir: _dir,
        ..
    } = export_das("das.glb", Some(ExportFormat::Gltf));
    let (doc, buffers, images) = gltf::import(&path).unwrap();
    let nodes: BTreeMap<String, gltf::Node> = doc
        .nodes()
        .map(|n| (n.name().unwrap().to_string(), n))
        .collect();

    // The three cameras: field of view, aspect, and the pose (checked by projecting points).
    let probes = [
        scene.obstacle.display_corners().to_vec(),
        // The ball, the cube, a tree, the head and an eye of das.toml.
        vec![
            DVec3::new(-0.9, 0.35, -5.5),
            DVec3::new(-2.6, 0.5, -19.0),
            DVec3::new(6.5, 2.0, -9.0),
            DVec3::new(1.4, 1.17, 0.1),
            DVec3::new(1.368, 1.2, 0.0),
        ],
    ]
    .concat();
    for (name, cam) in [
        ("driver", &scene.driver),
        ("frontal", &scene.frontal),
        ("back", &scene.back),
    ] {
        let node = &nodes[name];
        let camera = node.camera().unwrap();
        let gltf::camera::Projection::Perspective(p) = camera.projection() else {
            panic!("{name}: not a perspective camera");
        };
        let yfov = 2.0 * (cam.half_angle_x.tan() * cam.height as f64 / cam.width as f64).atan();
        let aspect = cam.width as f64 / cam.height as f64;
        assert!((p.yfov() as f64 - yfov).abs() < 1e-6, "{name}: yfov");
        assert!(
            (p.aspect_ratio().unwrap() as f64 - aspect).abs() < 1e-6,
            "{name}: aspect"
        );
        let m = Mat4::from_cols_array_2d(&node.transform().matrix());
        let mut projected = 0;
        for &probe in &probes {
            let size = DVec2::new(cam.width as f64, cam.height as f64);
            let in_view = |p: &DVec2| p.cmpge(DVec2::ZERO).all() && p.cmple(size).all();
            if let Some(expected) = cam.project_point(probe).filter(in_view) {
                let got = gltf_project(
                    &m,
                    p.yfov() as f64,
                    p.aspect_ratio().unwrap() as f64,
                    (cam.width, cam.height),
                    probe,
                );
                assert!(
                    (got - expected).length() < 2e-3,
                    "{name}: {probe} projects to {got}, seethru says {expected}"
                );
                projected += 1;
            }
        }
        assert!(projected >= 2, "{name}: too few probes in view");
        assert_eq!(
            extras(node.extras())["resolution"],
            serde_json::json!([cam.width, cam.height])
        );
    }

    // Every material of the scene file, its colour decoded to linear; the car's own.
    let materials: BTreeMap<&str, gltf::Material> =
        doc.materials().map(|m| (m.name().unwrap(), m)).collect();
    for m in &scene.materials {
        let got = materials[m.name.as_str()].pbr_metallic_roughness();
        let c = got.base_color_factor();
        for k in 0..3 {
            assert!(
                (c[k] as f64 - srgb_decode(m.color[k])).abs() < 1e-6,
                "{}: baseColorFactor {c:?} for sRGB {:?}",
                m.name,
                m.color
            );
        }
        assert_eq!(got.base_color_texture().is_some(), m.texture.is_some());
        if let Some(info) = got.base_color_texture() {
            let image = &images[info.texture().source().index()];
            let png = image::open(m.texture.as_ref().unwrap()).unwrap().to_rgb8();
            assert_eq!((image.width, image.height), png.dimensions());
            assert!(
                image.pixels == png.into_raw(),
                "{}: texture differs",
                m.name
            );
        }
    }
    let body = materials["car.body"]
        .pbr_metallic_roughness()
        .base_color_factor();
    assert_eq!(&body[..3], &[0.55, 0.04, 0.03], "car.mtl's linear Kd");
    for m in ["obstacle_body", "display"] {
        assert!(materials.contains_key(m), "{m}");
    }

    // The street's UVs carry uv_repeat: v runs over 25 texture periods.
    let street = nodes["street"].mesh().unwrap();
    let prim = street.primitives().next().unwrap();
    let reader = prim.reader(|b| Some(&buffers[b.index()]));
    let vmax = reader
        .read_tex_coords(0)
        .unwrap()
        .into_f32()
        .map(|t| t[1])
        .fold(f32::MIN, f32::max);
    assert_eq!(vmax, 25.0);

    // Ids and visibility as the scene file says; the obstacle last.
    for (i, object) in scene.objects.iter().enumerate() {
        let e = extras(nodes[object.name.as_str()].extras());
        assert_eq!(e["seethru_id"], i + 1, "{}", object.name);
        let hidden: Vec<&str> = ["driver", "frontal", "back"]
            .into_iter()
            .enumerate()
            .filter(|(bit, _)| object.visible_to & (1 << bit) == 0)
            .map(|(_, n)| n)
            .collect();
        assert_eq!(
            e["hidden_from"],
            serde_json::json!(hidden),
            "{}",
            object.name
        );
    }
    assert_eq!(
        extras(nodes["head"].extras())["hidden_from"],
        serde_json::json!(["driver"])
    );
    let obstacle = extras(nodes["obstacle"].extras());
    assert_eq!(obstacle["seethru_id"], scene.objects.len() + 1);
    assert_eq!(
        obstacle["hidden_from"],
        serde_json::json!(["frontal", "back"])
    );

    // The display: a named child of the obstacle, spanning the display rectangle, UV (0, 0)
    // at its top-left corner and (1, 1) at its bottom-right.
    let display = &nodes["display"];
    assert!(
        nodes["obstacle"]
            .children()
            .any(|c| c.index() == display.index())
    );
    let e = extras(display.extras());
    assert_eq!(e["seethru_id"], scene.objects.len() + 1);
    assert_eq!(e["display"]["width_m"], scene.obstacle.width);
    let prim = display.mesh().unwrap().primitives().next().unwrap();
    assert_eq!(materials["display"].index(), prim.material().index());
    let reader = prim.reader(|b| Some(&buffers[b.index()]));
    let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    let uvs: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
    let [tl, _, br, _] = scene.obstacle.display_corners();
    for (corner, uv) in [(tl, [0.0, 0.0]), (br, [1.0, 1.0])] {
        let i = positions
            .iter()
            .position(|p| (DVec3::from_array(p.map(f64::from)) - corner).length() < 1e-5)
            .unwrap_or_else(|| panic!("no display vertex at {corner}"));
        assert_eq!(uvs[i], uv);
    }

    // Normals agree with the winding (a viewer flips a back face's normal by its winding).
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            let r = prim.reader(|b| Some(&buffers[b.index()]));
            let p: Vec<Vec3> = r.read_positions().unwrap().map(Vec3::from_array).collect();
            let n: Vec<Vec3> = r.read_normals().unwrap().map(Vec3::from_array).collect();
            let idx: Vec<u32> = r.read_indices().unwrap().into_u32().collect();
            for t in idx.chunks_exact(3) {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
                let face = (p[b] - p[a]).cross(p[c] - p[a]).normalize();
                for v in [a, b, c] {
                    assert!(
                        face.dot(n[v]) > 0.5,
                        "{}: normal {} against face {face}",
                        mesh.name().unwrap(),
                        n[v]
                    );
                }
            }
        }
    }

    // The sun shines along −direction.
    let sun = &nodes["sun"];
    assert!(matches!(
        sun.light().unwrap().kind(),
        gltf::khr_lights_punctual::Kind::Directional
    ));
    let m = Mat4::from_cols_array_2d(&sun.transform().matrix()).as_dmat4();
    let shines = m.transform_vector3(-DVec3::Z);
    assert!((shines + scene.sun.direction).length() < 1e-6);
}

/// The triangles of a binary little-endian PLY as written by the Mitsuba export (x y z nx ny
/// nz u v floats, uchar-counted int faces).
fn read_ply(path: &Path) -> Vec<[Vec3; 3]> {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).unwrap();
    let count = |element: &str| -> usize {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("element {element} ")))
            .unwrap()
            .parse()
            .unwrap()
    };
    let (nv, nf) = (count("vertex"), count("face"));
    let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let vertices: Vec<Vec3> = (0..nv)
        .map(|i| {
            let o = end + 32 * i;
            Vec3::new(f32_at(o), f32_at(o + 4), f32_at(o + 8))
        })
        .collect();
    let faces = end + 32 * nv;
    assert_eq!(bytes.len(), faces + 13 * nf, "{}: size", path.display());
    (0..nf)
        .map(|i| {
            let o = faces + 13 * i;
            assert_eq!(bytes[o], 3);
            let index = |k: usize| {
                i32::from_le_bytes(bytes[o + 1 + 4 * k..o + 5 + 4 * k].try_into().unwrap()) as usize
            };
            [vertices[index(0)], vertices[index(1)], vertices[index(2)]]
        })
        .collect()
}

fn triple(text: &str) -> DVec3 {
    let v: Vec<f64> = text.split(',').map(|s| s.trim().parse().unwrap()).collect();
    DVec3::new(v[0], v[1], v[2])
}

#[test]
fn mitsuba_export_has_three_sensors_with_the_exact_field_of_view() {
    let Exported {
        scene,
        world,
        dir,
        path,
    } = export_das("das.xml", None);

    let read = |file: &Path| std::fs::read_to_string(file).unwrap();
    let text = read(&path);
    let doc = roxmltree::Document::parse(&text).unwrap();
    let child = |n: roxmltree::Node, tag: &str, name: &str| {
        n.descendants()
            .find(|c| c.has_tag_name(tag) && c.attribute("name") == Some(name))
            .unwrap_or_else(|| panic!("no <{tag} name=\"{name}\">"))
            .attribute("value")
            .unwrap()
            .to_string()
    };
    let sensors: Vec<roxmltree::Node> = doc
        .descendants()
        .filter(|n| n.has_tag_name("sensor"))
        .collect();
    let ids: Vec<&str> = sensors.iter().map(|s| s.attribute("id").unwrap()).collect();
    assert_eq!(ids, ["driver", "frontal", "back"]);
    for (sensor, cam) in sensors
        .iter()
        .zip([&scene.driver, &scene.frontal, &scene.back])
    {
        assert_eq!(sensor.attribute("type"), Some("perspective"));
        assert_eq!(child(*sensor, "string", "fov_axis"), "x");
        let fov: f64 = child(*sensor, "float", "fov").parse().unwrap();
        assert_eq!(
            fov,
            2.0 * cam.half_angle_x.to_degrees(),
            "full horizontal angle"
        );
        assert_eq!(child(*sensor, "integer", "width"), cam.width.to_string());
        assert_eq!(child(*sensor, "integer", "height"), cam.height.to_string());
        let lookat = sensor
            .descendants()
            .find(|n| n.has_tag_name("lookat"))
            .unwrap();
        let origin = triple(lookat.attribute("origin").unwrap());
        let target = triple(lookat.attribute("target").unwrap());
        let up = triple(lookat.attribute("up").unwrap());
        assert!((origin - cam.position()).length() < 1e-12);
        assert!((target - origin).normalize().dot(cam.forward()) > 1.0 - 1e-12);
        assert!(up.dot(cam.world_from_camera.matrix3.y_axis) > 1.0 - 1e-12);
    }

    // The sun: light travels along −direction with π × seethru's irradiance.
    let sun = doc
        .descendants()
        .find(|n| n.attribute("type") == Some("directional"))
        .unwrap();
    assert!((triple(&child(sun, "vector", "direction")) + scene.sun.direction).length() < 1e-6);
    let irradiance = triple(&child(sun, "rgb", "irradiance"));
    for k in 0..3 {
        let expected = std::f64::consts::PI * srgb_decode(scene.sun.color[k]) * scene.sun.intensity;
        assert!((irradiance[k] - expected).abs() < 1e-5 * expected);
    }

    // Every file a scene names exists; every referenced material is defined.
    let bsdfs: BTreeSet<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("bsdf"))
        .filter_map(|n| n.attribute("id"))
        .collect();
    for n in doc.descendants() {
        if n.attribute("name") == Some("filename") {
            assert!(dir.path().join(n.attribute("value").unwrap()).is_file());
        }
        if n.has_tag_name("ref") {
            assert!(bsdfs.contains(n.attribute("id").unwrap()));
        }
    }

    // The PLY meshes hold exactly the exported triangles.
    let mut plys: Vec<[Vec3; 3]> = Vec::new();
    for shape in doc.descendants().filter(|n| n.has_tag_name("shape")) {
        plys.extend(read_ply(
            &dir.path().join(child(shape, "string", "filename")),
        ));
    }
    assert_traced(&world, &plys, "ply");

    // Each view's file has its camera and exactly the objects seethru shows in that view.
    let shape_objects = |file: &Path| -> BTreeSet<String> {
        let text = read(file);
        let doc = roxmltree::Document::parse(&text).unwrap();
        doc.descendants()
            .filter(|n| n.has_tag_name("shape"))
            .map(|n| {
                n.attribute("id")
                    .unwrap()
                    .split("_m")
                    .next()
                    .unwrap()
                    .to_string()
            })
            .collect()
    };
    let object_key = |id: usize, name: &str| format!("o{id}_{name}");
    let obstacle = scene.objects.len() + 1;
    for (view, camera_bit, with_obstacle) in [
        ("truth", 0, false),
        ("occluded", 0, true),
        ("frontal", 1, false),
        ("back", 2, false),
    ] {
        let mut expected: BTreeSet<String> = scene
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.visible_to & (1 << camera_bit) != 0)
            .map(|(i, o)| object_key(i + 1, &o.name))
            .collect();
        if with_obstacle {
            expected.insert(object_key(obstacle, "obstacle"));
            expected.insert(object_key(obstacle, "display"));
        }
        let file = dir.path().join(format!("das.{view}.xml"));
        assert_eq!(shape_objects(&file), expected, "{view}");
        let text = read(&file);
        let doc = roxmltree::Document::parse(&text).unwrap();
        let sensor = doc
            .descendants()
            .find(|n| n.has_tag_name("sensor"))
            .unwrap();
        assert_eq!(
            sensor.attribute("id"),
            Some(["driver", "frontal", "back"][camera_bit])
        );
    }
    assert!(shape_objects(&path).contains(&object_key(8, "head")));
}

/// The Mitsuba sky stands for seethru's ambient term: an environment of uniform radiance
/// `up` above the horizon and `down` below gives a Lambertian surface the irradiance π ×
/// ambient(n) — checked by integrating the environment over the sphere.
#[test]
fn two_hemispheres_light_a_surface_as_seethrus_ambient() {
    let scene = common::das();
    let sky = SkyModel::new(&scene.sky, &scene.sun, scene.photometry.as_ref());
    let (up, down) = (sky.ambient(Vec3::Y), sky.ambient(-Vec3::Y));
    assert!(
        (up - down).length() > 0.1,
        "the test needs distinct hemispheres"
    );
    let (n_theta, n_phi) = (400, 800);
    for normal in [
        Vec3::Y,
        -Vec3::Y,
        Vec3::X,
        Vec3::new(0.3, 0.8, -0.2).normalize(),
        Vec3::new(-0.5, -0.4, 0.6).normalize(),
    ] {
        let mut irradiance = glam::DVec3::ZERO;
        for i in 0..n_theta {
            let theta = std::f64::consts::PI * (i as f64 + 0.5) / n_theta as f64;
            for j in 0..n_phi {
                let phi = std::f64::consts::TAU * (j as f64 + 0.5) / n_phi as f64;
                let w = DVec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                let cos = w.dot(normal.as_dvec3());
                if cos > 0.0 {
                    let radiance = if w.y > 0.0 { up } else { down };
                    let d_omega = theta.sin()
                        * (std::f64::consts::PI / n_theta as f64)
                        * (std::f64::consts::TAU / n_phi as f64);
                    irradiance += radiance.as_dvec3() * cos * d_omega;
                }
            }
        }
        let expected = sky.ambient(normal).as_dvec3() * std::f64::consts::PI;
        assert!(
            (irradiance - expected).length() < 2e-3 * expected.length(),
            "n = {normal}: {irradiance} vs π·ambient {expected}"
        );
    }
}

#[test]
fn obj_export_has_linear_colours_in_its_material_library() {
    let Exported {
        scene, dir, path, ..
    } = export_das("das.obj", Some(ExportFormat::Obj));
    let (_, materials) = tobj::load_obj(&path, &tobj::GPU_LOAD_OPTIONS).unwrap();
    let materials = materials.unwrap();
    for m in &scene.materials {
        let got = materials
            .iter()
            .find(|g| g.name.ends_with(&format!("_{}", m.name)))
            .unwrap_or_else(|| panic!("no material {}", m.name));
        for (kd, srgb) in got.diffuse.unwrap().iter().zip(m.color) {
            assert!((*kd as f64 - srgb_decode(srgb)).abs() < 1e-6, "{}", m.name);
        }
        assert_eq!(got.diffuse_texture.is_some(), m.texture.is_some());
        if let Some(original) = &m.texture {
            let texture = dir.path().join(got.diffuse_texture.as_ref().unwrap());
            let written = image::open(texture).unwrap().to_rgb8();
            let original = image::open(original).unwrap().to_rgb8();
            assert!(written == original, "{}: texture", m.name);
        }
    }
}

fn seethru(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_seethru"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn the_format_and_the_file_name_must_agree() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    for (format, name, expected) in [
        (
            "mitsuba",
            "das.glb",
            "error: --format mitsuba writes a .xml file, but --out is ",
        ),
        (
            "gltf",
            "das",
            "error: --format gltf writes a .glb file, but --out is ",
        ),
        (
            "",
            "das.stl",
            "error: export writes .obj or .glb (glTF) or .xml (Mitsuba) files, not ",
        ),
    ] {
        let file = out(name);
        let mut args = vec!["export", "scenes/das.toml", "--out", &file];
        if !format.is_empty() {
            args.extend(["--format", format]);
        }
        let (ok, err) = seethru(&args);
        assert!(!ok && err.starts_with(expected), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "output left behind"
        );
    }
    // A folder that does not exist yet is made.
    let file = out("new/scene.obj");
    let (ok, err) = seethru(&[
        "export",
        "scenes/das.toml",
        "--out",
        &file,
        "--format",
        "obj",
    ]);
    assert!(ok, "{err}");
    assert!(dir.path().join("new/scene.mtl").is_file());
}

#[test]
fn lamps_export_as_mitsuba_emitters_and_gltf_lights_of_their_intensity() {
    // das_night's lamps, white 10 cd/m²: a Lambertian surface of albedo ρ at d, θ gets
    // ρ/π · I·cos θ/d² cd/m² from a lamp of I cd, so a physical renderer in units of the
    // white needs a radiant intensity of I / white (per channel, for a white lamp; a colour
    // is scaled so its luminance is I).
    let path = common::repo_path("scenes/das_night.toml");
    let scene = seethru::scene::Scene::load(&path).unwrap();
    let white = scene.photometry.as_ref().unwrap().white_cd_m2;
    let dir = tempfile::tempdir().unwrap();
    let world = World::build(&scene).unwrap();
    let xml = dir.path().join("night.xml");
    export(&scene, &world, &xml, Some(ExportFormat::Mitsuba)).unwrap();
    let text = std::fs::read_to_string(&xml).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let emitters: Vec<roxmltree::Node> = doc
        .descendants()
        .filter(|n| {
            n.has_tag_name("emitter") && matches!(n.attribute("type"), Some("point" | "spot"))
        })
        .collect();
    assert_eq!(emitters.len(), scene.lights.len());
    let value = |n: roxmltree::Node, tag: &str, name: &str| -> String {
        n.descendants()
            .find(|c| c.has_tag_name(tag) && c.attribute("name") == Some(name))
            .unwrap()
            .attribute("value")
            .unwrap()
            .to_string()
    };
    let luminance = |v: DVec3| 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
    for (lamp, e) in scene.lights.iter().zip(&emitters) {
        let intensity = triple(&value(*e, "rgb", "intensity"));
        assert!(
            (luminance(intensity) / (lamp.intensity_cd / white) - 1.0).abs() < 1e-5,
            "{}: {intensity}",
            lamp.name
        );
        match &lamp.spot {
            None => {
                assert_eq!(e.attribute("type"), Some("point"));
                let p = e.descendants().find(|n| n.has_tag_name("point")).unwrap();
                let at: Vec<f64> = ["x", "y", "z"]
                    .map(|k| p.attribute(k).unwrap().parse().unwrap())
                    .to_vec();
                assert_eq!(DVec3::from_slice(&at), lamp.position);
            }
            Some(spot) => {
                assert_eq!(e.attribute("type"), Some("spot"));
                let cone: f64 = value(*e, "float", "cutoff_angle").parse().unwrap();
                let beam: f64 = value(*e, "float", "beam_width").parse().unwrap();
                assert!((cone.to_radians().cos() - spot.cos_cone).abs() < 1e-9);
                assert!((beam.to_radians().cos() - spot.cos_falloff).abs() < 1e-9);
                let lookat = e.descendants().find(|n| n.has_tag_name("lookat")).unwrap();
                let (origin, target) = (
                    triple(lookat.attribute("origin").unwrap()),
                    triple(lookat.attribute("target").unwrap()),
                );
                assert!((origin - lamp.position).length() < 1e-9);
                assert!(((target - origin).normalize() - spot.direction).length() < 1e-9);
            }
        }
    }
    // What Mitsuba cannot state is said beside the emitter.
    assert!(text.contains("cut-off line (cutoff_deg) is not exported"));
    // glTF: a light per lamp after the sun, the spots' cones in radians.
    let glb = dir.path().join("night.glb");
    export(&scene, &world, &glb, Some(ExportFormat::Gltf)).unwrap();
    let gltf = gltf::Gltf::open(&glb).unwrap();
    let lights: Vec<_> = gltf.document.lights().unwrap().collect();
    assert_eq!(lights.len(), 1 + scene.lights.len());
    for (lamp, light) in scene.lights.iter().zip(&lights[1..]) {
        let c = light.color().map(f64::from);
        let radiant = DVec3::from(c) * f64::from(light.intensity());
        assert!((luminance(radiant) / (lamp.intensity_cd / white) - 1.0).abs() < 1e-5);
        if let (
            Some(spot),
            gltf::khr_lights_punctual::Kind::Spot {
                outer_cone_angle, ..
            },
        ) = (&lamp.spot, light.kind())
        {
            assert!((f64::from(outer_cone_angle).cos() - spot.cos_cone).abs() < 1e-6);
        }
    }
}

/// A GLB's JSON chunk as written (the gltf crate drops extensions it does not model): after
/// the 12-byte header, the chunk's length and type.
fn glb_json(path: &Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    serde_json::from_slice(&bytes[20..20 + length]).unwrap()
}

/// The `bsdf` elements directly inside `n`.
fn child_bsdfs<'a, 'input>(n: roxmltree::Node<'a, 'input>) -> Vec<roxmltree::Node<'a, 'input>> {
    n.children().filter(|c| c.has_tag_name("bsdf")).collect()
}

#[test]
fn glossy_materials_export_as_a_coat_of_their_f0_and_roughness_in_every_format() {
    // left_turn_night's wet streets (F0 0.02, α 0.15) beside Lambertian materials: Mitsuba's
    // blend of a diffuse and a rough conductor, glTF's metallic-roughness with an index of
    // refraction and OBJ's Blinn–Phong each state the same lobe; the Lambertian ones stay
    // diffuse.
    let path = common::repo_path("scenes/left_turn_night.toml");
    let mut scene = seethru::scene::Scene::load(&path).unwrap();
    // Two untextured coats besides: a bright yellow one (its diffuse part near 1) and paint.
    for (name, f0) in [("cyclist", 0.04), ("paint", 0.5)] {
        let m = scene.materials.iter_mut().find(|m| m.name == name).unwrap();
        (m.specular, m.roughness) = (f0, 0.3);
    }
    let world = World::build(&scene).unwrap();
    let glossy: Vec<_> = (scene.materials.iter())
        .filter(|m| m.specular > 0.0)
        .collect();
    assert!(glossy.len() >= 4 && glossy.len() < scene.materials.len());
    let f0_of_ior = |n: f64| ((n - 1.0) / (n + 1.0)).powi(2);
    let dir = tempfile::tempdir().unwrap();

    let xml = dir.path().join("wet.xml");
    export(&scene, &world, &xml, Some(ExportFormat::Mitsuba)).unwrap();
    let text = std::fs::read_to_string(&xml).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let value_of = |n: roxmltree::Node, name: &str| -> String {
        let c = (n.children())
            .find(|c| c.attribute("name") == Some(name))
            .unwrap_or_else(|| panic!("no {name} in {:?}", n.attribute("type")));
        c.attribute("value").unwrap().to_string()
    };
    let number = |n: roxmltree::Node, name: &str| -> f64 { value_of(n, name).parse().unwrap() };
    for (i, m) in scene.materials.iter().enumerate() {
        let outer = (doc.descendants())
            .find(|n| {
                n.has_tag_name("bsdf")
                    && n.attribute("id")
                        .is_some_and(|id| id.ends_with(&format!("_{}", m.name)))
            })
            .unwrap_or_else(|| panic!("no bsdf for {}", m.name));
        let inner = child_bsdfs(outer)[0];
        let albedo = world.materials[i].albedo.as_dvec3();
        if m.specular > 0.0 {
            // (1 − w) × diffuse(ρ') + w × conductor(s): ρ'(1 − w) = (1 − F0) ρ, w s = 1, the
            // conductor's index that of the coat (k = 0: a dielectric's Fresnel), its α.
            assert_eq!(inner.attribute("type"), Some("blendbsdf"), "{}", m.name);
            let w = number(inner, "weight");
            let [diffuse, coat] = child_bsdfs(inner)[..] else {
                panic!("{}", m.name)
            };
            assert_eq!(diffuse.attribute("type"), Some("diffuse"));
            assert_eq!(coat.attribute("type"), Some("roughconductor"));
            assert_eq!(value_of(coat, "distribution"), "ggx");
            assert!(
                (number(coat, "alpha") - m.roughness).abs() < 1e-6,
                "{}",
                m.name
            );
            assert!((w * number(coat, "specular_reflectance") - 1.0).abs() < 1e-5);
            let eta = triple(&value_of(coat, "eta"));
            assert_eq!(triple(&value_of(coat, "k")), DVec3::ZERO);
            let f0 = f0_of_ior(eta.x);
            assert!(
                eta.x == eta.y && eta.y == eta.z && (f0 - m.specular).abs() < 1e-6,
                "{f0}"
            );
            if m.texture.is_none() {
                let rho = triple(&value_of(diffuse, "reflectance"));
                assert!(rho.max_element() <= 1.0, "{}: {rho}", m.name);
                let want = albedo * (1.0 - m.specular);
                assert!(
                    (rho * (1.0 - w) - want).length() < 1e-5,
                    "{}: {rho}",
                    m.name
                );
            }
        } else {
            assert_eq!(inner.attribute("type"), Some("diffuse"), "{}", m.name);
            if m.texture.is_none() {
                let rho = triple(&value_of(inner, "reflectance"));
                assert!((rho - albedo).length() < 1e-6, "{}: {rho}", m.name);
            }
        }
    }

    let glb = dir.path().join("wet.glb");
    export(&scene, &world, &glb, Some(ExportFormat::Gltf)).unwrap();
    let json = glb_json(&glb);
    for m in &scene.materials {
        let got = (json["materials"].as_array().unwrap().iter())
            .find(|g| g["name"] == m.name.as_str())
            .unwrap_or_else(|| panic!("no glTF material {}", m.name));
        let pbr = &got["pbrMetallicRoughness"];
        assert_eq!(pbr["metallicFactor"].as_f64(), Some(0.0));
        let ext = &got["extensions"];
        let specular = ext["KHR_materials_specular"]["specularFactor"]
            .as_f64()
            .unwrap();
        if m.specular > 0.0 {
            let alpha = pbr["roughnessFactor"].as_f64().unwrap().powi(2);
            assert!((alpha - m.roughness).abs() < 1e-6, "{}: α {alpha}", m.name);
            let f0 = f0_of_ior(ext["KHR_materials_ior"]["ior"].as_f64().unwrap());
            assert!(
                (f0 - m.specular).abs() < 1e-6 && specular == 1.0,
                "{}",
                m.name
            );
        } else {
            assert!(
                specular == 0.0 && ext.get("KHR_materials_ior").is_none(),
                "{}",
                m.name
            );
        }
    }
    let used = json["extensionsUsed"].to_string();
    assert!(used.contains("KHR_materials_ior"), "{used}");
    // A Lambertian scene does not use it.
    let das = export_das("das.glb", Some(ExportFormat::Gltf));
    let json = glb_json(&das.path);
    assert!(
        !json["extensionsUsed"]
            .to_string()
            .contains("KHR_materials_ior")
    );

    let obj = dir.path().join("wet.obj");
    export(&scene, &world, &obj, Some(ExportFormat::Obj)).unwrap();
    let (_, materials) = tobj::load_obj(&obj, &tobj::GPU_LOAD_OPTIONS).unwrap();
    for m in &scene.materials {
        let got = (materials.as_ref().unwrap().iter())
            .find(|g| g.name.ends_with(&format!("_{}", m.name)))
            .unwrap_or_else(|| panic!("no OBJ material {}", m.name));
        let ks = got.specular.unwrap();
        // Blinn–Phong adds the two: the diffuse part is (1 − F0) ρ, as seethru's.
        let kd = DVec3::from_array(got.diffuse.unwrap().map(f64::from));
        let rho = world.materials[scene
            .materials
            .iter()
            .position(|x| x.name == m.name)
            .unwrap()]
        .albedo
        .as_dvec3();
        assert!(
            (kd - rho * (1.0 - m.specular)).length() < 1e-6,
            "{}: Kd {kd}",
            m.name
        );
        if m.specular > 0.0 {
            let ns = f64::from(got.shininess.unwrap());
            let alpha = (2.0 / (ns + 2.0)).sqrt();
            assert!((alpha - m.roughness).abs() < 1e-5, "{}: α {alpha}", m.name);
            assert!(
                ks.iter().all(|&k| (f64::from(k) - m.specular).abs() < 1e-6),
                "{}",
                m.name
            );
            assert_eq!(got.illumination_model, Some(2));
        } else {
            assert_eq!(ks, [0.0; 3], "{}", m.name);
        }
    }
}
