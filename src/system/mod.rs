//! The see-through system of the paper: the back camera's head estimate, the planar
//! compensation, the display, and the pipeline that runs them on rendered frames.

pub mod compensation;
pub mod display;
pub mod head;
pub mod memory;
pub mod options;
pub mod pipeline;
pub mod report;
pub mod sequence;
