//! # lensview-core
//!
//! lensview's library: a Whitted-style CPU ray tracer built around exact
//! lenses and lens systems. It knows nothing of windows or command lines:
//! the desktop app (the workspace's root package, which re-exports this
//! crate as `lensview`) and the web page (`web/`) are front ends over it.
//!
//! ## Layers
//!
//! Each module uses only those on its own line or below (checked by
//! `tests/layers.rs`; decisions in `ARCHITECTURE.md`):
//!
//! ```text
//! math · color · sampling · optics · simd     pure functions and lane helpers
//! glass · prescription                        glass catalogue · lens prescription text
//! limits · output · files · photon            size/work limits · atomic file writes · which files · photon map
//!         ↑
//! geometry · material · light · camera        one closed set of shapes
//!         ↑
//! accel                                       BVH over boxes (knows no Scene)
//!         ↑
//! scene                                       file model → validated render model
//!         ↑
//! trace                                       what rays meet: scalar, packets, tiles
//!         ↑
//! integrator                                  Whitted radiance, scalar and packets
//!         ↑
//! render · edit                               progressive rendering · scene changes
//!         ↑
//! bench · lens_tools                          measurements · lens trace / info / figures
//! ```
//! The binary adds `cli` (`src/cli/`) and `viewer` (`src/viewer/`) on top;
//! the web page (`web/`, a workspace member) adds `web/src/view.rs`.
//!
//! ## Features
//!
//! `desktop` (default) is the binary's: the command line and the window
//! (clap, indicatif, winit, pixels, egui, plotters) and `signals` (Ctrl-C
//! removes a write's temporary file: [`output::remove_temp_files_on_interrupt`]).
//! Without default features the library builds for `wasm32-unknown-unknown`
//! (web/build.sh): time is `web_time::Instant` (std's off the web), the SIMD
//! dispatch falls to the portable build, rayon runs on the calling thread.
//!
//! ## Where things live
//!
//! | what | where |
//! |---|---|
//! | the lens: construction, double-double start point | `geometry/lens/mod.rs`, `geometry/lens/dd.rs` |
//! | the lens: one cap's roots (the quadratic, once) | `geometry/lens/cap.rs` |
//! | the lens: a ray inside, exits, internal reflection | `geometry/lens/trace.rs` |
//! | the lens: the same steps over eight lanes | `geometry/lens/lanes.rs` |
//! | refraction, Fresnel, thick-lens paraxial data | `optics.rs` |
//! | the glass catalogue; lens prescriptions as text (`lenses/*.dat`) | `glass.rs`; `prescription.rs` |
//! | `lens trace`/`info`; ray fan, LSA, spot diagram, distortion, the fan's drawing | `lens_tools/mod.rs`; `lens_tools/{setup,fan,spot,distortion,sketch}.rs` |
//! | other shapes, one a file; the box test and its padding | `geometry/{sphere,cuboid,prism,pyramid,polytope,aabb}.rs` |
//! | the BVH | `accel/mod.rs` |
//! | scene file model, validation, errors with lines | `scene/{file,validate,error,input}.rs` |
//! | closest hit and shadow transmittance, one ray | `trace/scalar.rs` |
//! | the same for packets of eight, BVH walk | `trace/packet.rs` |
//! | camera packets and frustum tiles | `trace/tile.rs` |
//! | lanes, masks, the AVX2 twin builds | `simd.rs` |
//! | hit point data (`Surface`), spawning rays | `integrator/surface.rs` |
//! | shading both kernels share (ambient, Lambert, Phong, onward rays) | `integrator/shade.rs` |
//! | the one-ray kernel | `integrator/scalar.rs` |
//! | the packet kernel | `integrator/packet.rs` |
//! | the pass through a lens, scalar and in lanes | `integrator/lens_pass.rs` |
//! | feature dispatch, entry points | `integrator/mod.rs` |
//! | rendering an image, the progressive schedule, the render thread | `render/{mod,progressive,worker}.rs` |
//! | `render` in steps of one band of one sample, on the calling thread (the web page) | `render/steps.rs` |
//! | caustics: the photon map, photons traced, passes scheduled | `photon/`, `integrator/emission.rs`, `integrator/photons.rs`, `render/caustics.rs` |
//! | every scene change (undo, save, add, edit) | `edit.rs`, `edit/document.rs`, `edit/document/*.rs` |
//! | benchmark scenes, timings, error against time | `bench/{scenes,timing,features,convergence}.rs` |
//! | the viewer's shell, flight, refinement, statistics; its heap policy | `viewer/{mod,flight,refine,stats,session,screen,input,heap}.rs` (binary) |
//! | when the window presents; when a resized surface is configured; the watchdog of `--exit-after`; the overlay and key help (egui); the X11 environment | `viewer/{pacing,settle,watchdog,overlay,platform}.rs` (binary) |
//! | each panel section | `viewer/panel/{add,objects,material,camera,lens,light,render,menu,file_dialog,confirm}.rs` (binary) |
//! | optics over the picture (F6): its figure and projection; painted by the viewer and the page | `lens_tools/overlay.rs`; `viewer/optics.rs` (binary), `web/src/optics.rs` |
//! | the lens analysis (F7): its figures; drawn by the viewer (egui) and as SVG for the page | `lens_tools/{analysis,chart}.rs`; `viewer/panel/{analysis,system_analysis,plots}.rs` (binary) |
//! | the limits of every command; atomic, safe file writes | `limits.rs`, `output.rs` |
//! | each command (`render`, `lens`, `bench`, `converge`, `view`) | `cli/*.rs` (binary) |

// `!(x >= lo)` is written on purpose throughout: unlike `x < lo` it is also
// true for NaN, so a NaN can never pass a validity check.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod bench;
pub mod camera;
pub mod color;
pub mod edit;
pub mod files;
pub mod flight;
pub mod geometry;
pub mod glass;
pub mod integrator;
pub mod lens_tools;
pub mod light;
pub mod limits;
pub mod material;
pub mod math;
pub mod optics;
pub mod output;
pub mod photon;
pub mod prescription;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod simd;
pub mod trace;
