//! Reading the command line: a value that starts with a minus (`--d -2`,
//! `--camera-step -1,0,0`) is the flag's value in every subcommand, and
//! any error is one line with exit status 1, as every refusal is; `--help`
//! and `--version` print as clap writes them and exit 0.

use super::Cli;
use clap::error::ErrorKind;
use clap::{Arg, Command, CommandFactory, FromArgMatches};
use std::ffi::OsString;
use std::path::PathBuf;

impl Cli {
    /// The command line as [`Cli::command_line`] reads it; an error is
    /// [`parse_error`]'s.
    pub fn read() -> Result<Cli, clap::Error> {
        let m = Cli::command_line().try_get_matches()?;
        Cli::from_arg_matches(&m)
    }

    /// The command with every option that takes a value, in every
    /// subcommand, taking one that starts with a minus: a number
    /// (`--d -2`), and, but for a path, anything (a list of numbers
    /// `-1,0,0`, which clap would take for a flag). A path does not
    /// (`-o --width` is refused, not a file named `--width`).
    pub fn command_line() -> Command {
        fn value(a: Arg) -> Arg {
            if a.is_positional() || !a.get_action().takes_values() {
                return a;
            }
            let path = a.get_value_parser().type_id() == std::any::TypeId::of::<PathBuf>();
            a.allow_negative_numbers(true).allow_hyphen_values(!path)
        }
        fn every(c: Command) -> Command {
            c.mut_args(value).mut_subcommands(every)
        }
        every(Cli::command())
    }
}

/// What a command-line error prints, and whether that is success: help
/// and the version as clap writes them (success); any error as the one
/// line every refusal is (`error: …; see lensview … --help`, exit 1),
/// naming what is wrong: the flag and value, the arguments missing, the
/// values possible, clap's tip.
pub fn parse_error(e: &clap::Error) -> (String, bool) {
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        return (e.render().to_string(), true);
    }
    let args: Vec<OsString> = std::env::args_os().skip(1).collect();
    let (path, cmd) = command_path(&args);
    let what = match e.kind() {
        // clap would print the help here: say what is missing instead.
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let subs: Vec<&str> = cmd.get_subcommands().map(Command::get_name).collect();
            format!("a subcommand is missing, one of: {}", subs.join(", "))
        }
        _ => one_line(&e.render().to_string()),
    };
    let line = format!("error: {what}; see {path} --help");
    (lensview::scene::escape_controls(&line).into_owned(), false)
}

/// clap's message (the error, then what it lists, a tip, the usage, over
/// several lines) on one line: the error, what it lists after it (`the
/// following required arguments were not provided: --d <D>, --n <N>`),
/// the tips in parentheses; the usage and the pointer to `--help` left out.
pub fn one_line(rendered: &str) -> String {
    let (mut head, mut items, mut tips) = (None, Vec::new(), Vec::new());
    for l in rendered.lines().map(str::trim) {
        if l.starts_with("Usage:") || l.starts_with("For more information") {
            break;
        }
        match head {
            _ if l.is_empty() => {}
            None => head = Some(l.strip_prefix("error: ").unwrap_or(l)),
            Some(_) if l.starts_with("tip:") => tips.push(l),
            Some(_) => items.push(l),
        }
    }
    let mut out = head.unwrap_or("the command line is not understood").to_string();
    if !items.is_empty() {
        let sep = if out.ends_with(':') { ", " } else { " " };
        out = format!("{out} {}", items.join(sep));
    }
    if !tips.is_empty() {
        out = format!("{out} ({})", tips.join("; "));
    }
    out
}

/// `lensview` and the subcommands named in `args` (`lensview lens info`),
/// whose `--help` to point at, and that subcommand. An argument that is
/// not UTF-8 ends the path (it names no subcommand).
fn command_path(args: &[OsString]) -> (String, Command) {
    let mut cmd = Cli::command_line();
    let mut path = vec!["lensview"];
    for arg in args.iter().map(|a| a.to_str()) {
        let Some(sub) = arg.and_then(|a| cmd.find_subcommand(a)).cloned() else {
            break;
        };
        path.push(arg.unwrap_or_default());
        cmd = sub;
    }
    (path.join(" "), cmd)
}
