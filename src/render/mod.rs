//! Rendering: the BVH, the integrator, the sky, and the frames of aligned AOVs it produces
//! for each view.

pub mod accel;
pub mod bvh;
pub mod bvh_binned;
pub mod bvh_build;
pub mod bvh_packet;
pub mod camera_rays;
pub mod cancel;
pub mod exposure;
pub mod footprint;
pub mod frame;
pub mod frame_over;
pub mod in_time;
pub mod instances;
pub mod integrator;
pub mod moving;
pub mod packets;
pub mod ray;
pub mod render_job;
pub mod screen;
pub mod sensor_image;
pub mod settings;
pub mod shutter_rays;
pub mod simd;
pub mod sky;
pub mod specular;
pub mod throughput;
pub mod views;
