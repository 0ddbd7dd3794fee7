//! The see-through system over time (`seethru sequence`): the vehicle drives and turns, the
//! head moves, and every image the display shows is late by the system's latencies.
//!
//! - `timeline`: frame, refresh, capture and head-sample times; the rig at any instant;
//! - `head_motion`: still, sway, lean or a recorded path;
//! - `predict`: the head estimate carried to display time;
//! - `system_loop`: per displayed frame, the system's work — frontal render at its capture
//!   time, head estimate, prediction, compensation, the display image — and the `seethru` view;
//!   the static world's hierarchy is built once, what moves gets its own small one per instant;
//! - `frontal_region`: the frontal pixels a refresh renders (what the crop reads);
//! - `back_tracker`: the back camera rendered and searched only around the last face.
//!
//! The truth and the metrics of every frame are `measure::sequence`'s.

mod back_tracker;
pub mod byo;
mod frontal_region;
pub mod head_motion;
pub mod predict;
pub mod system_loop;
pub mod timeline;
