//! `cargo xtask bless`: render scenes on the CPU (reference) backend at test size and write
//! them as the reference images — the only way references change.

use crate::render::{load, render};
use crate::workspace::{list_scenes, select};
use fray_render::Backend;
use fray_render::output::{PngOptions, write_png};
use std::path::PathBuf;

/// The scene the CLI renders without arguments (it embeds `data/scenes/turboprop.ron`).
const DEFAULT_SCENE_STEM: &str = "turboprop";

/// What to bless, and where.
#[derive(Clone, Debug)]
pub struct BlessOptions {
    pub scenes: PathBuf,
    pub reference: PathBuf,
    /// Image width; the height keeps the scene's aspect ratio.
    pub width: u32,
    /// Scene stems to bless; empty means all.
    pub stems: Vec<String>,
}

/// Blesses the chosen scenes. Scenes that fail are reported and skipped; the result is `Err`
/// if any did.
pub fn run(options: &BlessOptions) -> Result<(), String> {
    let scenes = select(list_scenes(&options.scenes)?, &options.stems)?;
    if scenes.is_empty() {
        println!("bless: no *.ron scenes in {}", options.scenes.display());
        return Ok(());
    }
    std::fs::create_dir_all(&options.reference)
        .map_err(|e| format!("cannot create {}: {e}", options.reference.display()))?;
    let mut failed = Vec::new();
    for scene in &scenes {
        let path = options.reference.join(format!("{}.png", scene.stem));
        let result = load(&scene.path)
            .map_err(|e| format!("cannot load {}: {e}", scene.path.display()))
            .and_then(|s| render(&s, Backend::Cpu, options.width))
            .and_then(|r| {
                write_png(&r.frame, &path, &PngOptions::default())
                    .map(|()| r)
                    .map_err(|e| e.to_string())
            });
        match result {
            Ok(r) => println!(
                "bless: wrote {} ({}×{}, cpu, {:.1} ms)",
                path.display(),
                r.image.width(),
                r.image.height(),
                r.wall.as_secs_f64() * 1e3
            ),
            Err(e) => {
                eprintln!("bless: {}: {e}", scene.stem);
                failed.push(scene.stem.clone());
            }
        }
    }
    // The CLI's no-argument picture: the default scene at its own size, as the CLI's test
    // compares it (tests/cli.rs), blessed together with the default scene's test-size image.
    if let Some(scene) = scenes.iter().find(|s| s.stem == DEFAULT_SCENE_STEM) {
        let path = options
            .reference
            .join("default")
            .join(format!("{}.png", scene.stem));
        let result = load(&scene.path).and_then(|s| {
            let width = s.width;
            std::fs::create_dir_all(path.parent().unwrap_or(&options.reference))
                .map_err(|e| format!("cannot create the folder of {}: {e}", path.display()))?;
            let r = render(&s, Backend::Cpu, width)?;
            write_png(&r.frame, &path, &PngOptions::default()).map_err(|e| e.to_string())
        });
        match result {
            Ok(()) => println!("bless: wrote {} (full size, cpu)", path.display()),
            Err(e) => {
                eprintln!("bless: {} (full size): {e}", scene.stem);
                failed.push(format!("{} (full size)", scene.stem));
            }
        }
    }
    if failed.is_empty() {
        Ok(())
    } else {
        Err(format!("could not bless: {}", failed.join(", ")))
    }
}
