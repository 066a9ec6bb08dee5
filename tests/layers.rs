//! The layers of ARCHITECTURE.md, checked: every `crate::X` or
//! `lensview::X` path outside test code, in the library (`core/src`) or
//! the desktop app (`src`), names a module of the same layer or one below,
//! and the graph of top-level modules has no cycle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level modules by layer, lowest first (ARCHITECTURE.md, "Layers").
const LAYERS: &[&[&str]] = &[
    &[
        "math",
        "color",
        "sampling",
        "optics",
        "simd",
        "limits",
        "output",
        "files",
        "photon",
        "glass",
        "prescription",
    ],
    &["geometry", "material", "light", "camera"],
    &["accel"],
    &["scene"],
    &["trace"],
    &["integrator"],
    &["render", "edit", "flight"],
    &["bench", "lens_tools"],
    &["cli", "viewer", "plot", "main"],
];

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn rs_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("a source folder is readable") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            rs_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file of a source folder `src` belongs to (`None`
/// for lib.rs).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let rel = file.strip_prefix(src).ok()?;
    let first = rel.components().next()?.as_os_str().to_str()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (name != "lib").then(|| name.to_string())
}

/// The names right after each `prefix` in `code`: `a` in `crate::a::b`, and
/// `a`, `b` in `crate::{a::x, b}`.
fn names_after(code: &str, prefix: &str) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices(prefix) {
        let before = code[..i].chars().next_back();
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_') {
            continue;
        }
        let rest = &code[i + prefix.len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let (mut depth, mut start) = (0usize, 0usize);
            for (j, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        out.insert(ident(&group[start..j]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        out.insert(ident(&group[start..j]));
                        start = j + 1;
                    }
                    _ => {}
                }
            }
        } else {
            out.insert(ident(rest));
        }
    }
    out.retain(|n| !n.is_empty() && n != "self");
    out
}

/// The lines of a file outside its tests: a `#[cfg(test)] mod x;` line pair
/// is left out, and an inline `#[cfg(test)] mod x { … }` ends the code (test
/// modules come last in this crate).
fn non_test_lines(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut lines = text.lines().peekable();
    while let Some(l) = lines.next() {
        if l.trim() == "#[cfg(test)]" {
            match lines.peek() {
                Some(next) if next.trim_end().ends_with(';') => {
                    lines.next();
                    continue;
                }
                _ => break,
            }
        }
        out.push(l);
    }
    out
}

/// Code without comments and tests.
fn non_test_code(text: &str) -> String {
    non_test_lines(text)
        .into_iter()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

type Graph = BTreeMap<String, BTreeSet<String>>;

/// The library's and the desktop app's source folders.
fn source_folders() -> [PathBuf; 2] {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    [root.join("core/src"), root.join("src")]
}

fn graph() -> Graph {
    let mut g = Graph::new();
    for src in source_folders() {
        add_to_graph(&src, &mut g);
    }
    g
}

fn add_to_graph(src: &Path, g: &mut Graph) {
    let mut files = Vec::new();
    rs_files(src, &mut files);
    for file in files {
        let Some(module) = module_of(src, &file) else { continue };
        if file.file_name().is_some_and(|n| n == "tests.rs") {
            continue;
        }
        let code = non_test_code(&std::fs::read_to_string(&file).expect("a readable source file"));
        let mut uses = names_after(&code, "crate::");
        uses.extend(names_after(&code, "lensview::"));
        uses.remove(&module);
        g.entry(module).or_default().extend(uses);
    }
}

/// A cycle in `g`, if there is one, as the list of its modules.
fn find_cycle(g: &Graph) -> Option<Vec<String>> {
    fn visit(g: &Graph, n: &str, path: &mut Vec<String>, done: &mut BTreeSet<String>) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|p| p == n) {
            return Some(path[at..].to_vec());
        }
        if done.contains(n) {
            return None;
        }
        path.push(n.to_string());
        for m in g.get(n).into_iter().flatten() {
            if let Some(c) = visit(g, m, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    g.keys().find_map(|n| visit(g, n, &mut Vec::new(), &mut done))
}

#[test]
fn every_top_level_module_is_in_a_layer() {
    let g = graph();
    assert!(g.len() >= 25, "found only {:?}", g.keys());
    for (m, uses) in &g {
        assert!(layer(m).is_some(), "module {m} is in no layer of tests/layers.rs");
        for u in uses {
            assert!(layer(u).is_some(), "module {m} uses `{u}`, which is in no layer");
        }
    }
}

#[test]
fn no_module_uses_one_above_it() {
    let g = graph();
    let upward: Vec<String> = g
        .iter()
        .flat_map(|(m, uses)| uses.iter().map(move |u| (m, u)))
        .filter(|(m, u)| layer(u) > layer(m))
        .map(|(m, u)| format!("{m} -> {u}"))
        .collect();
    assert!(upward.is_empty(), "edges pointing up: {upward:?}");
}

#[test]
fn top_level_modules_form_no_cycle() {
    let g = graph();
    assert_eq!(find_cycle(&g), None);
}

#[test]
fn the_checker_sees_paths_groups_and_cycles() {
    let code = "use crate::{a::X, b, c::{d, e}};\nlet x = crate::f::g(); lensview::h::i; not_crate::z;";
    let mut names = names_after(code, "crate::");
    names.extend(names_after(code, "lensview::"));
    let want: BTreeSet<String> = ["a", "b", "c", "f", "h"].iter().map(|s| s.to_string()).collect();
    assert_eq!(names, want);
    let mut g = Graph::new();
    g.entry("x".into()).or_default().insert("y".into());
    g.entry("y".into()).or_default().insert("z".into());
    assert_eq!(find_cycle(&g), None);
    g.entry("z".into()).or_default().insert("x".into());
    assert_eq!(find_cycle(&g), Some(vec!["x".into(), "y".into(), "z".into()]));
    assert_eq!(
        non_test_code("a\n// crate::q\n#[cfg(test)]\nmod t;\nb\n#[cfg(test)]\nmod u {\ncrate::r"),
        "a\nb"
    );
}

/// The longest a source file may grow (the brief's "small rooms").
const MAX_FILE_LINES: usize = 700;
/// The longest a function outside tests may be.
const MAX_FN_LINES: usize = 80;
/// Functions allowed to be longer, each with its reason: (file, name, why).
const LONG_FUNCTIONS: &[(&str, &str, &str)] = &[];

/// A line without its string and character literals and its `//` comment,
/// so that braces in them are not counted.
fn code_only(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                while let Some(d) = chars.next() {
                    match d {
                        '\\' => {
                            chars.next();
                        }
                        '"' => break,
                        _ => {}
                    }
                }
            }
            '\'' if matches!(chars.clone().nth(1), Some('\'')) || chars.peek() == Some(&'\\') => {
                for d in chars.by_ref() {
                    if d == '\'' {
                        break;
                    }
                }
            }
            '/' if chars.peek() == Some(&'/') => break,
            _ => out.push(c),
        }
    }
    out
}

