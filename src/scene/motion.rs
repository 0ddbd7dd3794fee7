//! Motion over time, for `seethru sequence`: what an object rides with (the world, the
//! vehicle, the driver's head), its keyframed path, and the vehicle's own motion.
//!
//! Every other command sees the scene at its placement (`translate`, `rotate_deg`): the
//! paths here are read only by `sequence`, so a static command's images never depend on them.

use glam::{DAffine3, DQuat, DVec3, EulerRot};

use crate::scene::lane_route::LaneRoute;
use crate::scene::limits::out_of_world;
use crate::scene::source::SceneError;
use crate::scene::table_reader::TableReader;

/// Latest keyframe time, seconds.
pub const MAX_KEY_TIME_S: f64 = 3600.0;
/// Most keyframes of one object.
pub const MAX_KEYFRAMES: usize = 10_000;

/// What an object moves with during a sequence (`moves_with`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MovesWith {
    /// Fixed in the world (or on its own keyframed path).
    #[default]
    World,
    /// Rides with the vehicle, as the obstacle and the cameras do.
    Vehicle,
    /// Rides with the vehicle and follows the driver's head motion (the head the back
    /// camera films).
    Head,
}

impl MovesWith {
    pub const NAMES: [&'static str; 3] = ["world", "vehicle", "head"];
}

/// One `[[object.keyframe]]`: the object's placement at time `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keyframe {
    /// Time, seconds from the start of the sequence, in [0, 3600]; strictly increasing.
    pub t: f64,
    /// Position, world frame, metres (default: the object's `translate`).
    pub translate: DVec3,
    /// Rotation about x, then y, then z, degrees (default: the object's `rotate_deg`).
    pub rotate_deg: DVec3,
}

/// How one object moves during a sequence.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjectMotion {
    pub moves_with: MovesWith,
    /// The keyframed path (empty: the object stays at its placement). Linear between keys,
    /// held before the first and after the last.
    pub keyframes: Vec<Keyframe>,
    /// The object's scale factors (the keyframes replace translation and rotation only).
    pub scale: DVec3,
    /// Where each keyframe's `translate` is in the scene file (its message empty), for
    /// errors found once the object's mesh is loaded: its triangles leaving the world.
    pub places: Vec<crate::scene::source::SceneError>,
}

impl ObjectMotion {
    /// Whether `sequence` has to move the object.
    pub fn moves(&self) -> bool {
        self.moves_with != MovesWith::World || !self.keyframes.is_empty()
    }

    /// world_from_object at time `t` (s) on the keyframed path; `None` without keyframes.
    pub fn world_from_object_at(&self, t: f64) -> Option<DAffine3> {
        let keys = &self.keyframes;
        let first = keys.first()?;
        let (translate, rotate) = match keys.iter().position(|k| k.t > t) {
            Some(0) => (first.translate, first.rotate_deg),
            None => {
                let last = keys[keys.len() - 1];
                (last.translate, last.rotate_deg)
            }
            Some(i) => {
                let (a, b) = (keys[i - 1], keys[i]);
                let s = (t - a.t) / (b.t - a.t);
                (
                    a.translate.lerp(b.translate, s),
                    a.rotate_deg.lerp(b.rotate_deg, s),
                )
            }
        };
        Some(placement(translate, rotate, self.scale))
    }
}

/// translate · rotate (about x, then y, then z, degrees) · scale, as scene files define it.
pub fn placement(translate: DVec3, rotate_deg: DVec3, scale: DVec3) -> DAffine3 {
    let r = rotate_deg * (std::f64::consts::PI / 180.0);
    let rotation = DQuat::from_euler(EulerRot::ZYX, r.z, r.y, r.x);
    DAffine3::from_scale_rotation_translation(scale, rotation, translate)
}

