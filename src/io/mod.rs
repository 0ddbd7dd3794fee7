//! Files the simulator writes (and reads back): frames as PNG and EXR, plots, scene exports
//! (glTF, OBJ, Mitsuba), all written atomically.

pub mod animation;
pub mod atomic;
pub mod caption;
pub mod capture_folder;
pub mod colour_bar;
pub mod display_map;
pub mod export;
pub mod exr_zip;
pub mod frame_files;
pub mod junit;
pub mod output_paths;
pub mod plot;
pub mod run_dir;
pub mod staged;
