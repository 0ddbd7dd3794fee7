//! Small pieces every layer uses: sRGB transfer functions, deterministic hashing for
//! sampling, short numbers for messages, and the progress line.

pub mod color;
pub mod number;
pub mod progress;
pub mod sampling;
