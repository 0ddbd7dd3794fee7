//! The geometry of seeing: cameras (pose, intrinsics, rays, projection) and homographies.

pub mod camera;
pub mod homography;
