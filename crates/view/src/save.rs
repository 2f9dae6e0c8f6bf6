//! The save key: the current view rendered through `fray-render` — the frame `fray render`
//! makes for that camera, size and settings — written as PNG or EXR, and the camera printed as
//! a scene snippet.

use crate::camera::FlyCamera;
use crate::overlay::Controls;
use fray_core::PixelSamples;
use fray_render::output::{PngOptions, check_extension, write_image};
use fray_render::{Backend, RenderOptions, Renderer};
use fray_scene::Scene;
use std::path::{Path, PathBuf};

/// What a save renders with besides the camera.
#[derive(Clone, Copy, Debug)]
pub struct SaveSettings {
    pub backend: Backend,
    pub size: (u32, u32),
    pub threads: Option<usize>,
    pub controls: Controls,
    /// The animation's time shown (`None`: nothing moves).
    pub time: Option<f64>,
}

/// Where the `n`-th save goes: `save_as` if given, else `<stem>-view-<n>.png`.
pub fn save_path(save_as: Option<&Path>, stem: &str, n: u32) -> PathBuf {
    save_as.map_or_else(
        || PathBuf::from(format!("{stem}-view-{n}.png")),
        Path::to_path_buf,
    )
}

/// Renders `scene` (the viewer's: at its time, its parts switched) from `camera` with
/// `settings` and writes it to `path`; returns the command line that renders the same bytes
/// from the file (with the printed camera in the scene; an animation's camera path puts the
/// camera where the path is at `--time`, which is the printed camera while it rides the path).
pub fn save(
    scene: &Scene,
    camera: &FlyCamera,
    settings: &SaveSettings,
    path: &Path,
) -> Result<String, String> {
    check_extension(path).map_err(|e| e.to_string())?;
    let samples = PixelSamples::new(settings.controls.samples).map_err(|e| e.to_string())?;
    let options = RenderOptions {
        backend: settings.backend,
        width: Some(settings.size.0),
        height: Some(settings.size.1),
        threads: settings.threads,
        shadows: Some(settings.controls.shadows),
        culling: Some(settings.controls.culling),
        samples: Some(samples),
        ..RenderOptions::default()
    };
    let mut scene = scene.clone();
    scene.camera = camera.projector();
    let frame = Renderer::new(options)
        .render(&scene)
        .map_err(|e| e.to_string())?;
    write_image(&frame, path, &PngOptions::default()).map_err(|e| e.to_string())?;
    let mut flags = format!(
        "--backend {} --width {} --height {} --samples {}",
        settings.backend.name(),
        settings.size.0,
        settings.size.1,
        samples.count()
    );
    if !settings.controls.shadows {
        flags.push_str(" --no-shadows");
    }
    if !settings.controls.culling {
        flags.push_str(" --no-culling");
    }
    if let Some(t) = settings.time {
        flags.push_str(&format!(" --time {t:?}"));
    }
    let on = settings.controls.switches;
    for (kept, flag) in [
        (on.fog, " --no-fog"),
        (on.sky, " --no-sky"),
        (on.clouds, " --no-clouds"),
        (on.reflections, " --no-reflections"),
    ] {
        if !kept {
            flags.push_str(flag);
        }
    }
    Ok(flags)
}
