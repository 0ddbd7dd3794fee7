//! Scenes lit in physical units and their EXRs, for the tests of light and sensors.

use std::collections::HashMap;
use std::path::Path;

use exr::prelude::{FlatSamples, read_all_flat_layers_from_file};

/// The sun of the lit-wall scenes, lux: white, 60° high behind the cameras (the obstacle's
/// shadow falls below the wall), no sky and a black ground.
pub const WALL_SUN_LUX: f64 = 50_000.0;

/// A grey wall (sRGB 0.6) 20 m ahead of the driver and the display, lit by the sun of
/// [`WALL_SUN_LUX`]: a flat field of luminance ρE cos 60°/π. `obstacle` holds keys added to
/// that table, `frontal` the frontal camera's keys (its resolution at least).
pub fn lit_wall_scene(white: f64, obstacle: &str, frontal: &str) -> String {
    format!(
        r#"[sun]
illuminance_lux = {WALL_SUN_LUX}
color = [1.0, 1.0, 1.0]
elevation_deg = 60
azimuth_deg = 180
[sky]
zenith_luminance_cd_m2 = 0
ground_color = [0.0, 0.0, 0.0]
cloud_cover = 0
[photometry]
white_cd_m2 = {white}

[obstacle]
center = [0.0, 1.2, -0.8]
width = 0.3
height = 0.4
{obstacle}

[camera.driver]
position = [0.0, 1.2, 0.0]
look_at = [0.0, 1.2, -10.0]
half_angle_deg = 20.0
resolution = [64, 36]

[camera.frontal]
{frontal}

[camera.back]
resolution = [16, 12]

[[material]]
name = "grey"
color = [0.6, 0.6, 0.6]

[[object]]
name = "wall"
kind = "quad"
material = "grey"
size = [200.0, 200.0]
translate = [0.0, 0.0, -20.0]
"#
    )
}

/// Runs `seethru <command> scene.toml <flags> --spp 1 --quiet --out out` on `scene` (text)
/// in `dir` (`--spp 1` unless `flags` give one), and returns `out`.
pub fn seethru_on(dir: &Path, scene: &str, command: &str, flags: &[&str]) -> std::path::PathBuf {
    let file = dir.join("scene.toml");
    std::fs::write(&file, scene).unwrap();
    let out = dir.join("out");
    let _ = std::fs::remove_dir_all(&out);
    let mut args = vec![command, file.to_str().unwrap()];
    args.extend_from_slice(flags);
    if !flags.contains(&"--spp") {
        args.extend(["--spp", "1"]);
    }
    args.extend(["--quiet", "--out", out.to_str().unwrap()]);
    let (ok, _, stderr) = super::seethru(&args);
    assert!(ok, "{stderr}");
    out
}

/// Every channel of an EXR, read with the exr crate alone, as f64.
pub fn exr_channels(path: &Path) -> HashMap<String, Vec<f64>> {
    let image = read_all_flat_layers_from_file(path).unwrap();
    (image.layer_data[0].channel_data.list.iter())
        .map(|c| {
            let values = match &c.sample_data {
                FlatSamples::F32(v) => v.iter().map(|&x| f64::from(x)).collect(),
                FlatSamples::U32(v) => v.iter().map(|&x| f64::from(x)).collect(),
                FlatSamples::F16(v) => v.iter().map(|&x| f64::from(x.to_f32())).collect(),
            };
            (c.name.to_string(), values)
        })
        .collect()
}

/// Per pixel, Y = 0.2126 R + 0.7152 G + 0.0722 B of an EXR's channels.
pub fn luminance(channels: &HashMap<String, Vec<f64>>) -> Vec<f64> {
    let [r, g, b] = ["R", "G", "B"].map(|c| &channels[c]);
    (0..r.len())
        .map(|i| 0.2126 * r[i] + 0.7152 * g[i] + 0.0722 * b[i])
        .collect()
}
