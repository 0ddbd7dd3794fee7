//! The source tree's layers: every import runs down, from the command line towards the scene,
//! and no two files import each other in a loop (docs/ARCHITECTURE.md).

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The library's layers from the bottom up; a module may import from its own layer and those
/// before it. `geometry` and `analysis` share a rank: neither needs the other.
const LAYERS: [(&str, u32); 10] = [
    ("util", 0),
    ("geometry", 1),
    ("analysis", 1),
    ("scene", 2),
    ("render", 3),
    ("io", 4),
    ("system", 4),
    ("measure", 5),
    ("paper", 6),
    ("cli", 7),
];

fn rank(layer: &str) -> Option<u32> {
    LAYERS.iter().find(|(l, _)| *l == layer).map(|(_, r)| *r)
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module path segments after every `prefix` (`crate::` or `seethru::`) in `text`.
fn imported_paths(text: &str, prefix: &str) -> Vec<Vec<String>> {
    let mut paths = Vec::new();
    for (at, _) in text.match_indices(prefix) {
        // Skip `seethru::` inside a longer identifier or a string such as "seethru::x".
        if at > 0 {
            let before = text.as_bytes()[at - 1];
            if before.is_ascii_alphanumeric() || before == b'_' || before == b'"' {
                continue;
            }
        }
        let rest = &text[at + prefix.len()..];
        assert!(
            !rest.starts_with('{'),
            "a grouped import `{prefix}{{…}}` hides its layers; import each path on its own"
        );
        let mut path = Vec::new();
        let mut rest = rest;
        loop {
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            if end == 0 {
                break;
            }
            path.push(rest[..end].to_string());
            match rest[end..].strip_prefix("::") {
                Some(next) => rest = next,
                None => break,
            }
        }
        if !path.is_empty() {
            paths.push(path);
        }
    }
    paths
}

/// The file a module path names: the longest prefix of it that is `src/a/b.rs` or
/// `src/a/b/mod.rs`.
fn file_of(src: &Path, path: &[String]) -> Option<PathBuf> {
    (1..=path.len()).rev().find_map(|k| {
        let dir: PathBuf = path[..k].iter().collect();
        let file = src.join(&dir).with_extension("rs");
        let module = src.join(&dir).join("mod.rs");
        [file, module].into_iter().find(|f| f.is_file())
    })
}

#[test]
fn every_import_runs_down_and_no_files_import_each_other_in_a_loop() {
    let src = common::repo_path("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut upward = Vec::new();
    let mut edges: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap();
        let own_layer = match rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_str()
            .unwrap()
        {
            "main.rs" => "cli",
            "lib.rs" => continue,
            layer => layer,
        };
        let own = rank(own_layer)
            .unwrap_or_else(|| panic!("src/{} is in no layer of LAYERS", rel.display()));
        let text = std::fs::read_to_string(file).unwrap();
        let prefix = if own_layer == "cli" {
            "seethru::"
        } else {
            "crate::"
        };
        for path in imported_paths(&text, prefix) {
            let target = &path[0];
            let Some(r) = rank(target) else {
                panic!(
                    "src/{} imports `{target}`, which is no layer",
                    rel.display()
                );
            };
            if r > own {
                upward.push(format!("src/{} -> {}", rel.display(), path.join("::")));
            }
            if let Some(to) = file_of(&src, &path).filter(|to| to != file) {
                edges.entry(file.clone()).or_default().insert(to);
            }
        }
    }
    assert!(upward.is_empty(), "imports that run up: {upward:#?}");

    // Depth-first search for a loop among the files.
    fn visit(
        node: &PathBuf,
        edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        state: &mut BTreeMap<PathBuf, bool>,
        stack: &mut Vec<PathBuf>,
    ) {
        match state.get(node) {
            Some(true) => return,
            Some(false) => panic!("files import each other in a loop: {stack:#?} -> {node:?}"),
            None => {}
        }
        state.insert(node.clone(), false);
        stack.push(node.clone());
        for next in edges.get(node).into_iter().flatten() {
            visit(next, edges, state, stack);
        }
        stack.pop();
        state.insert(node.clone(), true);
    }
    let mut state = BTreeMap::new();
    for file in edges.keys() {
        visit(file, &edges, &mut state, &mut Vec::new());
    }
}

#[test]
fn the_import_scanner_sees_upward_imports() {
    // The scanner itself: a render file that imports the system would be caught.
    let paths = imported_paths(
        "use crate::system::display::MISSING_ID;\nlet x = crate::scene::Scene::load(p);",
        "crate::",
    );
    assert_eq!(paths[0], ["system", "display", "MISSING_ID"]);
    assert_eq!(paths[1][0], "scene");
    assert!(rank("system").unwrap() > rank("render").unwrap());
}