/// Reads `moves_with` and `[[object.keyframe]]` of an object table. `corners` are the
/// object-space corners of a box around the shape (empty for meshes: their origin is
/// checked), placed at every key to keep the path inside the world.
pub fn read_object_motion(
    t: &TableReader,
    translate: DVec3,
    rotate_deg: DVec3,
    scale: DVec3,
    corners: &[DVec3],
) -> Result<ObjectMotion, SceneError> {
    let moves_with = match t.choice("moves_with", "world", &MovesWith::NAMES)? {
        "vehicle" => MovesWith::Vehicle,
        "head" => MovesWith::Head,
        _ => MovesWith::World,
    };
    let tables = t.array_of_tables("keyframe")?;
    if tables.len() > MAX_KEYFRAMES {
        return Err(t.error(
            "keyframe",
            format!(
                "{} keyframes, more than the limit of {MAX_KEYFRAMES}",
                tables.len()
            ),
        ));
    }
    if !tables.is_empty() && moves_with != MovesWith::World {
        return Err(t.error(
            "keyframe",
            "an object that moves with the vehicle or the head has no path of its own",
        ));
    }
    let mut keyframes: Vec<Keyframe> = Vec::new();
    let mut places = Vec::new();
    for k in tables {
        let time = k.f64_in("t", f64::NAN, 0.0, MAX_KEY_TIME_S).map_err(|e| {
            if k.has("t") {
                e
            } else {
                k.error("t", "required key is missing (seconds in [0, 3600])")
            }
        })?;
        if let Some(prev) = keyframes.last()
            && time <= prev.t
        {
            return Err(k.error(
                "t",
                format!(
                    "keyframe times must increase: {time} s follows {} s",
                    prev.t
                ),
            ));
        }
        let key = Keyframe {
            t: time,
            translate: k.point("translate", Some(translate.to_array()))?,
            rotate_deg: DVec3::from_array(k.array_in(
                "rotate_deg",
                rotate_deg.to_array(),
                -crate::scene::limits::MAX_ROTATION_DEG,
                crate::scene::limits::MAX_ROTATION_DEG,
            )?),
        };
        let at = placement(key.translate, key.rotate_deg, scale);
        let origin = [DVec3::ZERO];
        let points = if corners.is_empty() {
            &origin[..]
        } else {
            corners
        };
        if let Some(why) = points
            .iter()
            .find_map(|c| out_of_world(at.transform_point3(*c)))
        {
            return Err(k.error(
                "translate",
                format!("the path leaves the world at t = {time} s: {why}"),
            ));
        }
        places.push(k.error("translate", ""));
        k.finish()?;
        keyframes.push(key);
    }
    Ok(ObjectMotion {
        moves_with,
        keyframes,
        scale,
        places,
    })
}

/// Checks a keyframed mesh at every keyframe: the corners of its bounding box (object frame)
/// placed by each key stay inside the world, as a keyframed sphere's do. The error names the
/// scene file and the keyframe's line.
pub fn check_keyframed_mesh(
    path: &std::path::Path,
    object: &str,
    tris: &[crate::scene::shapes::Tri],
    motion: &ObjectMotion,
) -> anyhow::Result<()> {
    let Some(first) = tris.first() else {
        return Ok(());
    };
    let (mut lo, mut hi) = (first.p[0].as_dvec3(), first.p[0].as_dvec3());
    for p in tris.iter().flat_map(|t| t.p) {
        lo = lo.min(p.as_dvec3());
        hi = hi.max(p.as_dvec3());
    }
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    for (key, place) in motion.keyframes.iter().zip(&motion.places) {
        let at = placement(key.translate, key.rotate_deg, motion.scale);
        if let Some(why) = corners
            .iter()
            .find_map(|c| out_of_world(at.transform_point3(*c)))
        {
            let mut error = place.clone();
            error.message = format!(
                "the path of object `{object}` takes its mesh {} outside the world at t = {} s: {why}",
                path.display(),
                key.t
            );
            return Err(error.into());
        }
    }
    Ok(())
}

/// The vehicle's motion: constant speed along its heading, on flat ground (+y up) turning at
/// a constant yaw rate, or along a lane of a map (`route`). The rig — obstacle, cameras,
/// driver, and every object that moves with the vehicle — is rigid; at t = 0 it is where the
/// scene file puts it.
#[derive(Clone, Debug, PartialEq)]
pub struct VehicleMotion {
    /// Speed along the heading, m/s.
    pub speed: f64,
    /// Yaw rate, rad/s, positive turning left (counter-clockwise seen from above, about +y);
    /// 0 with a route.
    pub yaw_rate: f64,
    /// Unit heading at t = 0, horizontal, world frame.
    pub forward: DVec3,
    /// The pivot of the yaw rate's turn (the eye at t = 0), world frame.
    pub pivot: DVec3,
    /// The lane the vehicle follows, if the scene places it in one: the lane's centre point
    /// under the vehicle moves along it at `speed`, the vehicle turning with the lane's
    /// heading and rising with its elevation (it does not pitch or roll with grade and
    /// bank).
    pub route: Option<std::sync::Arc<LaneRoute>>,
}

