//! The layers of ARCHITECTURE.md, checked: every `crate::X` (library) or
//! `lensview::X` (binary) path in `src/` outside test code names a module
//! of the same layer or one below, and the graph of top-level modules has no
//! cycle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level modules by layer, lowest first (ARCHITECTURE.md, "Layers").
const LAYERS: &[&[&str]] = &[
    &["math", "color", "sampling", "optics", "simd"],
    &["geometry", "material", "light", "camera"],
    &["accel"],
    &["scene"],
    &["trace"],
    &["integrator"],
    &["render", "edit"],
    &["bench", "lens_tools"],
    &["cli", "viewer", "plot", "main"],
];

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn rs_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("src/ is readable") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            rs_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The top-level module a file of `src/` belongs to (`None` for lib.rs).
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

/// Code without comments and without what follows the first `#[cfg(test)]`.
fn non_test_code(text: &str) -> String {
    let body = text.split("#[cfg(test)]").next().unwrap_or("");
    body.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

type Graph = BTreeMap<String, BTreeSet<String>>;

fn graph() -> Graph {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rs_files(&src, &mut files);
    let mut g = Graph::new();
    for file in files {
        let Some(module) = module_of(&src, &file) else { continue };
        if file.file_name().is_some_and(|n| n == "tests.rs") {
            continue;
        }
        let code = non_test_code(&std::fs::read_to_string(&file).expect("a readable source file"));
        let mut uses = names_after(&code, "crate::");
        uses.extend(names_after(&code, "lensview::"));
        uses.remove(&module);
        g.entry(module).or_default().extend(uses);
    }
    g
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
    assert!(g.len() >= 15, "found only {:?}", g.keys());
    for (m, uses) in &g {
        assert!(layer(m).is_some(), "src/{m} is in no layer of tests/layers.rs");
        for u in uses {
            assert!(layer(u).is_some(), "src/{m} uses `{u}`, which is in no layer");
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
    assert_eq!(non_test_code("a\n// crate::q\n#[cfg(test)]\ncrate::r"), "a");
}
