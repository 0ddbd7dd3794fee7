//! A capture folder, written and made again: what `seethru capture` writes (the inputs a
//! method reads at the top, the truth and the capture's specification in `truth/`) and what
//! `seethru score` and Python's `seethru.load_capture` read back: the capture made again
//! from its specification, its fingerprint checked against the folder's.

use std::path::Path;

use anyhow::{Context, Result, bail};
use exr::prelude::{AnyChannel, FlatSamples};
use serde_json::json;

use crate::io::atomic::write_text;
use crate::io::capture_folder::{
    CaptureSpec, MANIFEST_FILE, SPEC_FILE, read_capture_record, spec_json, spec_path,
};
use crate::io::display_map::write_npy_f32;
use crate::io::frame_files::{
    ExrContent, layer_attributes, write_color_png, write_exr_channels, write_exr_channels_with,
    write_view_exr,
};
use crate::render::frame::Frame;
use crate::render::integrator::RenderContext;
use crate::scene::Scene;
use crate::scene::lens_keys::read_calibration_file;
use crate::system::capture::{Capture, capture};
use crate::system::options::RunOptions;

/// The specification of a capture of the scene file `scene` (with the calibration file
/// `calibration` over its `[calibration]`) under `options`, `depth` whether the depth map is
/// captured: the files made absolute, so that `score` may run from anywhere.
pub fn capture_spec(
    scene: &Path,
    calibration: Option<&Path>,
    depth: bool,
    options: &RunOptions,
) -> Result<CaptureSpec> {
    let absolute = |p: &Path| std::path::absolute(p).with_context(|| format!("{}", p.display()));
    Ok(CaptureSpec {
        scene: absolute(scene)?,
        calibration: calibration.map(absolute).transpose()?,
        depth,
        run_options: serde_json::to_value(options)?,
    })
}

/// The scene of a specification: its file, with its calibration file over `[calibration]`.
pub fn spec_scene(spec: &CaptureSpec) -> Result<Scene> {
    let mut scene = Scene::load(&spec.scene)?;
    if let Some(path) = &spec.calibration {
        scene.calibration = read_calibration_file(path, &scene.frontal, &scene.back)?;
    }
    Ok(scene)
}

/// A capture folder's capture made again in memory, with its options and context.
pub struct Recaptured {
    pub options: RunOptions,
    pub ctx: RenderContext,
    pub capture: Capture,
}

/// Reads the capture folder `inputs`' specification, captures again and checks that the
/// result is the folder's capture (its fingerprint).
pub fn recapture(inputs: &Path) -> Result<Recaptured> {
    let record = read_capture_record(inputs)?;
    let spec = &record.spec;
    let options: RunOptions = serde_json::from_value(spec.run_options.clone())
        .with_context(|| format!("{}: run_options", spec_path(inputs).display()))?;
    let again = || -> Result<(RenderContext, Capture)> {
        let ctx = RenderContext::new(spec_scene(spec)?)?;
        let capture = capture(&ctx, &options, spec.depth)?;
        Ok((ctx, capture))
    };
    let (ctx, capture) =
        again().with_context(|| format!("{}: capturing again", spec_path(inputs).display()))?;
    if capture.fingerprint != record.fingerprint {
        bail!(
            "{}: captured again, the inputs' fingerprint is {} but the folder's is {}: the scene, its assets or seethru changed since the capture; capture again",
            inputs.display(),
            capture.fingerprint,
            record.fingerprint
        );
    }
    Ok(Recaptured {
        options,
        ctx,
        capture,
    })
}

/// [`write_capture_folder`] with the capture's specification in `truth/`: a folder `score`
/// reads.
pub fn write_scoreable_capture(
    out: &Path,
    c: &Capture,
    spec: &CaptureSpec,
    exr: ExrContent,
) -> Result<()> {
    write_capture_folder(out, c, (SPEC_FILE, &spec_json(spec)), exr)
}

/// depth.npy's axial depth, metres, of the sensor's inverse depth `inverse` (1/m): NaN where
/// the sensor has no return (0: sky, past its range), not the infinity 1/0 would give.
pub fn axial_depth(inverse: f32) -> f32 {
    if inverse > 0.0 {
        1.0 / inverse
    } else {
        f32::NAN
    }
}

/// Only the colour of a frame (the rest of its AOVs is the renderer's truth), in cd/m² where
/// its light is in physical units.
fn write_colour_exr(frame: &Frame, path: &Path) -> Result<()> {
    let scale = frame.white_cd_m2.unwrap_or(1.0);
    let channels = ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(k, name)| {
            AnyChannel::new(
                *name,
                FlatSamples::F32(frame.color.iter().map(|c| c[k] * scale).collect()),
            )
        })
        .collect();
    let attributes = layer_attributes(frame.white_cd_m2);
    write_exr_channels_with(path, frame.width, frame.height, channels, attributes)
}

