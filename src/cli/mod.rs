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
//! - [`film`]: a recorded flight as frames and a film (`lensview film`).
//! - [`table`]: the table that `bench` and `converge` print, write and plot.
//! - [`args`]: reading the command line, and its errors as one line.

mod args;
mod bench;
mod bench_work;
mod converge;
mod film;
mod lens;
mod lens_charts;
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
    about = "A ray tracer that shows how a glass lens, or a system of them, distorts a 3D scene",
    long_about = "A ray tracer that shows how a glass lens, or a system of them, distorts a 3D scene.\n\n\
                  `lensview [SCENE] [VIEW OPTIONS]` opens the viewer on SCENE (the embedded default \
                  without one), as `lensview view` does.",
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Without a command: the viewer, with `view`'s arguments.
    #[command(flatten)]
    pub view: ViewArgs,
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
    /// Render a recorded flight (viewer: F8) into numbered frames and a film.
    Film(film::FilmArgs),
    /// Exact lens optics: real rays (`trace`), paraxial data (`info`, `system`), figures (`fan`, `spot`, `distortion`).
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
        None => {
            // A word that names no command and no file is a mistyped
            // command more likely than a scene.
            if let Some(p) = &cli.view.scene
                && !p.exists()
                && p.extension().is_none()
                && p.components().count() == 1
            {
                anyhow::bail!(
                    "'{}' is neither a command nor a scene file (commands: view, render, film, converge, bench, lens); see lensview --help",
                    p.display()
                );
            }
            view::view(cli.view)
        }
        Some(Command::View(a)) => view::view(a),
        Some(Command::Render(a)) => render::render_cmd(a),
        Some(Command::Converge(a)) => converge::converge(&a),
        Some(Command::Bench(a)) => bench::bench(&a),
        Some(Command::Lens(c)) => lens::lens(c),
        Some(Command::Film(a)) => film::film(a),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 33.7: `lensview SCENE` and `lensview --exit-after N` open the
    /// viewer as `lensview view …` does, with the same defaults; a command
    /// still wins where one is named.
    #[test]
    fn the_viewers_arguments_work_without_view() {
        let parse = |args: &[&str]| Cli::try_parse_from(args).expect("parses");
        let bare = parse(&["lensview", "scenes/cubes.toml", "--exit-after", "2", "--no-panel"]);
        assert!(bare.command.is_none());
        assert_eq!(bare.view.scene.as_deref(), Some(Path::new("scenes/cubes.toml")));
        assert_eq!(bare.view.exit_after, Some(2.0));
        assert!(bare.view.no_panel);
        let Some(Command::View(v)) = parse(&["lensview", "view", "scenes/cubes.toml"]).command else {
            panic!("`view` is the view command");
        };
        let d = parse(&["lensview"]).view;
        assert_eq!((d.max_spp, d.width, d.height), (v.max_spp, v.width, v.height));
        assert_eq!((d.max_spp, d.width, d.height), (64, 1280, 720));
        assert!(matches!(
            parse(&["lensview", "render"]).command,
            Some(Command::Render(_))
        ));
        assert!(
            Cli::try_parse_from(["lensview", "scenes/cubes.toml", "render"]).is_err(),
            "a scene and a command together"
        );
    }
}
