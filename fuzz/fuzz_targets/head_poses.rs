//! `seethru head-poses` on any scene: scene text (after three bytes that choose the pose:
//! yaw, pitch and distance scale within the command's ranges) → the pose grid of one pose at
//! an 8-pixel back camera → its table. No panic, no hang; an error is one line.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::measure::head_poses::{pose_grid, pose_table};
use seethru::scene::Scene;
use seethru::scene::source::SourceFile;

fuzz_target!(|data: &[u8]| {
    let Some((pose, rest)) = data.split_first_chunk::<3>() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    // The ranges `head-poses` accepts: yaw [-89, 89]°, pitch [-45, 45]°, scale [0.5, 2].
    let within = |byte: u8, low: f64, high: f64| low + (high - low) * f64::from(byte) / 255.0;
    let yaw = within(pose[0], -89.0, 89.0);
    let pitch = within(pose[1], -45.0, 45.0);
    let scale = within(pose[2], 0.5, 2.0);
    let file = SourceFile::from_text(Path::new("fuzz-scenes/scene.toml"), text.to_string());
    let scene = match Scene::from_source(&file) {
        Ok(scene) => scene,
        Err(e) => {
            assert!(!e.to_string().contains('\n'), "{e}");
            return;
        }
    };
    match pose_grid(&scene, &[yaw], &[pitch], &[scale], Some(8)) {
        Ok(results) => {
            let table = pose_table(&results);
            assert!(!table.is_empty());
        }
        Err(e) => assert!(!format!("{e:#}").contains('\n'), "{e:#}"),
    }
});
