//! The committed assets are exactly what the generators produce (`cargo run --example make_assets`).

mod common;

use seethru::scene::head_model::{head_mtl, head_obj};
use seethru::scene::mesh_io::load_mesh;
use seethru::scene::procedural::{car_mtl, car_obj, street_texture};

#[test]
fn committed_assets_match_their_generators() {
    let read =
        |name: &str| std::fs::read_to_string(common::repo_path(&format!("assets/{name}"))).unwrap();
    assert!(
        read("car.obj") == car_obj(),
        "assets/car.obj is stale: run `cargo run --example make_assets`"
    );
    assert_eq!(read("car.mtl"), car_mtl(), "assets/car.mtl is stale");
    assert!(
        read("head.obj") == head_obj(),
        "assets/head.obj is stale: run `cargo run --example make_assets`"
    );
    assert_eq!(read("head.mtl"), head_mtl(), "assets/head.mtl is stale");
    let png = image::open(common::repo_path("assets/street.png"))
        .unwrap()
        .to_rgb8();
    assert!(png == street_texture(), "assets/street.png is stale");
}

#[test]
fn the_car_is_a_real_mesh() {
    let car = load_mesh(&common::repo_path("assets/car.obj")).unwrap();
    assert!(car.tris.len() > 5000, "{} triangles", car.tris.len());
    let names: Vec<&str> = car.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["body", "glass", "wheels"]);
    // Three parts (body, glass, wheels), each with its own material.
    for part in 0..3 {
        let tris: Vec<_> = car.tris.iter().filter(|t| t.part == part).collect();
        assert!(!tris.is_empty());
        assert!(tris.iter().all(|t| t.file_material == Some(part)));
    }
    // A compact car's size: about 4.3 × 1.8 × 1.45 m, standing on y = 0.
    let (mut lo, mut hi) = (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN));
    for p in car.tris.iter().flat_map(|t| t.p) {
        (lo, hi) = (lo.min(p), hi.max(p));
    }
    let size = hi - lo;
    assert!(
        lo.y.abs() < 1e-3
            && (size.z - 4.3).abs() < 0.05
            && (1.6..2.0).contains(&size.x)
            && (1.3..1.6).contains(&size.y),
        "{size}"
    );
}
