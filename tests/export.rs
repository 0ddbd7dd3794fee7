//! `export` writes the very triangles the renderer traces, readable by other tools.

mod common;

use seethru::io::export::{export, object_triangles};
use seethru::scene::mesh_io::load_mesh;
use seethru::scene::world::World;

#[test]
fn obj_and_glb_exports_reload_to_the_same_triangles() {
    let scene = common::das();
    let world = World::build(&scene).unwrap();
    let expected: Vec<[glam::Vec3; 3]> = object_triangles(&world).into_iter().flatten().collect();
    // Spheres are tessellated for export; everything else is the traced triangles themselves.
    assert!(expected.len() > world.triangles.len());
    let dir = tempfile::tempdir().unwrap();
    for name in ["das.obj", "das.glb"] {
        let path = dir.path().join(name);
        let count = export(&scene, &world, &path).unwrap();
        assert_eq!(count, expected.len());
        let loaded = load_mesh(&path).unwrap();
        assert_eq!(loaded.tris.len(), expected.len(), "{name}");
        // Same set of triangles (glTF nodes may come back in another order).
        let key = |t: &[glam::Vec3; 3]| {
            t.iter()
                .flat_map(|v| v.to_array())
                .map(f32::to_bits)
                .collect::<Vec<_>>()
        };
        let mut a: Vec<_> = expected.iter().map(key).collect();
        let mut b: Vec<_> = loaded.tris.iter().map(|t| key(&t.p)).collect();
        a.sort_unstable();
        b.sort_unstable();
        assert!(a == b, "{name}: triangles differ");
        let cameras: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(path.with_extension("cameras.json")).unwrap(),
        )
        .unwrap();
        let eye: Vec<f64> = serde_json::from_value(cameras["driver"]["position"].clone()).unwrap();
        assert_eq!(eye, scene.eye().to_array());
        assert_eq!(
            cameras["frontal"]["half_angle_x_deg"].as_f64().unwrap(),
            scene.frontal.half_angle_x.to_degrees()
        );
    }
    assert!(export(&scene, &world, &dir.path().join("das.stl")).is_err());
}
