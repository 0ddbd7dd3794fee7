//! The geometry of seeing: cameras (pose, intrinsics, rays, projection), lens models,
//! calibration errors, homographies, and when a camera's rows see (shutters).

pub mod calibration;
pub mod camera;
pub mod homography;
pub mod lens;
pub mod lens_check;
pub mod opencv;
pub mod sensor;
pub mod shutter;
