//! Small pieces every layer uses: sRGB transfer functions, deterministic hashing for
//! sampling, the progress line, and JSON for infinite distances.

pub mod color;
pub mod json;
pub mod progress;
pub mod sampling;
