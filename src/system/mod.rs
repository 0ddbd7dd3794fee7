//! The see-through system of the paper: the back camera's head estimate, the planar
//! compensation, the display, and the pipeline that runs them on rendered frames.

pub mod calibration_json;
pub mod capture;
pub mod compensation;
pub mod depth_search;
pub mod depth_sensor;
pub mod display;
pub mod eyes;
pub mod frontal_map;
pub mod head;
pub mod head_confidence;
pub mod head_estimate;
pub mod head_pose;
pub mod head_side;
pub mod memory;
pub mod obstruction;
pub mod options;
pub mod pipeline;
pub mod point_model;
pub mod reads;
pub mod report;
pub mod scene_model;
pub mod scene_model_options;
pub mod scene_plane;
pub mod sequence;
pub mod surface_map;
pub mod tracker_model;
