//! # lensview
//!
//! A Whitted-style CPU ray tracer built around an exact thick biconvex lens.
//! The library knows nothing of windows; the command line (and the viewer)
//! are thin front ends over it.
//!
//! ```text
//! math · color · sampling · optics      pure functions, no scene
//!         ↑
//! geometry · material · light · camera  one closed set of shapes
//!         ↑
//! scene  (file model → validated render model)
//!         ↑
//! integrator (Whitted radiance)  ←  render (pixels, threads, image)
//!         ↑
//! cli (render, lens)
//! ```

// `!(x >= lo)` is written on purpose throughout: unlike `x < lo` it is also
// true for NaN, so a NaN can never pass a validity check.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod bench;
pub mod camera;
pub mod color;
pub mod edit;
pub mod geometry;
pub mod integrator;
pub mod lens_tools;
pub mod light;
pub mod material;
pub mod math;
pub mod optics;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod simd;
pub mod trace;