/// (name, first line, length in lines) of every function with a body.
fn functions(lines: &[&str]) -> Vec<(String, usize, usize)> {
    let code: Vec<String> = lines.iter().map(|l| code_only(l)).collect();
    let mut out = Vec::new();
    for (i, l) in code.iter().enumerate() {
        let Some(at) = l
            .find("fn ")
            .filter(|&at| at == 0 || !l.as_bytes()[at - 1].is_ascii_alphanumeric())
        else {
            continue;
        };
        let name: String = l[at + 3..]
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        let (mut depth, mut opened) = (0i64, false);
        for (j, m) in code.iter().enumerate().skip(i) {
            for c in m.chars() {
                match c {
                    '{' => (depth, opened) = (depth + 1, true),
                    '}' => depth -= 1,
                    _ => {}
                }
            }
            if opened && depth <= 0 {
                out.push((name.clone(), i + 1, j - i + 1));
                break;
            }
            if !opened && m.trim_end().ends_with(';') {
                break;
            }
        }
    }
    out
}

#[test]
fn no_file_or_function_outgrows_its_room() {
    // The library, the desktop app and the web crate, named from the root.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for src in source_folders() {
        rs_files(&src, &mut files);
    }
    rs_files(&root.join("web/src"), &mut files);
    assert!(files.len() > 100, "found only {} source files", files.len());
    let mut too_long = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).expect("a readable source file");
        let rel = file.strip_prefix(root).expect("under the root").display().to_string();
        let n = text.lines().count();
        if n > MAX_FILE_LINES {
            too_long.push(format!("{rel}: {n} lines"));
        }
        for (name, line, len) in functions(&non_test_lines(&text)) {
            let allowed = LONG_FUNCTIONS.iter().any(|(f, n, _)| *f == rel && *n == name);
            if len > MAX_FN_LINES && !allowed {
                too_long.push(format!("{rel}:{line}: fn {name}: {len} lines"));
            }
        }
    }
    assert!(
        too_long.is_empty(),
        "over {MAX_FILE_LINES} lines a file or {MAX_FN_LINES} a function: {too_long:#?}"
    );
}

#[test]
fn the_room_checker_measures_functions() {
    let text =
        "fn a() {\n    let s = \"}\";\n    let c = '{';\n    // }\n}\nfn b();\npub fn c(x: u8) -> u8 {\n    x\n}";
    let lines: Vec<&str> = text.lines().collect();
    let got = functions(&lines);
    assert_eq!(got, vec![("a".to_string(), 1, 5), ("c".to_string(), 7, 3)]);
}
