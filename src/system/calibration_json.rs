//! `calibration.json` (and run.json's `calibration`): what a see-through system knows of its
//! rig, in OpenCV's conventions — the frontal and back cameras *as calibrated* (the believed
//! copies of `[calibration]`, not the true ones) at the capture's resolution, the display's
//! pose, size and pixel grid, and the obstacle frame, with the units and conventions stated.

use anyhow::Result;
use serde_json::{Value, json};

use crate::geometry::opencv::{camera_json, rows_4x4};
use crate::scene::Scene;

/// The calibration block of `scene` (its cameras already at the run's or capture's sizes).
pub fn calibration_json(scene: &Scene) -> Result<Value> {
    let frontal = scene.calibration.frontal.apply(&scene.frontal)?;
    let back = scene.calibration.back.apply(&scene.back)?;
    let o = &scene.obstacle;
    let [dw, dh] = o.display_resolution;
    Ok(json!({
        "units": "metres, radians, pixels",
        "conventions": {
            "world": "seethru's world frame: right-handed, +y up, metres",
            "camera": "OpenCV: camera looks down +z, +x right, +y down; world_from_camera maps that frame to the world; x_camera = R(rvec) · x_world + tvec (cv::projectPoints' extrinsics)",
            "pixels": "OpenCV: pixel centres at integer coordinates, (0, 0) the centre of the top-left pixel; seethru's continuous pixel = OpenCV's + 0.5",
            "distortion": "pinhole: none; opencv: cv::projectPoints' (k1, k2, p1, p2, k3); fisheye: cv::fisheye's (k1, k2, k3, k4)",
            "obstacle_frame": "origin at the display's centre, +x right and +y up across the display as the driver sees it, +z out of the display towards the driver",
            "display_pixels": "display pixel (i, j) (i right, j down, from the top-left) has its centre at obstacle x = ((i + 0.5) / width_px − 0.5) · width_m, y = (0.5 − (j + 0.5) / height_px) · height_m, z = 0",
            "display_map": "a method's map gives, per display pixel (row j, column i), the frontal pixel it shows in OpenCV's remap convention: map[j, i] = (x, y) with pixel centres at integers; NaN shows nothing",
            "cameras_are_calibrated": "these are the cameras as the system's calibration knows them; the true cameras (and the driver's eye) are not here",
        },
        "frontal": camera_json(&frontal),
        "back": camera_json(&back),
        "display": {
            "world_from_display": rows_4x4(o.world_from_obstacle),
            "width_m": o.width,
            "height_m": o.height,
            "resolution_px": [dw, dh],
            "pixel_pitch_m": [o.width / dw as f64, o.height / dh as f64],
            "normal_world": o.normal().to_array(),
            "corners_world_m_tl_tr_br_bl": o.display_corners().map(|c| c.to_array()),
        },
        "obstacle_frame": {
            "world_from_obstacle": rows_4x4(o.world_from_obstacle),
            "thickness_m": o.thickness,
            "note": "the display frame and the obstacle frame are the same frame",
        },
    }))
}
