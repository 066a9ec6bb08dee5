//! Command-line errors: every one is one line on stderr starting `error:`,
//! naming what is wrong and whose `--help` to read, with exit status 1
//! (clap's own form was several lines and status 2); a negative number
//! after a flag is that flag's value, not another flag; `--help` and
//! `--version` still print and exit 0.

use std::process::Command;

fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
        .args(args)
        .output()
        .unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (o.status.code(), text(&o.stdout), text(&o.stderr))
}

#[test]
fn every_argument_error_is_one_line_with_status_1() {
    let cases: &[(&[&str], &str, &str)] = &[
        (&["render", "--bogus"], "'--bogus'", "lensview render --help"),
        (&["render", "--width", "abc"], "'abc'", "lensview render --help"),
        (&["lens", "info", "--d"], "--d", "lensview lens info --help"),
        (&["lens"], "subcommand is missing", "lensview lens --help"),
        (&["nonsense"], "'nonsense'", "lensview --help"),
        (
            &["converge", "--max-spp", "1", "--max-spp", "2"],
            "--max-spp",
            "lensview converge --help",
        ),
        (&["bench", "--runs", "-3"], "'-3'", "lensview bench --help"),
        (&["lens", "fan", "--field", "x"], "", "lensview lens fan --help"),
    ];
    for (args, names, help) in cases {
        let (code, out, err) = run(args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?} printed {out}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains(names) && err.contains(help),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn a_negative_number_after_a_flag_is_its_value() {
    // Taken as the value of --d, and refused as a diameter, not as a flag.
    let (code, _, err) = run(&["lens", "info", "--d", "-2", "--r1", "5", "--r2", "5", "--n", "1.5"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("--d") && err.contains("-2") && !err.contains("unexpected argument"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[test]
fn help_and_version_still_print_and_succeed() {
    for args in [
        &["--help"][..],
        &["render", "--help"],
        &["lens", "trace", "--help"],
        &["--version"],
    ] {
        let (code, out, err) = run(args);
        assert_eq!(code, Some(0), "{args:?}: {err}");
        assert!(out.contains("lensview") || out.contains("Usage"), "{args:?}: {out}");
    }
}
