//! Scene text → parser and validation → world → BVH: no panic, no hang, one-line errors.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::render::integrator::RenderContext;
use seethru::scene::Scene;
use seethru::scene::source::SourceFile;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // Assets resolve against a folder with no files, so meshes and textures are "not found".
    let file = SourceFile::from_text(Path::new("fuzz-scenes/scene.toml"), text.to_string());
    match Scene::from_source(&file) {
        Ok(scene) => {
            if let Err(e) = RenderContext::new(scene) {
                assert!(!format!("{e:#}").contains('\n'), "{e:#}");
            }
        }
        Err(e) => assert!(!e.to_string().contains('\n'), "{e}"),
    }
});
