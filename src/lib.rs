//! The desktop app's view of lensview's library: `lensview-core` (core/),
//! re-exported whole, so that `lensview::scene`, `lensview::render`, … name
//! what they always named, for the app (src/main.rs: the command line and
//! the window) and for the tests and benches of this package.
//!
//! The library knows nothing of windows or command lines; its layers are
//! described in core/src/lib.rs and checked by tests/layers.rs.

pub use lensview_core::*;
