//! Small pieces every layer uses: sRGB transfer functions, deterministic hashing for
//! sampling, and the progress line.

pub mod color;
pub mod progress;
pub mod sampling;
