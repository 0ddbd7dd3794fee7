//! The record of how a capture folder (`seethru capture`) was made, read back as `score`
//! needs it: `capture.json`'s fingerprint and `truth/capture_command.json`'s flags and
//! working folder. The flags themselves are the command line's to parse.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde_json::Value;

use crate::io::display_map::fingerprint_text;
use crate::io::run_dir::MAX_RUN_JSON_BYTES;
use crate::util::input_file::read_input_text;
use crate::util::message::printable;

/// The manifest, at the top of a capture folder; written last, so its presence marks a
/// finished capture.
pub const MANIFEST_FILE: &str = "capture.json";
/// The capture's command line, under `truth/` (a method never reads it).
pub const COMMAND_FILE: &str = "capture_command.json";

/// What a capture folder says about its own making.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureRecord {
    /// The capture's fingerprint, 16 hex digits (`system::capture::fingerprint`).
    pub fingerprint: String,
    /// The folder the capture ran in: relative paths among `args` are relative to it.
    pub cwd: PathBuf,
    /// The flags given to `seethru capture`, in order, `--quiet` left out.
    pub args: Vec<String>,
}

/// The text of `truth/capture_command.json` for a capture run in `cwd` with the flags `args`
/// (`--quiet` left out by the caller); [`parse_capture_record`] reads it back.
pub fn command_json(cwd: &Path, args: &[String]) -> Value {
    serde_json::json!({
        "cwd": cwd.display().to_string(),
        "args": args,
        "note": "seethru score parses these flags again (relative paths from cwd) and captures again, checking the fingerprint",
    })
}

/// `truth/capture_command.json` of the folder `inputs`.
pub fn command_path(inputs: &Path) -> PathBuf {
    inputs.join("truth").join(COMMAND_FILE)
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
    let (command_path, command) = read(command_path(inputs))?;
    parse_capture_record(&manifest_path, &manifest, &command_path, &command)
}

/// The record from the texts of the manifest and the command file (`*_path` name them in
/// errors). Every field is required and typed: a missing `cwd` or a non-string flag is an
/// error, not a default, since either would capture something else and fail only at the
/// fingerprint.
pub fn parse_capture_record(
    manifest_path: &Path,
    manifest_text: &str,
    command_path: &Path,
    command_text: &str,
) -> Result<CaptureRecord> {
    let json = |path: &Path, text: &str| -> Result<Value> {
        serde_json::from_str(text).with_context(|| format!("{}: not JSON", path.display()))
    };
    let manifest = json(manifest_path, manifest_text)?;
    let command = json(command_path, command_text)?;
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
    let cwd = match command.get("cwd") {
        Some(Value::String(s)) if !s.is_empty() => PathBuf::from(s),
        Some(other) => bail!(
            "{}: cwd must be the capture's working folder (a non-empty string), got {}",
            command_path.display(),
            shown(other)
        ),
        None => bail!(
            "{}: no key cwd (the folder the capture ran in)",
            command_path.display()
        ),
    };
    let args = match command.get("args") {
        Some(Value::Array(items)) => items
            .iter()
            .enumerate()
            .map(|(k, a)| match a {
                Value::String(s) => Ok(s.clone()),
                other => bail!(
                    "{}: args[{k}] must be a string (a flag of seethru capture), got {}",
                    command_path.display(),
                    shown(other)
                ),
            })
            .collect::<Result<Vec<_>>>()?,
        Some(other) => bail!(
            "{}: args must be a list of strings (the flags of seethru capture), got {}",
            command_path.display(),
            shown(other)
        ),
        None => bail!(
            "{}: no key args (the flags of seethru capture)",
            command_path.display()
        ),
    };
    Ok(CaptureRecord {
        fingerprint,
        cwd,
        args,
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

    fn parse(manifest: &str, command: &str) -> Result<CaptureRecord> {
        parse_capture_record(
            Path::new("c/capture.json"),
            manifest,
            Path::new("c/truth/capture_command.json"),
            command,
        )
    }

    const MANIFEST: &str = r#"{"fingerprint": "0123456789abcdef"}"#;

    #[test]
    fn a_record_reads_back_its_fields_in_order() {
        let r = parse(
            MANIFEST,
            r#"{"cwd": "/w", "args": ["s.toml", "--width", "8"]}"#,
        )
        .unwrap();
        assert_eq!(r.fingerprint, "0123456789abcdef");
        assert_eq!(r.cwd, PathBuf::from("/w"));
        assert_eq!(r.args, ["s.toml", "--width", "8"]);
    }

    #[test]
    fn the_written_command_reads_back_as_written() {
        let args: Vec<String> = ["s.toml", "--eye", "-0.1,0,0", "ü\n"]
            .map(Into::into)
            .into();
        let command = command_json(Path::new("/w d"), &args).to_string();
        let r = parse(MANIFEST, &command).unwrap();
        assert_eq!((r.cwd, r.args), (PathBuf::from("/w d"), args));
    }

    #[test]
    fn each_missing_or_mistyped_field_is_refused_by_name_in_one_line() {
        let command = r#"{"cwd": "/w", "args": []}"#;
        for (manifest, command, names) in [
            ("{}", command, "c/capture.json: no key fingerprint"),
            (
                r#"{"fingerprint": 7}"#,
                command,
                "capture.json: fingerprint must",
            ),
            (r#"{"fingerprint": "12\nab"}"#, command, "16 hex digits"),
            (
                MANIFEST,
                r#"{"args": []}"#,
                "capture_command.json: no key cwd",
            ),
            (MANIFEST, r#"{"cwd": "", "args": []}"#, "cwd must be"),
            (MANIFEST, r#"{"cwd": "/w"}"#, "no key args"),
            (
                MANIFEST,
                r#"{"cwd": "/w", "args": "s"}"#,
                "args must be a list",
            ),
            (
                MANIFEST,
                r#"{"cwd": "/w", "args": ["s", 8]}"#,
                "args[1] must be a string",
            ),
            ("[", command, "c/capture.json: not JSON"),
            (MANIFEST, "nope", "capture_command.json: not JSON"),
        ] {
            let e = format!("{:#}", parse(manifest, command).unwrap_err());
            assert!(e.contains(names), "{e} (wanted {names})");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn a_long_value_with_a_line_break_is_shown_escaped_and_clipped() {
        let long = format!(
            r#"{{"cwd": "/w", "args": [{{"a": "x\ny{}"}}]}}"#,
            "z".repeat(500)
        );
        let e = format!("{:#}", parse(MANIFEST, &long).unwrap_err());
        assert!(
            !e.contains('\n') && e.len() < 200 && e.ends_with('…'),
            "{e}"
        );
    }
}
