//! A capture folder's record (`capture.json` and `truth/capture_spec.json`, split at the
//! first NUL byte) → `parse_capture_record` (`seethru score`, `seethru.load_capture`), then
//! its run options → `RunOptions`: no panic; an error is one line naming its file; a record
//! read back is written again as `capture` writes it and reads back the same.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::io::capture_folder::{parse_capture_record, spec_json};
use seethru::system::options::RunOptions;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (manifest, spec) = text.split_once('\0').unwrap_or((text, ""));
    let [manifest_path, spec_path] =
        [Path::new("c/capture.json"), Path::new("c/truth/capture_spec.json")];
    match parse_capture_record(manifest_path, manifest, spec_path, spec) {
        Ok(record) => {
            assert_eq!(record.fingerprint.len(), 16);
            let written = spec_json(&record.spec).to_string();
            let again = parse_capture_record(manifest_path, manifest, spec_path, &written)
                .expect("a written specification reads back");
            assert_eq!(again, record);
            // The options read back whole or not at all, and write the same again.
            if let Ok(options) = serde_json::from_value::<RunOptions>(record.spec.run_options) {
                let value = serde_json::to_value(&options).expect("options write");
                let back: RunOptions = serde_json::from_value(value).expect("read back");
                assert_eq!(back, options);
            }
        }
        Err(e) => {
            let shown = format!("{e:#}");
            assert!(
                shown.starts_with("c/capture.json") || shown.starts_with("c/truth/capture_spec.json"),
                "{shown}"
            );
            assert!(!shown.contains('\n'), "{shown}");
        }
    }
});
