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
    // Ctrl-C, SIGTERM and SIGHUP remove the temporary file of a write in
    // progress (a screenshot's, in the window) and exit 130, as they would
    // have ended the process anyway.
    if matches!(cli.command, None | Some(cli::Command::View(_))) {
        // Before any thread exists (the handler's is one): it sets an
        // environment variable.
        viewer::quiet_wayland_probe();
    }
    lensview::output::remove_temp_files_on_interrupt();
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
