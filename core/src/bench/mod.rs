//! The measurements behind `lensview bench` and `lensview converge`: render
//! time against image size and object count, primary-ray throughput, what
//! each feature costs a scene that uses it and one that does not, and the
//! error of the progressive schedule against run time. Every figure is the
//! median of several timed runs of the real renderer; formatting the
//! figures into tables and plots is the command line's business.
//!
//! - [`timing`]: medians, round-robin frame timing, primary rays per second.
//! - [`scenes`]: the benchmark scenes (variants of the cubes scene).
//! - [`features`]: what each feature costs.
//! - [`convergence`]: error against time of the progressive schedule.

pub mod convergence;
pub mod features;
pub mod scenes;
pub mod timing;

pub use features::{FeatureCost, feature_costs, unused_feature_frame};
pub use scenes::{FEATURES, cubes_grid, cubes_subset, feature_variants};
pub use timing::{
    frame_time, frame_time_with, interleaved_frame_samples, interleaved_frame_times, median_time, packet_frame,
    primary_rays_per_second, primary_rays_per_second_scalar,
};
