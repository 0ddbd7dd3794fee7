//! Files the simulator writes (and reads back): frames as PNG and EXR, plots, scene exports
//! (glTF, OBJ, Mitsuba), all written atomically.

pub mod animation;
pub mod atomic;
pub mod display_map;
pub mod export;
pub mod frame_files;
pub mod plot;
pub mod run_dir;
pub mod staged;
