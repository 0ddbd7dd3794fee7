//! A display map (`score --map`, `compare --methods map:NAME=FILE`), .npy or .exr, → the
//! map, then the checks `score` makes against its capture: no panic, no runaway
//! allocation; an error is one line.
#![no_main]

use libfuzzer_sys::fuzz_target;
use seethru::io::display_map::{parse_exr_map, parse_npy};
use seethru::system::capture::{DisplayMap, check_display_input};

fuzz_target!(|data: &[u8]| {
    // EXR files start with its magic number; everything else is read as .npy.
    let read = if data.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        parse_exr_map(data)
    } else {
        parse_npy(data)
    };
    let map = match read {
        Ok(m) => m,
        Err(e) => {
            let shown = format!("{e:#}");
            assert!(!shown.contains('\n'), "{shown}");
            return;
        }
    };
    assert_eq!(map.xy.len(), map.width as usize * map.height as usize);
    let map = DisplayMap {
        width: map.width,
        height: map.height,
        xy: map.xy,
        fingerprint: map.fingerprint,
    };
    if let Err(e) = check_display_input(
        [map.width, map.height],
        Some([64, 36]),
        "0123456789abcdef",
        Some(&map),
        None,
    ) {
        let shown = format!("{e:#}");
        assert!(!shown.contains('\n'), "{shown}");
    }
});
