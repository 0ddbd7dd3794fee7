//! EXR bytes → a frame, as `measure` reads them: no panic, no runaway allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;
use seethru::io::frame_files::read_exr_from;

fuzz_target!(|data: &[u8]| {
    // A quarter megapixel keeps every decode within libFuzzer's memory limit.
    if let Err(e) = read_exr_from(std::io::Cursor::new(data), 1 << 18) {
        assert!(!format!("{e:#}").contains('\n'), "{e:#}");
    }
});
