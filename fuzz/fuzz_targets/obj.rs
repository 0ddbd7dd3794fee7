//! OBJ + MTL bytes → triangles: no panic, no hang, one-line errors naming what is wrong.
//! The input is the OBJ, then a NUL byte, then the MTL that any `mtllib` line reads.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use seethru::scene::mesh_io::parse_obj;

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[][..]),
    };
    let read = |_: &Path| Ok(mtl.to_vec());
    if let Err(e) = parse_obj(obj, Path::new("mesh.obj"), &read) {
        assert!(!format!("{e:#}").contains('\n'), "{e:#}");
    }
});
