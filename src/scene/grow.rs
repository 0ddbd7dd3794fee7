//! A scene grown procedurally to a multiple of its triangle count — parked cars, trees and
//! buildings in lots along both sides of the street, further out as it fills — so that
//! `seethru bench --grow` can show how build time and ray throughput scale with scene size.
//! The growth is deterministic (hashed, no random generator).

use anyhow::{Result, bail};
use glam::{DAffine3, DQuat, DVec3};

use crate::scene::mesh_io::load_mesh;
use crate::scene::shapes::frustum;
use crate::scene::world::World;
use crate::scene::{CameraKind, Material, Object, Scene, Shape};
use crate::util::sampling::{hash_words, unit_float};

/// Largest growth factor accepted.
pub const MAX_GROW: f64 = 2000.0;

/// Lot size along the street (z) and across it (x), metres.
const LOT_Z: f64 = 10.0;
const LOT_X: f64 = 12.0;
/// Lots per side and column: the street is 300 m long.
const LOTS_ALONG: u32 = 30;
/// Distance from the street's centre line to the first column of lots' centres, metres.
const FIRST_COLUMN_X: f64 = 12.0;

/// `base` with objects added until it has about `factor` times its triangles (≥ 1; 1 gives
/// `base` unchanged). Parked cars are copies of the scene's first mesh object (boxes if it
/// has none).
pub fn grow(base: &Scene, factor: f64) -> Result<Scene> {
    if !(1.0..=MAX_GROW).contains(&factor) {
        bail!("option `grow` {factor} is out of range [1, {MAX_GROW}]");
    }
    let mut scene = base.clone();
    if factor == 1.0 {
        return Ok(scene);
    }
    let base_triangles = World::build(base)?.triangles.len();
    let target = (base_triangles as f64 * factor).round() as usize;
    let material = |scene: &mut Scene, name: &str, color: [f64; 3]| {
        (scene.materials).push(Material::matte(format!("grown_{name}"), color));
        scene.materials.len() - 1
    };
    let bark = material(&mut scene, "bark", [0.36, 0.25, 0.16]);
    let foliage = material(&mut scene, "foliage", [0.2, 0.45, 0.16]);
    let wall = material(&mut scene, "wall", [0.7, 0.66, 0.6]);
    let body = material(&mut scene, "car", [0.55, 0.1, 0.1]);
    let car = base
        .objects
        .iter()
        .find(|o| matches!(o.shape, Shape::Mesh { .. }))
        .map(|o| o.shape.clone());
    let car_triangles = match &car {
        Some(Shape::Mesh { path }) => load_mesh(path)?.tris.len(),
        _ => 12,
    };
    let (trunk, crown) = (
        frustum(0.16, 0.16, 2.0, 12).len(),
        frustum(1.2, 0.0, 3.5, 16).len(),
    );
    let lot_triangles = car_triangles + 2 * (trunk + crown) + 12;
    let lots = target
        .saturating_sub(base_triangles)
        .div_ceil(lot_triangles);
    let all_cameras = CameraKind::Driver.bit() | CameraKind::Frontal.bit() | CameraKind::Back.bit();
    let mut add = |name: String, shape: Shape, material: Option<usize>, at: DAffine3| {
        scene.objects.push(Object {
            name,
            shape,
            material,
            file_materials: Vec::new(),
            world_from_object: at,
            visible_to: all_cameras,
            casts_shadow: true,
            hazard: false,
            motion: Default::default(),
            instances: Vec::new(),
        })
    };
    for lot in 0..lots as u32 {
        // Left and right alternate; each side fills 30 lots along the street, then moves out.
        let (side, along, column) = (lot % 2, (lot / 2) % LOTS_ALONG, lot / (2 * LOTS_ALONG));
        let sign = if side == 0 { -1.0 } else { 1.0 };
        let x = sign * (FIRST_COLUMN_X + LOT_X * column as f64);
        let z = -LOT_Z * (along as f64 + 0.5) - 5.0;
        let u = |k: u32| unit_float(hash_words(&[lot, k])) as f64;
        let turn = DQuat::from_rotation_y(if u(0) < 0.5 {
            0.0
        } else {
            std::f64::consts::PI
        });
        // The car nearest the street, the building furthest from it, trees between.
        let car_at = DAffine3::from_rotation_translation(
            turn,
            DVec3::new(x - sign * 3.5, 0.0, z + 2.0 * (u(1) - 0.5)),
        );
        match &car {
            Some(shape) => add(format!("grown_car_{lot}"), shape.clone(), None, car_at),
            None => add(
                format!("grown_car_{lot}"),
                Shape::Box {
                    size: [1.8, 1.5, 4.2],
                },
                Some(body),
                car_at * DAffine3::from_translation(DVec3::new(0.0, 0.75, 0.0)),
            ),
        }
        for t in 0..2u32 {
            let tz = z + if t == 0 { -3.0 } else { 3.0 };
            let at = DAffine3::from_translation(DVec3::new(x, 0.0, tz));
            add(
                format!("grown_trunk_{lot}_{t}"),
                Shape::Cylinder {
                    radius: 0.16,
                    height: 2.0,
                    segments: 12,
                },
                Some(bark),
                at,
            );
            add(
                format!("grown_crown_{lot}_{t}"),
                Shape::Cone {
                    radius: 1.2,
                    height: 3.5,
                    segments: 16,
                },
                Some(foliage),
                at * DAffine3::from_translation(DVec3::new(0.0, 1.5, 0.0)),
            );
        }
        let height = 6.0 + 14.0 * u(2);
        add(
            format!("grown_building_{lot}"),
            Shape::Box {
                size: [5.0, height, 8.0],
            },
            Some(wall),
            DAffine3::from_translation(DVec3::new(x + sign * 3.5, height / 2.0, z)),
        );
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_reaches_the_factor_and_is_deterministic() {
        let base = Scene::bundled("das.toml");
        let n = |s: &Scene| World::build(s).unwrap().triangles.len() as f64;
        assert!(grow(&base, 1.0).unwrap() == base);
        let grown = grow(&base, 10.0).unwrap();
        let ratio = n(&grown) / n(&base);
        // Whole lots are added: at most one lot (about one car) over the target.
        assert!((10.0..11.0).contains(&ratio), "{ratio}");
        assert!(grown == grow(&base, 10.0).unwrap());
        assert!(grow(&base, 0.5).is_err() && grow(&base, 1e6).is_err());
    }
}
