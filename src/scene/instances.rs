//! Instances: one mesh placed many times (`[[object]] instances = "placements.csv"`).
//!
//! The world keeps such a mesh once, in its object frame, with one transform per placement
//! (`world.rs`'s `InstanceSet`); the tracer shares one hierarchy among the placements
//! (`render/instances.rs`). A placed triangle is defined by [`placed`]: its base vertex under
//! the whole transform, its edges and normal under the linear part, in f32 with the
//! operations in one fixed order. The tracer's leaf test applies the same function to four
//! triangles at once and the world to one (`InstanceSet::triangle`), so an instanced world
//! and the same world flattened (`World::flattened`) hit the same triangles at the same
//! distances, bit for bit.
//!
//! A placements file is CSV, one instance a row: `x,y,z,yaw_deg` (metres, world frame;
//! degrees about +y, counter-clockwise seen from above), with an optional header. The row
//! places the object as its `translate`/`rotate_deg`/`scale` keys leave it: world from object
//! = translation(x, y, z) · rotation about y(yaw) · the object's own transform.

use std::ops::{Add, Mul, Sub};
use std::path::Path;

use anyhow::{Result, bail};
use glam::{Affine3A, DAffine3, DVec3, Vec3, Vec3A, Vec4};
use obvhs::rt_triangle::RtTriangle;

use crate::util::number_rows::number_rows;

/// Most rows of one placements file.
pub const MAX_INSTANCES: usize = 1_000_000;
/// Most triangles of a world's instances together, counted once per placement (primitive
/// indices are 32-bit).
pub const MAX_INSTANCED_TRIANGLES: u64 = 1_000_000_000;

/// A number or four numbers in SIMD lanes: what [`placed`] computes with, so that one
/// triangle and a packet of four are placed by the same operations.
pub trait Lane: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> {
    fn splat(v: f32) -> Self;
}

impl Lane for f32 {
    #[inline(always)]
    fn splat(v: f32) -> f32 {
        v
    }
}

impl Lane for Vec4 {
    #[inline(always)]
    fn splat(v: f32) -> Vec4 {
        Vec4::splat(v)
    }
}

/// A triangle in the layout of [`RtTriangle`] (base vertex, `e1 = v0 − v1`, `e2 = v2 − v0`,
/// `ng = e1 × e2`), per axis, placed by `m`: `v0` under the whole transform, the edges
/// under its linear part, the normal their cross product.
#[inline(always)]
pub fn placed<L: Lane>(m: &Affine3A, v0: [L; 3], e1: [L; 3], e2: [L; 3]) -> [[L; 3]; 4] {
    let c = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis];
    let t = m.translation;
    let linear = |v: [L; 3]| {
        [0, 1, 2].map(|row| {
            L::splat(c[0][row]) * v[0] + L::splat(c[1][row]) * v[1] + L::splat(c[2][row]) * v[2]
        })
    };
    let moved = linear(v0);
    let v0 = [0, 1, 2].map(|row| moved[row] + L::splat(t[row]));
    let (e1, e2) = (linear(e1), linear(e2));
    [v0, e1, e2, normal(e1, e2)]
}

/// `e1 × e2`, in the order of operations of `RtTriangle`'s stored normal (glam's
/// `Vec3A::cross`: x = e1.y·e2.z − e1.z·e2.y, and so on), so that a normal computed here (a
/// placed triangle's, a packet's lane) is the world's bit for bit.
#[inline(always)]
pub fn normal<L: Lane>(e1: [L; 3], e2: [L; 3]) -> [L; 3] {
    [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ]
}

/// [`placed`] of one triangle.
pub fn placed_triangle(m: &Affine3A, t: &RtTriangle) -> RtTriangle {
    let a = |v: Vec3A| v.to_array();
    let [v0, e1, e2, ng] = placed(m, a(t.v0), a(t.e1), a(t.e2)).map(Vec3A::from_array);
    RtTriangle { v0, e1, e2, ng }
}

/// The transform of a placements row: translation(x, y, z) · rotation about y(yaw) ·
/// `object`.
pub fn world_from_object(row: [f64; 4], object: &DAffine3) -> DAffine3 {
    let [x, y, z, yaw_deg] = row;
    DAffine3::from_translation(DVec3::new(x, y, z))
        * DAffine3::from_rotation_y(yaw_deg.to_radians())
        * *object
}

/// The eight corners of the box [lo, hi] (corner i takes hi on axis k where bit k of i is set).
pub fn box_corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        let pick = |bit: usize, a: f32, b: f32| if i & bit == 0 { a } else { b };
        Vec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        )
    })
}

