//! Reading a `run` directory back: its run.json and the driver-view frames the metrics need.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use crate::io::frame_files::read_exr;
use crate::render::frame::Frame;
use crate::scene::limits::MAX_COORDINATE;
use crate::util::input_file::read_input_text;
use crate::util::number::{clip_long_numbers, short_list};

/// What `measure` needs of a run.json.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRecord {
    /// The scene file the run rendered, as the run was given it (relative to the folder the
    /// run was started in).
    pub scene: PathBuf,
    /// The same, absolute (`scene_absolute`; `None` in run.json files older than it).
    pub scene_absolute: Option<PathBuf>,
    /// The content hash of the scene file when the run read it (`scene_hash`, as
    /// `util::hash::content_hash`; `None` in older run.json files).
    pub scene_hash: Option<String>,
    /// The eye the driver views were rendered from, world, metres (`eyes.view_world_m`;
    /// `None` in run.json files that predate two eyes: the scene's driver camera).
    pub view_eye: Option<[f64; 3]>,
}

/// The views the metrics compare, in the order `measure` takes them.
pub const MEASURED_VIEWS: [&str; 3] = ["truth", "seethru", "occluded"];

/// Parses the text of a run.json; errors say what is wrong (the caller names the file).
pub fn parse_run_json(text: &str) -> Result<RunRecord> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| anyhow::anyhow!("invalid JSON: {e}"))?;
    let object = value
        .as_object()
        .context("expected a JSON object, as `seethru run` writes")?;
    let scene = match object.get("scene") {
        Some(serde_json::Value::String(s)) if !s.is_empty() => s,
        Some(other) => bail!("`scene` must be the path of the scene file, got {other}"),
        None => bail!("no `scene` (the path of the scene file the run rendered)"),
    };
    let view_eye = match object.get("eyes").and_then(|e| e.get("view_world_m")) {
        None => None,
        Some(v) => {
            let range = "`eyes.view_world_m` must be 3 numbers in [-1e6, 1e6] m (the world)";
            let p = serde_json::from_value::<[f64; 3]>(v.clone())
                .ok()
                .with_context(|| format!("{range}, got {}", clip_long_numbers(&v.to_string())))?;
            if p.iter().any(|c| c.is_nan() || c.abs() > MAX_COORDINATE) {
                bail!("{range}, got {}", short_list(&p));
            }
            Some(p)
        }
    };
    let optional_text = |key: &str| -> Result<Option<String>> {
        match object.get(key) {
            None | Some(serde_json::Value::Null) => Ok(None),
            Some(serde_json::Value::String(s)) if !s.is_empty() => Ok(Some(s.clone())),
            Some(other) => bail!("`{key}` must be a non-empty string, got {other}"),
        }
    };
    Ok(RunRecord {
        scene: PathBuf::from(scene),
        scene_absolute: optional_text("scene_absolute")?.map(PathBuf::from),
        scene_hash: optional_text("scene_hash")?,
        view_eye,
    })
}

/// Largest run.json read (seethru writes a few KiB).
pub const MAX_RUN_JSON_BYTES: u64 = 16 << 20;

/// Reads `dir/run.json`; errors name that file.
pub fn read_run_json(dir: &Path) -> Result<RunRecord> {
    let path = dir.join("run.json");
    let text = read_input_text(&path, MAX_RUN_JSON_BYTES).with_context(|| {
        format!(
            "cannot read {} (not a `seethru run` directory?)",
            path.display()
        )
    })?;
    parse_run_json(&text).with_context(|| format!("{}", path.display()))
}

/// The EXR files of the measured views in `dir`.
pub fn measured_exrs(dir: &Path) -> [PathBuf; 3] {
    MEASURED_VIEWS.map(|v| dir.join(format!("{v}.exr")))
}

/// Reads truth, seethru and occluded from `dir`; they must have the same size.
pub fn read_measured_frames(dir: &Path) -> Result<[Frame; 3]> {
    let [truth, seethru, occluded] = measured_exrs(dir);
    // A run written with `--exr lean`, `colour` or `none` lacks AOVs to measure: say which option.
    let read = |path: &Path| {
        read_exr(path).map_err(|e| {
            let why = format!("{e:#}");
            match !path.exists() || why.contains("no channel") {
                true => anyhow::anyhow!(
                    "{why}; the metrics need every AOV of truth, seethru and occluded: write the run with option `exr` all (`run` writes `lean` by default: no `P`)"
                ),
                false => e,
            }
        })
    };
    let frames = [read(&truth)?, read(&seethru)?, read(&occluded)?];
    let size = |f: &Frame| (f.width, f.height);
    for (frame, path) in frames.iter().zip([&truth, &seethru, &occluded]).skip(1) {
        if size(frame) != size(&frames[0]) {
            bail!(
                "{} is {}×{} but {} is {}×{}: the views of one run have one size",
                path.display(),
                frame.width,
                frame.height,
                truth.display(),
                frames[0].width,
                frames[0].height
            );
        }
    }
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_json_needs_a_scene_path() {
        let ok = parse_run_json(r#"{"scene": "scenes/das.toml", "x": 1}"#).unwrap();
        assert_eq!(ok.scene, PathBuf::from("scenes/das.toml"));
        assert_eq!(ok.view_eye, None);
        let eye = parse_run_json(r#"{"scene": "s.toml", "eyes": {"view_world_m": [1, 2.5, 3]}}"#);
        assert_eq!(eye.unwrap().view_eye, Some([1.0, 2.5, 3.0]));
        for (text, words) in [
            (
                r#"{"scene": "s.toml", "eyes": {"view_world_m": [1, 2]}}"#,
                "must be 3 numbers in [-1e6, 1e6] m",
            ),
            (
                r#"{"scene": "s.toml", "eyes": {"view_world_m": [1e300, 1.2, 0]}}"#,
                "must be 3 numbers in [-1e6, 1e6] m (the world), got [1e300, 1.2, 0]",
            ),
            (
                r#"{"scene": "s.toml", "scene_hash": 3}"#,
                "`scene_hash` must be",
            ),
            ("", "invalid JSON"),
            ("[1]", "expected a JSON object"),
            ("{}", "no `scene`"),
            (r#"{"scene": 3}"#, "must be the path"),
            (r#"{"scene": ""}"#, "must be the path"),
        ] {
            let err = format!("{:#}", parse_run_json(text).unwrap_err());
            assert!(err.contains(words), "{text}: {err}");
            assert!(!err.contains('\n'), "{err}");
        }
    }
}
