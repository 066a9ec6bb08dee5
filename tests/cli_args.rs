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

/// The subcommands whose options the tests below go through, found in the
/// help (so that a new one is covered): `["render"]`, `["lens", "info"]`…
fn subcommands(path: &[String]) -> Vec<Vec<String>> {
    let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
    args.push("--help");
    let (_, help, _) = run(&args);
    let names: Vec<String> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|n| *n != "help")
        .map(str::to_string)
        .collect();
    let mut out = Vec::new();
    for n in names {
        let mut sub = path.to_vec();
        sub.push(n);
        let deeper = subcommands(&sub);
        out.push(sub);
        out.extend(deeper);
    }
    out
}

/// The options of a subcommand that take a value (`--width <WIDTH>`), and
/// whether the value is a path (by its name in the help).
fn value_options(path: &[String]) -> Vec<(String, bool)> {
    let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
    args.push("--help");
    let (_, help, _) = run(&args);
    help.lines()
        .filter_map(|l| {
            let l = l.trim_start();
            let l = l
                .split_once(", ")
                .filter(|(s, _)| s.len() == 2)
                .map_or(l, |(_, long)| long);
            let (flag, rest) = l.split_once(' ')?;
            let value = rest.strip_prefix('<')?.split('>').next()?;
            let path = [
                "OUTPUT",
                "OUT_DIR",
                "CSV",
                "PLOT",
                "FRAME_LOG",
                "UI_LOG",
                "FILE",
                "DIR",
                "FLIGHT",
            ]
            .contains(&value);
            flag.starts_with("--").then(|| (flag.to_string(), path))
        })
        .collect()
}

/// Every option that takes a value, in every subcommand, takes one that
/// starts with a minus: a negative number (`--d -2`), and but for a path a
/// list that starts with one (`--camera-step -1,0,0`). Each is followed by
/// an argument that does not exist, so that nothing runs: the error must
/// name that argument, not the value.
#[test]
fn every_option_of_every_subcommand_takes_a_value_with_a_minus() {
    let subs = subcommands(&[]);
    assert!(subs.len() >= 9, "{subs:?}");
    let mut checked = 0;
    for sub in &subs {
        for (flag, path) in value_options(sub) {
            let values: &[&str] = if path { &["-1"] } else { &["-1", "-0.5", "-1,0,0"] };
            for value in values {
                let mut args: Vec<&str> = sub.iter().map(String::as_str).collect();
                args.extend([flag.as_str(), value, "--no-such-option"]);
                let (code, _, err) = run(&args);
                assert_eq!(code, Some(1), "{args:?}: {err}");
                assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
                assert!(
                    err.contains("'--no-such-option'") || err.contains(&format!("'{value}'")),
                    "{args:?}: {err}"
                );
                assert!(
                    !err.contains(&format!("unexpected argument '{value}'")),
                    "{args:?}: {err}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 60, "{checked} options checked");
}

/// What clap lists below its first line is on the one line: the arguments
/// missing, the values possible, its tip.
#[test]
fn the_one_line_names_what_is_missing_and_what_is_possible() {
    let cases: &[(&[&str], &[&str])] = &[
        (&["lens", "info"], &["--d <D>", "--r1 <R1>", "--r2 <R2>", "--n <N>"]),
        (&["lens", "info", "--d", "2", "--r1", "5"], &["--r2 <R2>", "--n <N>"]),
        (&["lens", "trace"], &["<CASES>"]),
        (&["converge", "--pattern", "foo"], &["'foo'", "r2", "uniform"]),
        (&["render", "--widht", "3"], &["'--widht'", "--width"]),
        (&["lens"], &["trace", "info", "fan", "spot", "distortion"]),
    ];
    for (args, names) in cases {
        let (code, _, err) = run(args);
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        for n in *names {
            assert!(err.contains(n), "{args:?}: {n} not in {err}");
        }
    }
}

/// A command line with an argument that is not UTF-8 is refused (or read,
/// for a path) like any other: one line, status 1, no panic.
#[test]
fn an_argument_that_is_not_utf8_is_one_line_too() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let bad = OsStr::from_bytes(b"\xff.toml");
    for args in [
        vec![OsStr::new("render"), bad, OsStr::new("--bogus")],
        vec![OsStr::new("render"), OsStr::new("--width"), bad],
        vec![bad],
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_lensview"))
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("error: "), "{args:?}: {err}");
    }
}
