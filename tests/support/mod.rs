//! What the command tests of the figures share: running the built
//! `lensview`.

use std::ffi::OsStr;
use std::process::Command;

/// Runs `lensview` with `args`: whether it succeeded, and its stdout and
/// stderr as text.
pub fn run<S: AsRef<OsStr>>(args: &[S]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .args(args)
        .output()
        .expect("lensview runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
