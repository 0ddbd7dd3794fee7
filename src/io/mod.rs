//! Files the simulator writes (and reads back): frames as PNG and EXR, plots, scene exports
//! (glTF, OBJ, Mitsuba), all written atomically.

pub mod atomic;
pub mod export;
pub mod export_scene;
pub mod frame_files;
pub mod gltf_export;
pub mod mitsuba_export;
pub mod obj_export;
pub mod plot;
