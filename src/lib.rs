//! seethru: a ray-traced simulator of video see-through displays for driver assistance.
#![forbid(unsafe_code)]

pub mod accel;
pub mod analysis;
pub mod bench;
pub mod camera;
pub mod claims;
pub mod color;
pub mod commands;
pub mod compensation;
pub mod display;
pub mod export;
pub mod figures;
pub mod frame;
pub mod head;
pub mod mesh_io;
pub mod metrics;
pub mod options;
pub mod output;
pub mod pipeline;
pub mod procedural;
pub mod progress;
pub mod ratio;
pub mod render;
pub mod reproduce;
pub mod sampling;
pub mod scene;
pub mod scene_file;
pub mod shapes;
pub mod sky;
pub mod sweep;
pub mod texture;
pub mod views;
pub mod world;
