//! Where things live: the workspace root, the default directories, and the scene set.

use std::path::{Path, PathBuf};

/// The workspace root (xtask lives in `<root>/xtask`), so defaults work from any directory.
pub fn root() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest.parent().unwrap_or(manifest).to_path_buf()
}

/// `data/scenes`: the scenes that regress renders.
pub fn default_scenes() -> PathBuf {
    root().join("data").join("scenes")
}

/// `data/reference`: the blessed images and `thresholds.ron`.
pub fn default_reference() -> PathBuf {
    root().join("data").join("reference")
}

/// `target/bench`: `cargo xtask bench`'s results.
pub fn default_bench_out() -> PathBuf {
    root().join("target").join("bench")
}

/// `target/regress`: the regression report and the images it shows.
pub fn default_regress_out() -> PathBuf {
    root().join("target").join("regress")
}

/// A scene file and its stem, which names its reference image and its outputs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneFile {
    pub stem: String,
    pub path: PathBuf,
}

/// Every `*.ron` file directly in `dir`, sorted by stem.
pub fn list_scenes(dir: &Path) -> Result<Vec<SceneFile>, String> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| format!("cannot list scenes in {}: {e}", dir.display()))?;
    let mut scenes = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| format!("cannot list scenes in {}: {e}", dir.display()))?;
        let path = entry.path();
        if !path.is_file() || path.extension().and_then(|e| e.to_str()) != Some("ron") {
            continue;
        }
        let Some(stem) = path.file_stem().and_then(|s| s.to_str()) else {
            return Err(format!("{}: scene file name is not UTF-8", path.display()));
        };
        scenes.push(SceneFile {
            stem: stem.to_owned(),
            path,
        });
    }
    scenes.sort_by(|a, b| a.stem.cmp(&b.stem));
    Ok(scenes)
}

/// The scenes named by `stems` (all of them when `stems` is empty); an unknown stem is an
/// error listing the known ones.
pub fn select(scenes: Vec<SceneFile>, stems: &[String]) -> Result<Vec<SceneFile>, String> {
    if stems.is_empty() {
        return Ok(scenes);
    }
    let mut chosen = Vec::new();
    for stem in stems {
        let stem = stem.strip_suffix(".ron").unwrap_or(stem);
        match scenes.iter().find(|s| s.stem == stem) {
            Some(s) if !chosen.contains(s) => chosen.push(s.clone()),
            Some(_) => {}
            None => {
                let known: Vec<&str> = scenes.iter().map(|s| s.stem.as_str()).collect();
                return Err(format!("no scene `{stem}` (known: {})", known.join(", ")));
            }
        }
    }
    Ok(chosen)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_ron_files_sorted_and_selects_by_stem() {
        let dir = std::env::temp_dir().join(format!("xtask-scenes-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub.ron")).unwrap();
        for name in ["b.ron", "a.ron", "notes.txt", "c.ron"] {
            std::fs::write(dir.join(name), "").unwrap();
        }
        let scenes = list_scenes(&dir).unwrap();
        let stems: Vec<&str> = scenes.iter().map(|s| s.stem.as_str()).collect();
        assert_eq!(stems, ["a", "b", "c"]);

        let picked = select(scenes.clone(), &["c".into(), "a.ron".into(), "c".into()]).unwrap();
        assert_eq!(picked.len(), 2);
        assert_eq!(picked[0].stem, "c");
        assert_eq!(select(scenes.clone(), &[]).unwrap(), scenes);
        let err = select(scenes, &["zz".into()]).unwrap_err();
        assert!(err.contains("zz") && err.contains("a, b, c"), "{err}");

        std::fs::remove_dir_all(&dir).unwrap();
        assert!(list_scenes(&dir).is_err());
    }
}