/// The capture's files into `out` (a staging folder): inputs at the top, the truth apart,
/// with `how` (a file name under `truth/` and its JSON: the capture's specification, or the
/// sequence that captured it); `exr` says which EXRs (`seethru capture --exr`).
pub fn write_capture_folder(
    out: &Path,
    c: &Capture,
    how: (&str, &serde_json::Value),
    exr: ExrContent,
) -> Result<()> {
    let mut files = Vec::new();
    for (name, frame) in [("frontal", &c.frontal), ("back", &c.back)] {
        write_color_png(frame, &out.join(format!("{name}.png")))?;
        files.push(format!("{name}.png"));
        if exr != ExrContent::None {
            write_colour_exr(frame, &out.join(format!("{name}.exr")))?;
            files.push(format!("{name}.exr"));
        }
    }
    files.extend(["head.json".to_string(), "calibration.json".to_string()]);
    if let Some(d) = &c.depth {
        let depth: Vec<f32> = d.inverse_depth.iter().map(|&v| axial_depth(v)).collect();
        let [w, h] = [d.camera.width, d.camera.height];
        write_npy_f32(&out.join("depth.npy"), &[h as usize, w as usize], &depth)?;
        // depth.exr is no colour: only `--exr lean` and `all` write it (depth.npy holds the
        // same).
        if matches!(exr, ExrContent::Lean | ExrContent::All) {
            write_exr_channels(
                &out.join("depth.exr"),
                w,
                h,
                vec![
                    AnyChannel::new("Z", FlatSamples::F32(depth)),
                    AnyChannel::new("inverse_depth", FlatSamples::F32(d.inverse_depth.clone())),
                ],
            )?;
        }
    }
    write_text(
        &out.join("head.json"),
        &serde_json::to_string_pretty(&json!({
            "head": c.head,
            "conventions": "eye_world_m: seethru's world frame; eye_obstacle_m: the obstacle (display) frame of calibration.json; detection: back-camera pixels, seethru's continuous convention (OpenCV's + 0.5)",
        }))?,
    )?;
    write_text(
        &out.join("calibration.json"),
        &serde_json::to_string_pretty(&c.calibration)?,
    )?;
    let truth = out.join("truth");
    write_view_exr(&c.truth.truth, &truth.join("truth.exr"), exr)?;
    write_color_png(&c.truth.truth, &truth.join("truth.png"))?;
    write_text(
        &truth.join("truth.json"),
        &serde_json::to_string_pretty(&json!({
            "eye_world_m": c.truth.eye_world_m.to_array(),
            "cameras": c.truth.cameras,
            "note": "a method must not read this folder",
        }))?,
    )?;
    write_text(&truth.join(how.0), &serde_json::to_string_pretty(how.1)?)?;
    // Last: a folder with capture.json holds a finished capture.
    write_text(
        &out.join(MANIFEST_FILE),
        &serde_json::to_string_pretty(&json!({
            "fingerprint": c.fingerprint,
            "display_resolution_px": [c.calibration["display"]["resolution_px"][0], c.calibration["display"]["resolution_px"][1]],
            "frontal_size_px": [c.frontal.width, c.frontal.height],
            "back_size_px": [c.back.width, c.back.height],
            "depth": c.depth.as_ref().map(|d| json!({"file": "depth.npy", "size_px": [d.camera.width, d.camera.height], "sensor": d.model, "units": "axial depth along the frontal camera's axis, metres, float32, shape (height, width); NaN: no return"})),
            "files": files,
            "exposure": {"frontal": crate::system::report::exposure_json(&c.frontal), "back": crate::system::report::exposure_json(&c.back)},
            "images": "frontal.png and back.png: a camera's image as sRGB of its linear light, or, for a camera with a tone curve, its codes (8 bits; 10 and 12 bits in 16-bit PNGs, each code × 65535 / its top code); the EXRs: cd/m² in a photometric scene, decoded from the codes where there are codes",
            "map_format": "a display map: .npy float32 of shape (display height, display width, 2), [..., 0] = x and [..., 1] = y frontal pixels in OpenCV's remap convention (pixel centres at integers), NaN shows nothing; or EXR with channels x, y. State the capture it was made for in <map>.json: {\"capture_fingerprint\": \"...\"}",
            "truth": "truth/ holds the truth view and the true eye: a method must not read it",
        }))?,
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_return_is_nan_and_a_return_its_distance() {
        assert!(axial_depth(0.0).is_nan());
        assert_eq!(axial_depth(0.5), 2.0);
        assert_eq!(axial_depth(4.0), 0.25);
    }
}
