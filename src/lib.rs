//! seethru: a ray-traced simulator of video see-through displays for driver assistance.
//!
//! The modules follow the data, from the bottom up (each imports only from those above it in
//! this list); `docs/ARCHITECTURE.md` walks one `run` through them.
// No unsafe code, except the one module that calls the packet kernels compiled for the
// CPU's widest SIMD instructions (`render/simd.rs`, which allows it and says why each call is
// sound). `forbid` cannot be lifted for one module, so the crate denies it instead.
#![deny(unsafe_code)]

/// Closed forms: the paper's equations and the physical-unit sensitivities.
pub mod analysis;
/// Cameras (pose, intrinsics, rays, projection) and homographies.
pub mod geometry;
/// Files written and read back: frames (PNG, EXR), plots, scene exports, atomic writes.
pub mod io;
/// Measurements against the ground truth: metrics, observed ratios, sweeps.
pub mod measure;
/// The paper: its claims, its figures and the reproduction of its §5.
pub mod paper;
/// The BVH, the integrator, the sky and the frames of AOVs it renders for each view.
pub mod render;
/// Scene files → a typed `Scene` → a `World` of triangles and ellipsoids.
pub mod scene;
/// The see-through system: head estimation, compensation, the display, the run pipeline.
pub mod system;
/// sRGB transfer, deterministic hashing for sampling, the progress line.
pub mod util;
