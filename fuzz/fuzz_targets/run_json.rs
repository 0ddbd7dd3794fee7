//! run.json text → the record `measure` needs: no panic, one-line errors.
#![no_main]

use libfuzzer_sys::fuzz_target;
use seethru::io::run_dir::parse_run_json;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Err(e) = parse_run_json(text) {
        assert!(!format!("{e:#}").contains('\n'), "{e:#}");
    }
});