/// A placement as [`placed`] applies it: the transform rounded to f32.
pub fn in_f32(m: &DAffine3) -> Affine3A {
    Affine3A::from_cols_array(&m.to_cols_array().map(|v| v as f32))
}

/// Reads a placements file: rows `x,y,z,yaw_deg` (an optional header); errors name the file
/// as `name` and the line.
pub fn read_placements(path: &Path, name: &str) -> Result<Vec<[f64; 4]>> {
    let text = crate::util::input_file::read_input(path, MAX_PLACEMENTS_BYTES)
        .map_err(|e| anyhow::anyhow!("{name}: cannot read the placements: {e}"))?;
    parse_placements(&text, name)
}

/// Largest placements file, bytes.
const MAX_PLACEMENTS_BYTES: u64 = 64 << 20;

/// [`read_placements`] of `text`, named `name` in errors.
pub fn parse_placements(text: &[u8], name: &str) -> Result<Vec<[f64; 4]>> {
    let rows = number_rows(
        text,
        name,
        ["x", "y", "z", "yaw_deg"],
        "metres, world frame; degrees about +y",
        MAX_INSTANCES,
    )?;
    if rows.is_empty() {
        bail!("{name}: no placements (expected x,y,z,yaw_deg rows)");
    }
    Ok(rows.into_iter().map(|(_, row)| row).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placements_read_with_or_without_a_header_and_name_the_bad_line() {
        let rows = parse_placements(
            b"x,y,z,yaw_deg\n1,2,3,90\n# a comment\n-1, 0, 0, 0\n",
            "p.csv",
        )
        .unwrap();
        assert_eq!(rows, vec![[1.0, 2.0, 3.0, 90.0], [-1.0, 0.0, 0.0, 0.0]]);
        let err = |text: &str| {
            parse_placements(text.as_bytes(), "p.csv")
                .unwrap_err()
                .to_string()
        };
        assert!(err("1,2,3\n").starts_with("p.csv:1: expected 4 values"));
        assert!(err("1,2,3,4\n1,2,NaN,4\n").starts_with("p.csv:2: `z` must be a finite"));
        assert!(err("1,2,3,4\n1,2,3,1e9\n").starts_with("p.csv:2: `yaw_deg`"));
        assert!(err("x,y,z,yaw_deg\n").starts_with("p.csv: no placements"));
    }

    /// A placement turns the mesh about +y by its yaw, then moves it: a point 1 m along +x
    /// turned 90° lies 1 m along −z (counter-clockwise seen from above).
    #[test]
    fn a_placement_turns_then_moves() {
        let m = in_f32(&world_from_object(
            [10.0, 0.0, 5.0, 90.0],
            &DAffine3::IDENTITY,
        ));
        let p = m.transform_point3(glam::Vec3::X);
        assert!((p - glam::Vec3::new(10.0, 0.0, 4.0)).length() < 1e-6, "{p}");
    }

    /// The placed triangle's corners are the transformed corners (to rounding), and the packet
    /// form gives the single form's bits in every lane.
    #[test]
    fn placing_one_triangle_or_four_gives_the_same_bits() {
        let m = in_f32(&world_from_object(
            [3.25, -0.5, 17.0, 33.0],
            &DAffine3::from_scale(DVec3::splat(1.7)),
        ));
        let tris: Vec<RtTriangle> = (0..4)
            .map(|i| {
                let f = i as f32;
                RtTriangle::new(
                    Vec3A::new(0.1 * f, 1.0, -0.3),
                    Vec3A::new(1.0, 0.2 * f, 0.4),
                    Vec3A::new(-0.7, 0.5, 1.0 + f),
                )
            })
            .collect();
        let lanes = |get: fn(&RtTriangle) -> Vec3A| {
            [0, 1, 2].map(|axis| Vec4::from_array([0, 1, 2, 3].map(|l| get(&tris[l])[axis])))
        };
        let packet = placed(&m, lanes(|t| t.v0), lanes(|t| t.e1), lanes(|t| t.e2));
        for (lane, tri) in tris.iter().enumerate() {
            let one = placed_triangle(&m, tri);
            for (k, v) in [one.v0, one.e1, one.e2, one.ng].iter().enumerate() {
                for axis in 0..3 {
                    assert_eq!(packet[k][axis][lane].to_bits(), v[axis].to_bits());
                }
            }
            let [a, b, c] =
                [tri.v0, tri.v0 - tri.e1, tri.v0 + tri.e2].map(|p| m.transform_point3a(p));
            assert!((one.v0 - a).length() < 1e-5);
            assert!(((one.v0 - one.e1) - b).length() < 1e-5);
            assert!(((one.v0 + one.e2) - c).length() < 1e-5);
        }
    }
}
