//! OpenDRIVE text → the road's triangles, the ego lane's pose and its route: no panic, no
//! hang, one-line errors, finite geometry.
#![no_main]

use libfuzzer_sys::fuzz_target;
use seethru::scene::road_map::{
    RoadLook, Turn, lane_pose, parse_network, road_triangles, route_points,
};

fuzz_target!(|data: &[u8]| {
    let Ok(xml) = std::str::from_utf8(data) else {
        return;
    };
    let network = match parse_network(xml, |_| Err("no includes here".to_string())) {
        Ok((network, warnings)) => {
            assert!(warnings.iter().all(|w| !w.contains('\n')), "{warnings:?}");
            network
        }
        Err(e) => {
            assert!(!format!("{e:#}").contains('\n'), "{e:#}");
            return;
        }
    };
    let mesh = road_triangles(&network, &RoadLook::default());
    assert!(mesh.tris.iter().all(|t| t.p.iter().all(|p| p.is_finite())));
    for road in network.roads().iter().take(4) {
        let length = road.length();
        for lane in [-2, -1, 1, 2] {
            for s in [0.0, length / 2.0, length] {
                match lane_pose(&network, road.od_id(), lane, s) {
                    Ok(pose) => {
                        assert!(pose.center.is_finite() && pose.travel.is_normalized());
                        let route = route_points(&network, &pose, &[Turn::Left, Turn::Right]);
                        assert!(route.iter().all(|p| p.is_finite()));
                    }
                    Err(e) => assert!(!e.message.contains('\n'), "{}", e.message),
                }
            }
        }
    }
});
