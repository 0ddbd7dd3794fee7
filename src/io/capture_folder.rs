//! The record of how a capture folder (`seethru capture`, `Capture.save` in Python) was
//! made, read back as `score` needs it: `capture.json`'s fingerprint and
//! `truth/capture_spec.json`'s specification (the scene and calibration files, the depth
//! sensor's map or not, and the run options, written whole by the library, not as a
//! command line). The run options stay JSON here: `system::options::RunOptions` reads them.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde_json::{Value, json};

use crate::io::display_map::fingerprint_text;
use crate::io::run_dir::MAX_RUN_JSON_BYTES;
use crate::util::input_file::read_input_text;
use crate::util::message::printable;

/// The manifest, at the top of a capture folder; written last, so its presence marks a
/// finished capture.
pub const MANIFEST_FILE: &str = "capture.json";
/// The capture's specification, under `truth/` (a method never reads it).
pub const SPEC_FILE: &str = "capture_spec.json";

/// What a capture is made from: enough to make it again, bit for bit.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureSpec {
    /// The scene file, an absolute path.
    pub scene: PathBuf,
    /// The calibration file read over the scene's `[calibration]`, an absolute path.
    pub calibration: Option<PathBuf>,
    /// Whether the depth sensor's map is captured.
    pub depth: bool,
    /// The run options (`RunOptions` as JSON, every field).
    pub run_options: Value,
}

/// What a capture folder says about its own making.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureRecord {
    /// The capture's fingerprint, 16 hex digits (`system::capture::fingerprint`).
    pub fingerprint: String,
    pub spec: CaptureSpec,
}

/// The text of `truth/capture_spec.json`; [`parse_capture_record`] reads it back.
pub fn spec_json(spec: &CaptureSpec) -> Value {
    json!({
        "scene": spec.scene.display().to_string(),
        "calibration": spec.calibration.as_ref().map(|c| c.display().to_string()),
        "depth": spec.depth,
        "run_options": spec.run_options,
        "note": "seethru score captures again from this specification and checks the fingerprint",
    })
}

/// `truth/capture_spec.json` of the folder `inputs`.
pub fn spec_path(inputs: &Path) -> PathBuf {
    inputs.join("truth").join(SPEC_FILE)
}

/// The record of the capture folder `inputs`; errors name the file and are one line.
pub fn read_capture_record(inputs: &Path) -> Result<CaptureRecord> {
    let read = |path: PathBuf| -> Result<(PathBuf, String)> {
        // A capture's JSON is small; a FIFO or a device in its place would block the read.
        let text = read_input_text(&path, MAX_RUN_JSON_BYTES).with_context(|| {
            format!(
                "cannot read {} (is {} a folder written by seethru capture?)",
                path.display(),
                inputs.display()
            )
        })?;
        Ok((path, text))
    };
    let (manifest_path, manifest) = read(inputs.join(MANIFEST_FILE))?;
    let (spec_path, spec) = read(spec_path(inputs))?;
    parse_capture_record(&manifest_path, &manifest, &spec_path, &spec)
}

/// The record from the texts of the manifest and the specification (`*_path` name them in
/// errors). Every field is required and typed: a default would capture something else and
/// fail only at the fingerprint.
pub fn parse_capture_record(
    manifest_path: &Path,
    manifest_text: &str,
    spec_path: &Path,
    spec_text: &str,
) -> Result<CaptureRecord> {
    let json = |path: &Path, text: &str| -> Result<Value> {
        serde_json::from_str(text).with_context(|| format!("{}: not JSON", path.display()))
    };
    let manifest = json(manifest_path, manifest_text)?;
    let spec = json(spec_path, spec_text)?;
    let fingerprint = match manifest.get("fingerprint") {
        Some(Value::String(s)) => fingerprint_text(s)
            .map_err(|e| anyhow::anyhow!("{}: fingerprint: {e}", manifest_path.display()))?,
        Some(other) => bail!(
            "{}: fingerprint must be a string of 16 hex digits, got {}",
            manifest_path.display(),
            shown(other)
        ),
        None => bail!("{}: no key fingerprint", manifest_path.display()),
    };
    // A file: an absolute path, or null where `optional` (no calibration file).
    let file = |key: &str, what: &str, optional: bool| -> Result<Option<PathBuf>> {
        match spec.get(key) {
            Some(Value::String(s)) if Path::new(s).is_absolute() => Ok(Some(PathBuf::from(s))),
            Some(Value::Null) if optional => Ok(None),
            Some(other) => bail!(
                "{}: {key} must be {what} (an absolute path{}), got {}",
                spec_path.display(),
                if optional { " or null" } else { "" },
                shown(other)
            ),
            None => bail!("{}: no key {key} ({what})", spec_path.display()),
        }
    };
    let scene = file("scene", "the scene file", false)?
        .with_context(|| format!("{}: no scene file", spec_path.display()))?;
    let calibration = file("calibration", "the calibration file", true)?;
    let depth = match spec.get("depth") {
        Some(Value::Bool(b)) => *b,
        Some(other) => bail!(
            "{}: depth must be true or false, got {}",
            spec_path.display(),
            shown(other)
        ),
        None => bail!(
            "{}: no key depth (whether the depth map is captured)",
            spec_path.display()
        ),
    };
    let run_options = match spec.get("run_options") {
        Some(v @ Value::Object(_)) => v.clone(),
        Some(other) => bail!(
            "{}: run_options must be an object (the run's options), got {}",
            spec_path.display(),
            shown(other)
        ),
        None => bail!("{}: no key run_options", spec_path.display()),
    };
    Ok(CaptureRecord {
        fingerprint,
        spec: CaptureSpec {
            scene,
            calibration,
            depth,
            run_options,
        },
    })
}

