//! No import circles inside a crate: for every crate under `crates/`, the graph of its modules
//! (an edge where a module's non-test code names `crate::other` or `super::sibling`) has no
//! cycle — except the ones listed in `KNOWN`, which may only shrink (the test fails when one of
//! them is gone, so the list stays true, and when a new one appears).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Cycles that existed when this check was written, by crate, each as its sorted modules.
/// Remove an entry when the cycle is broken; never add one.
const KNOWN: &[(&str, &[&str])] = &[
    ("atmosphere", &["fog", "method", "single_scattering"]),
    ("clouds", &["bake", "cost", "march"]),
    ("geometry", &["cast::finish", "cast::program"]),
    ("mesh", &["bvh", "bvh_build"]),
    ("trace", &["hit", "mesh", "secondary"]),
];

/// The module path of `file` under `src` (`""` for the crate root).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts.join("::")
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

/// The code of a file that the crate's library uses: line comments dropped, and everything from
/// the first `#[cfg(test)]` on (test modules sit at the end of a file here).
fn library_code(text: &str) -> String {
    let code = text.split("#[cfg(test)]").next().unwrap_or("");
    code.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The `a::b::c` paths that follow each occurrence of `prefix` in `code`.
fn paths_after<'c>(code: &'c str, prefix: &str) -> Vec<Vec<&'c str>> {
    code.match_indices(prefix)
        .map(|(i, _)| {
            let rest = &code[i + prefix.len()..];
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            rest[..end].split("::").filter(|s| !s.is_empty()).collect()
        })
        .collect()
}

/// The longest prefix of `path` (joined with `base`) that names a module of the crate.
fn module_named(modules: &BTreeSet<String>, base: &[&str], path: &[&str]) -> Option<String> {
    (1..=path.len()).rev().find_map(|k| {
        let name: Vec<&str> = base.iter().chain(&path[..k]).copied().collect();
        let name = name.join("::");
        modules.contains(&name).then_some(name)
    })
}

/// Each module's dependencies on the crate's other modules.
fn module_graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(src, f)).collect();
    let mut graph = BTreeMap::new();
    for file in &files {
        let module = module_of(src, file);
        let code = library_code(&std::fs::read_to_string(file).unwrap());
        let mut deps = BTreeSet::new();
        for path in paths_after(&code, "crate::") {
            deps.extend(module_named(&modules, &[], &path));
        }
        // `super::` is the parent module of this file's module.
        let own: Vec<&str> = module.split("::").filter(|s| !s.is_empty()).collect();
        let parent = &own[..own.len().saturating_sub(1)];
        for path in paths_after(&code, "super::") {
            let named = module_named(&modules, parent, &path);
            deps.extend(named.or_else(|| Some(parent.join("::"))));
        }
        deps.remove(&module);
        deps.remove("");
        graph.insert(module, deps);
    }
    graph
}

/// The strongly connected components with more than one module (Tarjan), each sorted.
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> BTreeSet<Vec<String>> {
    struct State<'g> {
        graph: &'g BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        stack: Vec<&'g str>,
        found: BTreeSet<Vec<String>>,
    }
    fn visit<'g>(s: &mut State<'g>, v: &'g str) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        for w in s.graph.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.stack.contains(&w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                component.push(w.to_owned());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                s.found.insert(component);
            }
        }
    }
    let mut state = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        found: BTreeSet::new(),
    };
    for v in graph.keys() {
        if !state.index.contains_key(v.as_str()) {
            visit(&mut state, v);
        }
    }
    state.found
}

#[test]
fn the_checker_finds_a_cycle_and_not_a_chain() {
    let graph = |edges: &[(&str, &str)]| {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    let chain = graph(&[("render", "passes"), ("passes", "shader")]);
    assert!(cycles(&chain).is_empty());
    let circle = graph(&[
        ("render", "passes"),
        ("passes", "shader"),
        ("shader", "passes"),
    ]);
    let found: Vec<Vec<String>> = cycles(&circle).into_iter().collect();
    assert_eq!(found, vec![vec!["passes".to_owned(), "shader".to_owned()]]);
}

#[test]
fn no_crate_has_a_module_cycle_but_the_known_ones() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates");
    let mut found = BTreeSet::new();
    for entry in std::fs::read_dir(&crates).unwrap() {
        let dir = entry.unwrap().path();
        let src = dir.join("src");
        if !src.is_dir() {
            continue;
        }
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        for cycle in cycles(&module_graph(&src)) {
            found.insert((name.clone(), cycle));
        }
    }
    let known: BTreeSet<(String, Vec<String>)> = KNOWN
        .iter()
        .map(|(c, m)| (c.to_string(), m.iter().map(|s| s.to_string()).collect()))
        .collect();
    let new: Vec<_> = found.difference(&known).collect();
    let gone: Vec<_> = known.difference(&found).collect();
    assert!(
        new.is_empty(),
        "modules that import each other in a circle (crate, modules): {new:?}"
    );
    assert!(
        gone.is_empty(),
        "these cycles are gone: remove them from KNOWN: {gone:?}"
    );
}
