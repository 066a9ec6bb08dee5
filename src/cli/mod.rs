//! The command line: argument parsing and dispatch to one module a
//! command. Each command parses its arguments, calls the library and
//! reports; errors travel up as `anyhow` chains and are printed by `main`.
//!
//! - [`view`]: the window (`lensview`, `lensview view`).
//! - [`render`]: a headless PNG (`lensview render`).
//! - [`lens`]: exact lens optics (`lensview lens trace | info`); its
//!   figures (`fan | spot | distortion`) in [`lens_figures`].
//! - [`bench`]: performance tables and plots (`lensview bench`).
//! - [`converge`]: error against run time (`lensview converge`).
//! - [`table`]: the table that `bench` and `converge` print, write and plot.
//! - [`args`]: reading the command line, and its errors as one line.

mod args;
mod bench;
mod bench_work;
mod converge;
mod lens;
mod lens_figures;
mod lens_system;
mod lens_system_figures;
mod progress;
mod render;
mod table;
mod view;

use anyhow::Result;
use clap::{Parser, Subcommand};
use lensview::scene::{Scene, SceneFile};
use std::path::Path;

pub use args::parse_error;
pub use bench::BenchArgs;
pub use converge::ConvergeArgs;
pub use lens::LensCommand;
pub use render::RenderArgs;
pub use view::ViewArgs;

#[derive(Parser, Debug)]
#[command(
    name = "lensview",
    version,
    about = "A ray tracer that shows how a thick biconvex glass lens distorts a 3D scene"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Open the interactive viewer on SCENE (the embedded default without one).
    View(ViewArgs),
    /// Render a scene to a PNG file without a window.
    Render(RenderArgs),
    /// Error against run time: the progressive schedule, headless, against a converged reference.
    Converge(ConvergeArgs),
    /// Performance: time against image size and object count, ray throughput, feature costs.
    Bench(BenchArgs),
    /// Exact lens optics: real rays (`trace`) and paraxial data (`info`).
    #[command(subcommand)]
    Lens(LensCommand),
}

/// Loads `path`, or the embedded default scene.
pub fn load_scene(path: Option<&Path>) -> Result<(SceneFile, Scene)> {
    match path {
        Some(p) => Ok(Scene::load(p)?),
        None => Ok(Scene::default_scene()),
    }
}

pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => view::view(ViewArgs {
            max_spp: 64,
            width: 1280,
            height: 720,
            ..Default::default()
        }),
        Some(Command::View(a)) => view::view(a),
        Some(Command::Render(a)) => render::render_cmd(a),
        Some(Command::Converge(a)) => converge::converge(&a),
        Some(Command::Bench(a)) => bench::bench(&a),
        Some(Command::Lens(c)) => lens::lens(c),
    }
}
