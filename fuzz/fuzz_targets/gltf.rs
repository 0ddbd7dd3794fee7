//! glTF JSON or GLB bytes → triangles: no panic, no hang (node cycles), one-line errors.
//! External buffers do not exist; GLB chunks and data: URIs do.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::scene::mesh_io::parse_gltf;

fuzz_target!(|data: &[u8]| {
    let read = |_: &Path| Err(std::io::ErrorKind::NotFound.into());
    if let Err(e) = parse_gltf(data, Path::new("mesh.glb"), &read) {
        assert!(!format!("{e:#}").contains('\n'), "{e:#}");
    }
});
