//! Shared by fray-trace's integration tests: the data scenes, at test size, and a scratch folder
//! for the files a test writes (each test file uses only some of these).

use std::path::{Path, PathBuf};

/// Every scene file in `data/scenes`, sorted (there are at least four).
#[allow(dead_code)]
pub fn data_scenes() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/scenes");
    let mut entries: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    entries.sort();
    assert!(entries.len() >= 4);
    entries
}

/// The scene at `path`, resized to `height` rows at its own aspect ratio.
#[allow(dead_code)]
pub fn load_at_height(path: &Path, height: u32) -> fray_scene::Scene {
    let mut s = fray_scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    let aspect = f64::from(s.width) / f64::from(s.height);
    s.height = height;
    s.width = (f64::from(height) * aspect).round() as u32;
    s
}

/// A folder of its own under the system's temporary folder for test `name` of test file
/// `file`, created.
#[allow(dead_code)]
pub fn temp_dir(file: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fray-{file}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
