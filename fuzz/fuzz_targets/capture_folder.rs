//! A capture folder's record (`capture.json` and `truth/capture_command.json`, split at the
//! first NUL byte) → `parse_capture_record` (`seethru score`): no panic; an error is one line
//! naming its file; a record read back is written again as `capture` writes it and reads back
//! the same.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::io::capture_folder::{command_json, parse_capture_record};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (manifest, command) = text.split_once('\0').unwrap_or((text, ""));
    let [manifest_path, command_path] =
        [Path::new("c/capture.json"), Path::new("c/truth/capture_command.json")];
    match parse_capture_record(manifest_path, manifest, command_path, command) {
        Ok(record) => {
            assert_eq!(record.fingerprint.len(), 16);
            let written = command_json(&record.cwd, &record.args).to_string();
            let again = parse_capture_record(manifest_path, manifest, command_path, &written)
                .expect("a written command reads back");
            assert_eq!(again, record);
        }
        Err(e) => {
            let shown = format!("{e:#}");
            assert!(
                shown.starts_with("c/capture.json") || shown.starts_with("c/truth/capture_command.json"),
                "{shown}"
            );
            assert!(!shown.contains('\n'), "{shown}");
        }
    }
});
