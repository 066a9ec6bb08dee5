//! `lensview`: the command-line front end. Prints the error chain on one
//! line and returns a non-zero exit code on failure.

mod cli;
mod plot;
mod viewer;

use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match cli::Cli::read() {
        Ok(cli) => cli,
        Err(e) => {
            let (text, ok) = cli::parse_error(&e);
            if ok {
                print!("{text}");
                return ExitCode::SUCCESS;
            }
            eprintln!("{text}");
            return ExitCode::FAILURE;
        }
    };
    // Headless commands: Ctrl-C removes the temporary file of a write in
    // progress and exits 130. The window keeps the default (it only writes
    // small files, from its own event loop).
    if !matches!(cli.command, None | Some(cli::Command::View(_))) {
        lensview::output::remove_temp_files_on_interrupt();
    } else {
        // Before any thread exists: it sets an environment variable.
        viewer::quiet_wayland_probe();
    }
    match cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            // Paths and messages may carry user text: no control character
            // reaches the terminal raw.
            eprintln!("error: {}", lensview::scene::escape_controls(&chain.join(": ")));
            ExitCode::FAILURE
        }
    }
}
