//! `[road]`: an OpenDRIVE map as the scene's road (scene/road_map.rs), placed in the world
//! as OpenDRIVE's axes say, or so that the ego vehicle stands in a lane of it.

use glam::{DAffine3, DMat3, DVec3};

use crate::scene::coat_keys::read_coat;
use crate::scene::lane_route::LaneRoute;
use crate::scene::limits::MAX_LENGTH;
use crate::scene::motion::{MovesWith, ObjectMotion};
use crate::scene::road_map::{PoseInput, RoadLook, Turn, lane_pose, read_network, route_points};
use crate::scene::source::SceneError;
use crate::scene::table_reader::TableReader;
use crate::scene::{CameraKind, Object, Shape};

/// The name of the object a `[road]` table adds.
pub const ROAD_OBJECT_NAME: &str = "road";

/// The keys that place the ego vehicle in a lane: all three or none.
const EGO_KEYS: [&str; 3] = ["ego_road", "ego_lane", "ego_s"];

/// World from OpenDRIVE's inertial frame (x east, y north, z up): x stays, up becomes +y,
/// north becomes −z. A rotation (determinant 1), so faces keep their winding.
pub fn world_from_map_axes() -> DMat3 {
    DMat3::from_cols(DVec3::X, DVec3::NEG_Z, DVec3::Y)
}

/// World from map such that the map point `center` lands on `at` and the horizontal map
/// direction `travel` becomes −z (the way the driver looks in every bundled scene), up
/// staying up.
pub fn world_from_map_at(center: DVec3, travel: DVec3, at: DVec3) -> DAffine3 {
    let axes = world_from_map_axes();
    let forward = axes * travel;
    let right = forward.cross(DVec3::Y).normalize();
    // The rows are the world's axes in the swapped frame: right → +x, up → +y, forward → −z.
    let turn = DMat3::from_cols(right, DVec3::Y, -forward).transpose();
    DAffine3::from_translation(at)
        * DAffine3::from_mat3(turn)
        * DAffine3::from_translation(-(axes * center))
        * DAffine3::from_mat3(axes)
}

/// What a `[road]` table adds to a scene: the map's object and, where it places the ego
/// vehicle in a lane, the route the vehicle drives in a sequence.
pub struct Road {
    pub object: Object,
    pub route: Option<LaneRoute>,
    /// What the importer dropped or doubted in the map, one line each, the file named.
    pub warnings: Vec<String>,
}

