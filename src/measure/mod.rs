//! Measurements of the see-through display against the ground truth: per-pixel metrics,
//! the observed p_cam/p_user of the paper's setups, and sweeps over parameters.

pub mod binocular;
pub mod capture_files;
pub mod compare;
pub mod compare_external;
pub mod diff_thresholds;
pub mod driver_share;
pub mod expectations;
pub mod hazard;
pub mod head_poses;
pub mod headline;
pub mod holes;
pub mod image_diff;
pub mod image_metrics;
pub mod luminance;
pub mod maps;
pub mod measured_run;
pub mod metrics;
pub mod metrics_json;
pub mod misregistration;
pub mod option_table;
pub mod option_value;
pub mod picture_layers;
pub mod ratio;
pub mod ratio_setup;
pub mod run_spec;
pub mod sequence;
pub mod sequence_budget;
pub mod sequence_files;
pub mod sequence_records;
pub mod sequence_regions;
pub mod sweep;
pub mod sweep_csv;
pub mod sweep_grid;
pub mod sweep_shard;
pub mod viewer;