impl VehicleMotion {
    /// world_from_rig at time `t` (s), where the rig frame is the world frame at t = 0.
    pub fn world_from_rig(&self, t: f64) -> DAffine3 {
        if let Some(route) = &self.route {
            let (start, now) = (route.pose_at(0.0), route.pose_at(self.speed * t));
            return DAffine3::from_translation(now.position)
                * DAffine3::from_rotation_y(yaw_between(start.heading, now.heading))
                * DAffine3::from_translation(-start.position);
        }
        let (w, v, f) = (self.yaw_rate, self.speed, self.forward);
        let left = DVec3::Y.cross(f);
        // ∫₀ᵗ v (cos ωs f + sin ωs left) ds, with its limit ω → 0.
        let travelled = if (w * t).abs() < 1e-9 {
            v * t * f + 0.5 * v * w * t * t * left
        } else {
            (v / w) * ((w * t).sin() * f + (1.0 - (w * t).cos()) * left)
        };
        DAffine3::from_translation(self.pivot + travelled)
            * DAffine3::from_rotation_y(w * t)
            * DAffine3::from_translation(-self.pivot)
    }

    /// How far the vehicle has turned at `t`, radians, positive to the left.
    pub fn yaw_at(&self, t: f64) -> f64 {
        match &self.route {
            Some(route) => yaw_between(
                route.pose_at(0.0).heading,
                route.pose_at(self.speed * t).heading,
            ),
            None => self.yaw_rate * t,
        }
    }
}

/// The angle about +y that turns horizontal `from` onto horizontal `to`, in (−π, π].
fn yaw_between(from: DVec3, to: DVec3) -> f64 {
    from.cross(to).y.atan2(from.dot(to))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vehicle_follows_its_circle_and_its_heading() {
        let m = VehicleMotion {
            speed: 10.0,
            yaw_rate: 0.5,
            forward: DVec3::NEG_Z,
            pivot: DVec3::new(1.0, 1.2, 0.0),
            route: None,
        };
        // Numerical integration of the pivot's velocity against the closed form.
        let (mut p, steps, t) = (m.pivot, 20_000, 3.0);
        for i in 0..steps {
            let s = (i as f64 + 0.5) * t / steps as f64;
            let heading = DAffine3::from_rotation_y(0.5 * s).transform_vector3(DVec3::NEG_Z);
            p += heading * 10.0 * t / steps as f64;
        }
        let at = m.world_from_rig(t);
        assert!((at.transform_point3(m.pivot) - p).length() < 1e-6);
        // The heading turned left by ω t: −z turns towards −x.
        let heading = at.transform_vector3(DVec3::NEG_Z);
        assert!((heading.x + (1.5f64).sin()).abs() < 1e-12 && heading.x < 0.0);
        // Straight and still: identity at t = 0, a pure translation without yaw.
        assert!(m.world_from_rig(0.0).abs_diff_eq(DAffine3::IDENTITY, 1e-12));
        let straight = VehicleMotion {
            yaw_rate: 0.0,
            ..m.clone()
        };
        let moved = straight.world_from_rig(2.0).transform_point3(DVec3::ZERO);
        assert!((moved - DVec3::new(0.0, 0.0, -20.0)).length() < 1e-12);
    }

    #[test]
    fn keyframes_interpolate_and_hold() {
        let key = |t: f64, x: f64| Keyframe {
            t,
            translate: DVec3::new(x, 0.0, 0.0),
            rotate_deg: DVec3::new(0.0, 10.0 * x, 0.0),
        };
        let m = ObjectMotion {
            moves_with: MovesWith::World,
            keyframes: vec![key(1.0, 0.0), key(3.0, 4.0)],
            scale: DVec3::ONE,
            places: Vec::new(),
        };
        let x = |t: f64| m.world_from_object_at(t).unwrap().translation.x;
        assert_eq!(
            (x(0.0), x(1.0), x(2.0), x(3.0), x(9.0)),
            (0.0, 0.0, 2.0, 4.0, 4.0)
        );
        let turned = m.world_from_object_at(2.0).unwrap();
        let expected = DAffine3::from_rotation_y(20f64.to_radians());
        assert!(turned.matrix3.abs_diff_eq(expected.matrix3, 1e-12));
        assert!(ObjectMotion::default().world_from_object_at(1.0).is_none());
    }
}