/// The scene's `[road]` table, if it has one.
pub fn read_road(root: &TableReader, objects: &[Object]) -> Result<Option<Road>, SceneError> {
    let Some(t) = root.table("road")? else {
        return Ok(None);
    };
    let rel = t.required_str("xodr")?;
    if !rel.to_ascii_lowercase().ends_with(".xodr") {
        return Err(t.error(
            "xodr",
            format!("`{rel}`: an OpenDRIVE map's file name ends in .xodr"),
        ));
    }
    let path = t.existing_asset("xodr", rel)?;
    let (map, warnings) =
        read_network(&path).map_err(|e| t.error("xodr", format!("`{rel}`: {e:#}")))?;
    let warnings = (warnings.into_iter())
        .map(|w| crate::util::message::printable(&format!("{}: {w}", path.display())))
        .collect();
    let given: Vec<&str> = EGO_KEYS.into_iter().filter(|k| t.has(k)).collect();
    let (world_from_map, route) = match given.len() {
        0 => {
            if let Some(key) = ["lane_center_at", "turns"].into_iter().find(|k| t.has(k)) {
                return Err(t.error(
                    key,
                    "belongs to the ego vehicle's lane: it needs ego_road, ego_lane and ego_s",
                ));
            }
            (DAffine3::from_mat3(world_from_map_axes()), None)
        }
        3 => {
            let road = t.required_str("ego_road")?;
            let lane = t.opt_i64("ego_lane", -100, 100)?.expect("given");
            if lane == 0 {
                return Err(t.error(
                    "ego_lane",
                    "lane 0 is the reference line, which has no width: a driving lane is -1, -2, … (right) or 1, 2, … (left)",
                ));
            }
            let s = t.f64_in("ego_s", 0.0, 0.0, MAX_LENGTH)?;
            let pose = lane_pose(&map.network, road, lane, s).map_err(|e| {
                let key = match e.about {
                    PoseInput::Road => "ego_road",
                    PoseInput::Lane => "ego_lane",
                    PoseInput::S => "ego_s",
                };
                t.error(key, e.message)
            })?;
            let at = t.point("lane_center_at", Some([0.0; 3]))?;
            let world_from_map = world_from_map_at(pose.center, pose.travel, at);
            let turns: Vec<Turn> = t
                .str_list("turns", &Turn::NAMES)?
                .into_iter()
                .filter_map(Turn::parse)
                .collect();
            let route = LaneRoute::new(
                route_points(&map.network, &pose, &turns)
                    .into_iter()
                    .map(|p| world_from_map.transform_point3(p)),
            );
            (world_from_map, route)
        }
        _ => {
            let missing: Vec<&str> = EGO_KEYS.into_iter().filter(|k| !t.has(k)).collect();
            return Err(t.error(
                given[0],
                format!(
                    "places the ego vehicle in a lane together with {}: give all of ego_road, ego_lane and ego_s, or none",
                    missing.join(" and ")
                ),
            ));
        }
    };
    let defaults = RoadLook::default();
    let (specular, roughness) = read_coat(&t)?;
    let look = RoadLook {
        asphalt: t.color("asphalt_color", defaults.asphalt)?,
        sidewalk: t.color("sidewalk_color", defaults.sidewalk)?,
        verge: t.color("verge_color", defaults.verge)?,
        object: t.color("object_color", defaults.object)?,
        signal: t.color("signal_color", defaults.signal)?,
        traffic_light: t.color("traffic_light_color", defaults.traffic_light)?,
        specular,
        roughness,
    };
    if objects.iter().any(|o| o.name == ROAD_OBJECT_NAME) {
        return Err(t.table_error(format!(
            "[road] adds the object `{ROAD_OBJECT_NAME}`, and an [[object]] already has that name"
        )));
    }
    t.finish()?;
    let object = Object {
        name: ROAD_OBJECT_NAME.to_string(),
        shape: Shape::Road { path, look, map },
        material: None,
        file_materials: Vec::new(),
        world_from_object: world_from_map,
        visible_to: CameraKind::ALL,
        casts_shadow: true,
        hazard: false,
        motion: ObjectMotion {
            moves_with: MovesWith::World,
            keyframes: Vec::new(),
            scale: DVec3::ONE,
            places: Vec::new(),
        },
        instances: Vec::new(),
    };
    Ok(Some(Road {
        object,
        route,
        warnings,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_axes_put_north_ahead_and_up_up() {
        let m = world_from_map_axes();
        assert_eq!(m * DVec3::Y, DVec3::NEG_Z);
        assert_eq!(m * DVec3::Z, DVec3::Y);
        assert_eq!(m * DVec3::X, DVec3::X);
        assert!((m.determinant() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_ego_pose_lands_on_its_point_facing_minus_z() {
        let center = DVec3::new(120.0, -40.0, 3.0);
        let heading = 0.7_f64;
        let travel = DVec3::new(heading.cos(), heading.sin(), 0.0);
        let at = DVec3::new(1.75, 0.0, 0.0);
        let m = world_from_map_at(center, travel, at);
        assert!(m.transform_point3(center).distance(at) < 1e-9);
        // Ten metres along the lane: ten metres ahead.
        let ahead = m.transform_point3(center + 10.0 * travel);
        assert!(ahead.distance(at + DVec3::new(0.0, 0.0, -10.0)) < 1e-9);
        // Left of travel (OpenDRIVE's +t) is the driver's left, −x; up is up.
        let left = DVec3::new(-travel.y, travel.x, 0.0);
        assert!(m.transform_point3(center + left).distance(at - DVec3::X) < 1e-9);
        assert!(
            m.transform_point3(center + DVec3::Z)
                .distance(at + DVec3::Y)
                < 1e-9
        );
    }
}