/// A JSON value as it may appear in one line of a message: escaped and clipped.
fn shown(value: &Value) -> String {
    let text = printable(&value.to_string());
    match text.char_indices().nth(60) {
        Some((cut, _)) => format!("{}…", &text[..cut]),
        None => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(manifest: &str, spec: &str) -> Result<CaptureRecord> {
        parse_capture_record(
            Path::new("c/capture.json"),
            manifest,
            Path::new("c/truth/capture_spec.json"),
            spec,
        )
    }

    const MANIFEST: &str = r#"{"fingerprint": "0123456789abcdef"}"#;
    const SPEC: &str =
        r#"{"scene": "/w/s.toml", "calibration": null, "depth": true, "run_options": {"spp": 1}}"#;

    #[test]
    fn a_record_reads_back_its_fields() {
        let r = parse(MANIFEST, SPEC).unwrap();
        assert_eq!(r.fingerprint, "0123456789abcdef");
        assert_eq!(r.spec.scene, PathBuf::from("/w/s.toml"));
        assert_eq!(r.spec.calibration, None);
        assert!(r.spec.depth);
        assert_eq!(r.spec.run_options, json!({"spp": 1}));
    }

    #[test]
    fn the_written_spec_reads_back_as_written() {
        let spec = CaptureSpec {
            scene: PathBuf::from("/w d/ü\n.toml"),
            calibration: Some(PathBuf::from("/c.toml")),
            depth: false,
            run_options: json!({"method": "planar", "d2": "inf"}),
        };
        let r = parse(MANIFEST, &spec_json(&spec).to_string()).unwrap();
        assert_eq!(r.spec, spec);
    }

    #[test]
    fn each_missing_or_mistyped_field_is_refused_by_name_in_one_line() {
        let with = |key: &str, value: &str| {
            let mut spec: Value = serde_json::from_str(SPEC).unwrap();
            match value {
                "" => spec.as_object_mut().unwrap().remove(key),
                v => spec
                    .as_object_mut()
                    .unwrap()
                    .insert(key.into(), serde_json::from_str(v).unwrap()),
            };
            spec.to_string()
        };
        for (manifest, spec, names) in [
            (
                "{}".to_string(),
                SPEC.to_string(),
                "c/capture.json: no key fingerprint",
            ),
            (
                r#"{"fingerprint": 7}"#.into(),
                SPEC.into(),
                "capture.json: fingerprint must",
            ),
            (
                r#"{"fingerprint": "12\nab"}"#.into(),
                SPEC.into(),
                "16 hex digits",
            ),
            (
                MANIFEST.into(),
                with("scene", ""),
                "capture_spec.json: no key scene",
            ),
            (
                MANIFEST.into(),
                with("scene", r#""s.toml""#),
                "scene must be the scene file (an absolute path)",
            ),
            (
                MANIFEST.into(),
                with("calibration", "3"),
                "calibration must be the calibration file (an absolute path or null)",
            ),
            (
                MANIFEST.into(),
                with("calibration", ""),
                "no key calibration",
            ),
            (
                MANIFEST.into(),
                with("depth", r#""yes""#),
                "depth must be true or false",
            ),
            (MANIFEST.into(), with("depth", ""), "no key depth"),
            (
                MANIFEST.into(),
                with("run_options", "[]"),
                "run_options must be an object",
            ),
            (
                MANIFEST.into(),
                with("run_options", ""),
                "no key run_options",
            ),
            ("[".into(), SPEC.into(), "c/capture.json: not JSON"),
            (
                MANIFEST.into(),
                "nope".into(),
                "capture_spec.json: not JSON",
            ),
        ] {
            let e = format!("{:#}", parse(&manifest, &spec).unwrap_err());
            assert!(e.contains(names), "{e} (wanted {names})");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn a_long_value_with_a_line_break_is_shown_escaped_and_clipped() {
        let long = format!(
            r#"{{"scene": "/s", "calibration": null, "depth": {{"a": "x\ny{}"}}, "run_options": {{}}}}"#,
            "z".repeat(500)
        );
        let e = format!("{:#}", parse(MANIFEST, &long).unwrap_err());
        assert!(
            !e.contains('\n') && e.len() < 200 && e.ends_with('…'),
            "{e}"
        );
    }
}
