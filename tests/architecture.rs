//! The workspace's layering (ARCHITECTURE.md, "Invariants" 1), checked on the real
//! dependency graph that `cargo metadata` reports, normal and dev dependencies apart:
//!
//! - `fray-core` is the bottom: it depends on no fray crate, not even in its tests;
//! - the model crates (`geometry`, `terrain`, `atmosphere`, `clouds`, `mesh`) use `fray-core`
//!   and never each other — nor any other fray crate —, and their tests (dev-dependencies) use
//!   `fray-core` alone too, so each is tested as it is used: alone;
//! - `fray-quadtree` knows only `fray-core` (its tests and benches may load scenes);
//! - `fray-scene` sits on the model crates: it depends on nothing but them, `fray-core` and
//!   `fray-quadtree`;
//! - `fray-trace` and `fray-gpu` both take a `fray-scene` `Scene`, and `fray-gpu` never depends
//!   on `fray-trace` (its tests may, for parity);
//! - only the front ends — the CLI (`fray`), the viewer (`fray-view`) —, xtask, tests and benches
//!   (dev-dependencies) depend on `fray-render`;
//! - windows are the viewer's alone: only `fray-view` depends on a window or overlay crate
//!   (winit, egui and its winit and wgpu parts), in its tests too, and only the CLI uses
//!   `fray-view`: the renderers know nothing of windows.
//!
//! Build dependencies count as normal ones (they are the crate's own code). Each rule is also
//! broken on purpose in a hand-made graph below, so a test that passes has checked something.

use std::collections::BTreeSet;
use std::process::Command;

const CORE: &str = "fray-core";
const MODELS: [&str; 5] = [
    "fray-geometry",
    "fray-terrain",
    "fray-atmosphere",
    "fray-clouds",
    "fray-mesh",
];
const QUADTREE: &str = "fray-quadtree";
const SCENE: &str = "fray-scene";
const TRACE: &str = "fray-trace";
const GPU: &str = "fray-gpu";
const RENDER: &str = "fray-render";
/// Helpers tests share: any crate's tests may use it; no crate's own code may.
const TEST_SUPPORT: &str = "fray-test-support";
/// The packages that may depend on `fray-render` in their own code: the front ends (the CLI,
/// the viewer) and xtask.
const RENDER_USERS: [&str; 3] = ["fray", "fray-view", "xtask"];
/// The viewer: the one crate that opens windows.
const VIEW: &str = "fray-view";
/// The window and overlay crates (not workspace members: their edges are kept by name).
const WINDOW_CRATES: [&str; 4] = ["winit", "egui", "egui-wgpu", "egui-winit"];

/// Whether a dependency is the crate's own code (normal, build) or its tests, benches and
/// examples' (dev).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    Normal,
    Dev,
}

/// One dependency of a workspace package on another.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Edge {
    from: String,
    to: String,
    kind: Kind,
}

/// The workspace's packages and the dependencies among them.
#[derive(Debug, Default)]
struct Graph {
    packages: BTreeSet<String>,
    edges: BTreeSet<Edge>,
}

impl Graph {
    /// A hand-made graph: `(from, to, kind)` triples over the packages they name.
    fn of(edges: &[(&str, &str, Kind)]) -> Self {
        let mut graph = Graph::default();
        for &(from, to, kind) in edges {
            graph.packages.extend([from.to_owned(), to.to_owned()]);
            graph.edges.insert(Edge {
                from: from.to_owned(),
                to: to.to_owned(),
                kind,
            });
        }
        graph
    }

