//! What moves during a sequence, in a world and a hierarchy of its own: built once at the
//! objects' t = 0 placements, then, at each instant, every primitive carried by its object's
//! rigid motion and the small hierarchy rebuilt. The static world's hierarchy is never touched;
//! the integrator traces both (`RenderContext::moving`).

use anyhow::Result;
use glam::{Affine3A, DAffine3, Vec3};
use obvhs::rt_triangle::RtTriangle;

use crate::render::accel::Accel;
use crate::scene::Scene;
use crate::scene::world::World;

/// The moving part of a scene at one instant, ready to trace.
pub struct MovingLayer {
    pub world: World,
    pub accel: Accel,
}

/// The moving part of a scene at its t = 0 placements.
pub struct MovingParts {
    reference: World,
    /// Corners of every triangle of `reference`, world frame.
    corners: Vec<[Vec3; 3]>,
}

impl MovingParts {
    /// The objects `keep` selects and the obstacle, at the scene's placements.
    pub fn new(scene: &Scene, keep: &dyn Fn(usize) -> bool) -> Result<Self> {
        let reference = World::build_part(scene, keep, true)?;
        let corners = reference
            .triangles
            .iter()
            .map(|t| {
                let v0 = Vec3::from(t.v0);
                [v0, v0 - Vec3::from(t.e1), v0 + Vec3::from(t.e2)]
            })
            .collect();
        Ok(Self { reference, corners })
    }

    /// The layer at an instant: the primitives of object id `o` carried by `motion(o)` (a
    /// rigid world_from_world map; `None`: where it is at t = 0), and its hierarchy rebuilt.
    pub fn at(&self, motion: &dyn Fn(u32) -> Option<DAffine3>) -> Result<MovingLayer> {
        let r = &self.reference;
        let maps: Vec<Option<DAffine3>> = (1..=r.objects.len() as u32).map(motion).collect();
        let map_of = |object: u32| maps[object as usize - 1];
        let mut triangles = Vec::with_capacity(r.triangles.len());
        let mut tri_attrs = r.tri_attrs.clone();
        for ((corners, attr), old) in self.corners.iter().zip(&mut tri_attrs).zip(&r.triangles) {
            let Some(m) = map_of(attr.object) else {
                triangles.push(*old);
                continue;
            };
            let [a, b, c] = corners.map(|p| m.transform_point3(p.as_dvec3()).as_vec3());
            triangles.push(RtTriangle::new(a.into(), b.into(), c.into()));
            attr.normal = m
                .transform_vector3(attr.normal.as_dvec3())
                .normalize()
                .as_vec3();
        }
        let mut ellipsoids = r.ellipsoids.clone();
        for e in &mut ellipsoids {
            if let Some(m) = map_of(e.object) {
                let m = Affine3A::from_cols_array(&m.to_cols_array().map(|v| v as f32));
                e.world_from_object = m * e.world_from_object;
                e.object_from_world = e.world_from_object.inverse();
                e.normal_from_object = e.object_from_world.matrix3.transpose();
            }
        }
        let world = World {
            triangles,
            tri_attrs,
            ellipsoids,
            objects: r.objects.clone(),
            materials: r.materials.clone(),
            textures: r.textures.clone(),
            obstacle_id: r.obstacle_id,
        };
        let accel = Accel::build(&world)?;
        Ok(MovingLayer { world, accel })
    }
}
