//! The source tree's shape: no source file of the library or the app over 600 lines (test files
//! aside), and no import circle among the modules of `src/rapier` (a module's `use crate::rapier::...` lines, resolved
//! to the longest module path that exists; a child's `use super::...` is not an edge).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The longest a source file of the library or the app may be, lines.
const MAX_LINES: usize = 600;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

fn is_test_file(path: &Path) -> bool {
    path.file_name().is_some_and(|n| n == "tests.rs")
        || path.components().any(|c| c.as_os_str() == "tests")
}

/// `src/rapier/joint/set.rs` -> `rapier::joint::set`; `.../mod.rs` names its folder.
fn module_of(src: &Path, path: &Path) -> String {
    let rel = path.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    parts.join("::")
}

/// The `crate::rapier::...` paths a file's `use` lines name, outside its inline test module.
fn imports(text: &str) -> Vec<String> {
    let code = text
        .split("#[cfg(test)]\nmod tests {")
        .next()
        .unwrap_or(text);
    let mut out = Vec::new();
    for line in code.lines() {
        let line = line.trim_start();
        let line = line
            .strip_prefix("pub(crate) ")
            .or_else(|| line.strip_prefix("pub "))
            .unwrap_or(line);
        if let Some(path) = line.strip_prefix("use crate::") {
            let end = path
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(path.len());
            let path = path[..end].trim_end_matches(':');
            if path.starts_with("rapier") {
                out.push(path.to_string());
            }
        }
    }
    out
}

/// The module graph of `src/rapier`: each module and the modules it imports.
fn rapier_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(&src.join("rapier"), &mut files);
    files.retain(|f| !is_test_file(f));
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(src, f)).collect();
    let resolve = |path: &str| -> Option<String> {
        let parts: Vec<&str> = path.split("::").collect();
        (1..=parts.len())
            .rev()
            .map(|k| parts[..k].join("::"))
            .find(|m| modules.contains(m))
    };
    let mut graph = BTreeMap::new();
    for file in &files {
        let module = module_of(src, file);
        let text = fs::read_to_string(file).unwrap();
        let edges: BTreeSet<String> = imports(&text)
            .iter()
            .filter_map(|p| resolve(p))
            .filter(|m| *m != module)
            .collect();
        graph.insert(module, edges);
    }
    graph
}

/// A circle through `start`, if any (depth-first search back to it).
fn circle_through(graph: &BTreeMap<String, BTreeSet<String>>, start: &str) -> Option<Vec<String>> {
    let mut stack = vec![(start.to_string(), vec![start.to_string()])];
    let mut seen = BTreeSet::new();
    while let Some((node, path)) = stack.pop() {
        for next in graph.get(&node).into_iter().flatten() {
            if next == start {
                return Some(path.clone());
            }
            if seen.insert(next.clone()) {
                let mut longer = path.clone();
                longer.push(next.clone());
                stack.push((next.clone(), longer));
            }
        }
    }
    None
}

/// The files under `dir` longer than [`MAX_LINES`] (test files aside), with their lengths.
fn too_long(dir: &Path) -> Vec<String> {
    let mut files = Vec::new();
    rust_files(dir, &mut files);
    files
        .iter()
        .filter(|f| !is_test_file(f))
        .filter_map(|f| {
            let lines = fs::read_to_string(f).unwrap().lines().count();
            (lines > MAX_LINES).then(|| format!("{} ({lines} lines)", f.display()))
        })
        .collect()
}

#[test]
fn no_library_file_is_longer_than_the_limit() {
    let long = too_long(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    assert!(long.is_empty(), "split by job: {long:?}");
}

#[test]
fn no_app_file_is_longer_than_the_limit() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("app/src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(
        files.len() > 20,
        "the walk found the app's files: {files:?}"
    );
    let long = too_long(&src);
    assert!(long.is_empty(), "split by job: {long:?}");
}

#[test]
fn the_rapier_modules_import_no_circle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = rapier_graph(&src);
    assert!(graph.len() > 20, "the walk found the modules: {graph:?}");
    for module in graph.keys() {
        if let Some(circle) = circle_through(&graph, module) {
            panic!("import circle: {}", circle.join(" -> "));
        }
    }
}

#[test]
fn a_circle_is_found_when_there_is_one() {
    let mut graph = BTreeMap::new();
    for (a, b) in [
        ("guards", "joint"),
        ("joint", "stall"),
        ("stall", "guards"),
        ("x", "joint"),
    ] {
        graph
            .entry(a.to_string())
            .or_insert_with(BTreeSet::new)
            .insert(b.to_string());
    }
    assert_eq!(
        circle_through(&graph, "guards"),
        Some(vec!["guards".into(), "joint".into(), "stall".into()])
    );
    assert_eq!(circle_through(&graph, "x"), None);
    assert_eq!(
        imports(
            "use crate::rapier::joint::{A, B};\npub(crate) use crate::rapier::pipeline::protocol::Wrench;\nuse crate::model::x;"
        ),
        ["rapier::joint", "rapier::pipeline::protocol::Wrench"]
    );
}