    /// The workspace's graph from `cargo metadata --no-deps` (every member's declared
    /// dependencies; the ones on other members are the fray edges).
    fn of_workspace() -> Self {
        let out = Command::new(env!("CARGO"))
            .args([
                "metadata",
                "--format-version",
                "1",
                "--no-deps",
                "--offline",
            ])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .expect("cargo metadata runs");
        assert!(
            out.status.success(),
            "cargo metadata failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let metadata: serde_json::Value =
            serde_json::from_slice(&out.stdout).expect("cargo metadata prints JSON");
        let packages = metadata["packages"].as_array().expect("a package list");
        let name = |p: &serde_json::Value| p["name"].as_str().expect("a name").to_owned();
        let mut graph = Graph {
            packages: packages.iter().map(name).collect(),
            edges: BTreeSet::new(),
        };
        for package in packages {
            for dep in package["dependencies"]
                .as_array()
                .expect("a dependency list")
            {
                let to = dep["name"].as_str().expect("a dependency name");
                if !graph.packages.contains(to) && !WINDOW_CRATES.contains(&to) {
                    continue;
                }
                let kind = match dep["kind"].as_str() {
                    Some("dev") => Kind::Dev,
                    None | Some("build") => Kind::Normal,
                    Some(other) => panic!("unknown dependency kind {other}"),
                };
                graph.edges.insert(Edge {
                    from: name(package),
                    to: to.to_owned(),
                    kind,
                });
            }
        }
        graph
    }

    fn has(&self, from: &str, to: &str, kind: Kind) -> bool {
        self.edges
            .iter()
            .any(|e| e.from == from && e.to == to && e.kind == kind)
    }
}

/// Every broken rule in `graph`, one line each naming the crate, the dependency and the rule.
fn violations(graph: &Graph) -> Vec<String> {
    let mut found = Vec::new();
    for e in &graph.edges {
        let kind = match e.kind {
            Kind::Normal => "depends on",
            Kind::Dev => "dev-depends on",
        };
        let mut report = |rule: &str| found.push(format!("{} {kind} {}: {rule}", e.from, e.to));
        if e.to == TEST_SUPPORT {
            if e.kind == Kind::Normal {
                report("fray-test-support is for tests: a dev-dependency only (invariant 1)");
            }
            continue;
        }
        if e.from == TEST_SUPPORT {
            report("fray-test-support depends on no fray crate, so any crate's tests may use it");
        }
        if WINDOW_CRATES.contains(&e.to.as_str()) && e.from != VIEW {
            report(
                "only fray-view opens windows: the renderers know nothing of them \
                 (invariant 1)",
            );
        }
        if e.from == CORE {
            report("fray-core is the bottom and depends on no fray crate (invariant 1)");
        }
        if MODELS.contains(&e.from.as_str()) && e.to != CORE {
            report(
                "a model crate uses fray-core alone, never another model crate or anything \
                 above, in its tests too (invariant 1)",
            );
        }
        if e.kind == Kind::Normal {
            if e.from == QUADTREE && e.to != CORE {
                report("fray-quadtree knows only fray-core (invariant 1)");
            }
            let below_scene = e.to == CORE || e.to == QUADTREE || MODELS.contains(&e.to.as_str());
            if e.from == SCENE && !below_scene {
                report(
                    "fray-scene sits on the model crates, fray-core and fray-quadtree \
                     (invariant 1)",
                );
            }
            if e.from == GPU && e.to == TRACE {
                report("fray-gpu never depends on fray-trace; only its tests do (invariant 1)");
            }
            if e.to == RENDER && !RENDER_USERS.contains(&e.from.as_str()) {
                report(
                    "only the CLI, the viewer, xtask, tests and benches depend on \
                     fray-render (invariant 1)",
                );
            }
            if e.to == VIEW && e.from != "fray" {
                report("only the CLI uses fray-view (invariant 1)");
            }
        }
    }
    for backend in [TRACE, GPU] {
        if graph.packages.contains(backend) && !graph.has(backend, SCENE, Kind::Normal) {
            found.push(format!(
                "{backend} does not depend on {SCENE}: both backends take a fray-scene Scene \
                 (invariant 1)"
            ));
        }
    }
    found
}

#[test]
fn the_workspace_keeps_every_layering_rule() {
    let graph = Graph::of_workspace();
    let expected = [
        CORE, QUADTREE, SCENE, TRACE, GPU, RENDER, VIEW, "fray", "xtask",
    ];
    for name in expected.iter().chain(&MODELS) {
        assert!(
            graph.packages.contains(*name),
            "cargo metadata lists no {name}: the rules name the crates that exist"
        );
    }
    let problems = violations(&graph);
    assert!(
        problems.is_empty(),
        "layering broken:\n{}",
        problems.join("\n")
    );
    // The rules are not vacuous on the real graph: it has the edges they allow.
    assert!(graph.has("fray-geometry", CORE, Kind::Normal));
    assert!(
        graph.has(GPU, TRACE, Kind::Dev),
        "fray-gpu's parity tests use fray-trace"
    );
    assert!(graph.has("fray", RENDER, Kind::Normal));
    assert!(graph.has(VIEW, "winit", Kind::Normal));
    assert!(graph.has("fray", VIEW, Kind::Normal));
}

/// A graph that keeps every rule, to break one rule at a time.
fn sound() -> Vec<(&'static str, &'static str, Kind)> {
    use Kind::*;
    let mut edges = vec![
        (QUADTREE, CORE, Normal),
        (QUADTREE, SCENE, Dev),
        (SCENE, CORE, Normal),
        (SCENE, QUADTREE, Normal),
        (TRACE, SCENE, Normal),
        (TRACE, QUADTREE, Normal),
        (GPU, SCENE, Normal),
        (GPU, TRACE, Dev),
        (GPU, RENDER, Dev),
        (RENDER, TRACE, Normal),
        (RENDER, GPU, Normal),
        ("fray", RENDER, Normal),
        ("xtask", RENDER, Normal),
        (VIEW, RENDER, Normal),
        (VIEW, GPU, Normal),
        (VIEW, "winit", Normal),
        (VIEW, "egui", Normal),
        ("fray", VIEW, Normal),
    ];
    for model in MODELS {
        edges.extend([
            (model, CORE, Normal),
            (model, CORE, Dev),
            (SCENE, model, Normal),
        ]);
    }
    edges
}

/// The violations of the sound graph with `changes` applied: edges added, or removed with
/// `remove`.
fn broken(add: &[(&str, &str, Kind)], remove: &[(&str, &str, Kind)]) -> Vec<String> {
    let mut edges = sound();
    edges.retain(|e| !remove.contains(e));
    edges.extend_from_slice(add);
    violations(&Graph::of(&edges))
}

/// Asserts exactly one violation, naming the crate, the dependency and the rule's words.
fn assert_one(problems: &[String], crate_: &str, dependency: &str, rule: &str) {
    assert_eq!(problems.len(), 1, "{problems:?}");
    let p = &problems[0];
    assert!(
        p.starts_with(crate_) && p.contains(dependency) && p.contains(rule),
        "{p}"
    );
}

#[test]
fn the_sound_graph_keeps_every_rule() {
    assert_eq!(violations(&Graph::of(&sound())), Vec::<String>::new());
}

#[test]
fn the_core_depending_on_a_fray_crate_is_caught_in_normal_and_dev_dependencies() {
    for kind in [Kind::Normal, Kind::Dev] {
        let problems = broken(&[(CORE, "fray-geometry", kind)], &[]);
        assert_one(&problems, CORE, "fray-geometry", "fray-core is the bottom");
    }
}

#[test]
fn a_model_crate_using_another_or_anything_above_is_caught() {
    for (to, kind) in [
        ("fray-terrain", Kind::Normal),
        ("fray-mesh", Kind::Dev),
        (SCENE, Kind::Dev),
        (RENDER, Kind::Dev),
    ] {
        let problems = broken(&[("fray-clouds", to, kind)], &[]);
        assert_one(
            &problems,
            "fray-clouds",
            to,
            "a model crate uses fray-core alone",
        );
    }
}

#[test]
fn the_quadtree_knowing_more_than_the_core_is_caught() {
    let problems = broken(&[(QUADTREE, "fray-geometry", Kind::Normal)], &[]);
    assert_one(&problems, QUADTREE, "fray-geometry", "knows only fray-core");
    // Its benches load scenes: a dev-dependency on fray-scene is allowed (in the sound graph).
}

#[test]
fn the_scene_depending_on_a_backend_is_caught() {
    let problems = broken(&[(SCENE, TRACE, Kind::Normal)], &[]);
    assert_one(
        &problems,
        SCENE,
        TRACE,
        "fray-scene sits on the model crates",
    );
}

#[test]
fn the_gpu_depending_on_the_cpu_backend_is_caught_outside_its_tests() {
    let problems = broken(&[(GPU, TRACE, Kind::Normal)], &[]);
    assert_one(
        &problems,
        GPU,
        TRACE,
        "fray-gpu never depends on fray-trace",
    );
}

#[test]
fn a_backend_not_taking_a_scene_is_caught() {
    for backend in [TRACE, GPU] {
        let problems = broken(&[], &[(backend, SCENE, Kind::Normal)]);
        assert_one(
            &problems,
            backend,
            SCENE,
            "both backends take a fray-scene Scene",
        );
    }
}

#[test]
fn a_library_depending_on_the_facade_is_caught() {
    let problems = broken(&[(TRACE, RENDER, Kind::Normal)], &[]);
    assert_one(
        &problems,
        TRACE,
        RENDER,
        "only the CLI, the viewer, xtask, tests and benches",
    );
    // As a dev-dependency (a test or bench), fray-render is allowed (fray-gpu's, above).
}

#[test]
fn a_window_outside_the_viewer_is_caught() {
    for (from, window, kind) in [
        (GPU, "winit", Kind::Normal),
        (TRACE, "egui", Kind::Dev),
        (RENDER, "egui-wgpu", Kind::Normal),
    ] {
        let problems = broken(&[(from, window, kind)], &[]);
        assert_one(&problems, from, window, "only fray-view opens windows");
    }
    let problems = broken(&[(RENDER, VIEW, Kind::Normal)], &[]);
    assert_one(&problems, RENDER, VIEW, "only the CLI uses fray-view");
}

#[test]
fn test_support_in_a_library_or_on_a_fray_crate_is_caught() {
    // Any crate's tests may use it (a model crate's too): that is sound.
    assert!(broken(&[("fray-geometry", TEST_SUPPORT, Kind::Dev)], &[]).is_empty());
    let problems = broken(&[("fray-geometry", TEST_SUPPORT, Kind::Normal)], &[]);
    assert_one(
        &problems,
        "fray-geometry",
        TEST_SUPPORT,
        "a dev-dependency only",
    );
    let problems = broken(&[(TEST_SUPPORT, SCENE, Kind::Normal)], &[]);
    assert_one(&problems, TEST_SUPPORT, SCENE, "depends on no fray crate");
}
