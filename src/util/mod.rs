//! Small pieces every layer uses: sRGB transfer functions, deterministic hashing for
//! sampling, short numbers for messages, the progress line, JSON for infinite distances and
//! the process's peak memory; errors as one inert line.

pub mod color;
pub mod input_file;
pub mod json;
pub mod memory;
pub mod message;
pub mod number;
pub mod progress;
pub mod sampling;
