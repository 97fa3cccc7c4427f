//! The engine crates' modules import one another without a circle
//! (docs/architecture.md, *Imports: a graph without circles*): each
//! top-level module of `crates/core`, `crates/constraints` and
//! `crates/world` is a node, each `crate::module` path outside comments
//! and `#[cfg(test)]` code an edge.

use std::collections::BTreeMap;
use std::path::Path;

/// Every `crate::name` path in `text` (line comments and everything from
/// the first `#[cfg(test)]` on left out).
fn crate_paths(text: &str) -> Vec<String> {
    let code = text.split("#[cfg(test)]").next().unwrap_or("");
    let mut out = Vec::new();
    for line in code.lines() {
        let line = line.split("//").next().unwrap_or("");
        let mut rest = line;
        while let Some(at) = rest.find("crate::") {
            let after = &rest[at + "crate::".len()..];
            let name: String = after
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            let word_start = at == 0
                || !rest[..at]
                    .chars()
                    .next_back()
                    .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
            if word_start && !name.is_empty() {
                out.push(name);
            }
            rest = after;
        }
    }
    out
}

/// The module graph of the crate whose sources are in `src`.
fn module_graph(src: &Path) -> BTreeMap<String, Vec<String>> {
    let mut graph: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let rel = path.strip_prefix(src).unwrap();
            let first = rel.components().next().unwrap().as_os_str();
            let module = first.to_string_lossy().trim_end_matches(".rs").to_owned();
            if module == "lib" {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let edges = graph.entry(module.clone()).or_default();
            for target in crate_paths(&text) {
                if target != module && !edges.contains(&target) {
                    edges.push(target);
                }
            }
        }
    }
    graph
}

/// A circle in `graph`, if it has one (depth-first, in name order).
fn find_circle(graph: &BTreeMap<String, Vec<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, Vec<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(node.to_owned(), 1);
        path.push(node.to_owned());
        let mut next: Vec<&String> = graph
            .get(node)
            .map(|v| v.iter().collect())
            .unwrap_or_default();
        next.sort();
        for target in next {
            match state.get(target.as_str()) {
                Some(1) => {
                    let from = path.iter().position(|n| n == target).unwrap();
                    let mut circle = path[from..].to_vec();
                    circle.push(target.clone());
                    return Some(circle);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(target, graph, state, path) {
                        return Some(c);
                    }
                }
            }
        }
        path.pop();
        state.insert(node.to_owned(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if !state.contains_key(node.as_str())
            && let Some(c) = visit(node, graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

#[test]
fn engine_crates_import_their_modules_without_a_circle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for krate in ["core", "constraints", "world"] {
        let graph = module_graph(&root.join("crates").join(krate).join("src"));
        assert!(graph.len() >= 5, "{krate}: {} modules found", graph.len());
        if let Some(circle) = find_circle(&graph) {
            panic!("crates/{krate}: import circle {}", circle.join(" -> "));
        }
    }
}

#[test]
fn a_circle_is_found_when_there_is_one() {
    let graph: BTreeMap<String, Vec<String>> = [
        ("a", vec!["b"]),
        ("b", vec!["c"]),
        ("c", vec!["a"]),
        ("d", vec![]),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_owned(), v.into_iter().map(str::to_owned).collect()))
    .collect();
    assert_eq!(
        find_circle(&graph),
        Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
    );
    assert_eq!(
        crate_paths(
            "use crate::x::Y; // crate::z\nlet v = crate::w::f();\n#[cfg(test)]\nuse crate::t;"
        ),
        vec!["x".to_owned(), "w".to_owned()]
    );
}
