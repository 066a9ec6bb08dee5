//! `lensview`: the command-line front end. Prints the error chain on one
//! line and returns a non-zero exit code on failure.

mod cli;
mod plot;
mod viewer;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
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
