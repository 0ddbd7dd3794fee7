//! What moves during a sequence, in a world and a hierarchy of its own: built once at the
//! objects' t = 0 placements, then, at each instant, every primitive carried by its object's
//! rigid motion and the hierarchy refitted to the moved primitives (same tree, boxes
//! recomputed: [`Accel::refit`]), or rebuilt where the refitted boxes have grown past
//! [`REBUILD_AREA`] times the last build's. The static world's hierarchy is never touched;
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

/// A refit whose child boxes sum to more than this many times the half-area of the last
/// build's ([`Accel::area`]) is dropped for a fresh build, which later instants refit. Rigid
/// motion of a whole group (the head mesh) keeps the ratio near 1; objects of one visibility
/// group moving apart (two cars, a car and the obstacle) raise it without bound.
pub const REBUILD_AREA: f32 = 1.5;

/// The moving part of a scene at its t = 0 placements.
pub struct MovingParts {
    reference: World,
    /// Corners of every triangle of `reference`, world frame.
    corners: Vec<[Vec3; 3]>,
    /// The last hierarchy built (at the first instant placed, or the last one whose refit
    /// had grown too loose) and its [`Accel::area`].
    built: Option<(Accel, f32)>,
    /// Instants placed by a refit, and by a build.
    pub refits: usize,
    pub builds: usize,
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
        Ok(Self {
            reference,
            corners,
            built: None,
            refits: 0,
            builds: 0,
        })
    }

    /// The layer at an instant: the primitives of object id `o` carried by `motion(o)` (a
    /// rigid world_from_world map; `None`: where it is at t = 0), and the last built
    /// hierarchy refitted to them (rebuilt where the refit is too loose: [`REBUILD_AREA`]).
    /// Traces bit-identically to [`MovingParts::at_rebuilt`].
    pub fn at(&mut self, motion: &dyn Fn(u32) -> Option<DAffine3>) -> Result<MovingLayer> {
        let world = self.place(motion);
        if let Some((built, area)) = &self.built {
            let accel = built.refit(&world);
            if accel.area() <= REBUILD_AREA * area {
                self.refits += 1;
                return Ok(MovingLayer { world, accel });
            }
        }
        let accel = Accel::build(&world)?;
        self.built = Some((accel.clone(), accel.area()));
        self.builds += 1;
        Ok(MovingLayer { world, accel })
    }

    /// [`MovingParts::at`] with the hierarchy always built afresh: its twin.
    pub fn at_rebuilt(&self, motion: &dyn Fn(u32) -> Option<DAffine3>) -> Result<MovingLayer> {
        let world = self.place(motion);
        let accel = Accel::build(&world)?;
        Ok(MovingLayer { world, accel })
    }

    /// The moving world with the primitives of object id `o` carried by `motion(o)`.
    fn place(&self, motion: &dyn Fn(u32) -> Option<DAffine3>) -> World {
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
        World {
            triangles,
            tri_attrs,
            // Instanced objects are static: never in a moving part.
            instanced: Vec::new(),
            ellipsoids,
            objects: r.objects.clone(),
            materials: r.materials.clone(),
            textures: r.textures.clone(),
            obstacle_id: r.obstacle_id,
        }
    }
}
