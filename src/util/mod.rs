//! Small pieces every layer uses: sRGB transfer functions, deterministic hashing for
//! sampling and FNV-1a for fingerprints, short numbers for messages, the progress line,
//! JSON for infinite distances, nearest-rank quantiles, the process's peak memory and its threads'
//! CPU time, input files read within limits,
//! errors as one inert line, and how messages name an option for each front end to spell.

pub mod color;
pub mod cpu_time;
pub mod hash;
pub mod input_file;
pub mod json;
pub mod memory;
pub mod message;
pub mod number;
pub mod number_rows;
pub mod option_words;
pub mod progress;
pub mod quantile;
pub mod sampling;
