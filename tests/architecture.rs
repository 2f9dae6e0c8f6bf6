//! The workspace's layering (ARCHITECTURE.md, "Invariants"), checked from the crates' manifests:
//! the model crates use `fray-core` and never each other; `fray-quadtree` knows only `fray-core`;
//! `fray-gpu` never depends on `fray-trace` (outside its tests); nothing but the binary, tests,
//! benches and xtask depends on `fray-render`.

use std::path::Path;

/// The `fray-*` packages a manifest lists in `[dependencies]` (not dev- or build-dependencies).
fn fray_dependencies(crate_folder: &str) -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("crates")
        .join(crate_folder)
        .join("Cargo.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut in_dependencies = false;
    let mut found = Vec::new();
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            in_dependencies = line == "[dependencies]";
            continue;
        }
        if in_dependencies && line.starts_with("fray-") {
            let name = line.split(['.', ' ', '=']).next().unwrap_or_default();
            found.push(name.to_owned());
        }
    }
    found
}

#[test]
fn model_crates_use_only_the_core() {
    for model in ["geometry", "terrain", "atmosphere", "clouds", "mesh"] {
        assert_eq!(
            fray_dependencies(model),
            ["fray-core"],
            "fray-{model} may depend on fray-core alone"
        );
    }
    assert_eq!(fray_dependencies("quadtree"), ["fray-core"]);
    assert!(fray_dependencies("core").is_empty());
}

#[test]
fn the_backends_and_the_facade_keep_their_places() {
    let gpu = fray_dependencies("gpu");
    assert!(
        !gpu.iter().any(|d| d == "fray-trace"),
        "fray-gpu depends on fray-trace: {gpu:?}"
    );
    for folder in [
        "core",
        "geometry",
        "terrain",
        "atmosphere",
        "clouds",
        "scene",
        "quadtree",
        "trace",
        "gpu",
    ] {
        let deps = fray_dependencies(folder);
        assert!(
            !deps.iter().any(|d| d == "fray-render"),
            "fray-{folder} depends on fray-render"
        );
    }
    // Both backends take a fray-scene scene.
    assert!(gpu.iter().any(|d| d == "fray-scene"));
    assert!(fray_dependencies("trace").iter().any(|d| d == "fray-scene"));
}
