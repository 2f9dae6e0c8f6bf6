//! Loading a scene and rendering it at test size on one backend, timed.

use fray_core::{Frame, Image};
use fray_render::output::{PngOptions, srgb8};
use fray_render::{Backend, RenderOptions, Renderer};
use fray_scene::Scene;
use std::path::Path;
use std::time::{Duration, Instant};

/// Loads a scene file; the error is the loader's message.
/// The scene at `path` as `fray render` renders it: an animated scene at time 0.
pub fn load(path: &Path) -> Result<Scene, String> {
    fray_scene::load(path)
        .and_then(|s| s.at_frame(0))
        .map_err(|e| e.to_string())
}

/// The short lower-case name of a backend, used in file names and reports (`cpu`, …).
pub fn backend_name(backend: Backend) -> String {
    format!("{backend:?}").to_ascii_lowercase()
}

/// A frame rendered for comparison.
#[derive(Debug)]
pub struct Rendered {
    pub frame: Frame,
    /// The frame as 8-bit sRGB with default [`PngOptions`]: exactly the bytes a PNG gets.
    pub image: Image<[u8; 3]>,
    /// Wall time of the `render` call.
    pub wall: Duration,
}

/// Renders `scene` on `backend` at `width` pixels wide, keeping the scene's aspect ratio.
pub fn render(scene: &Scene, backend: Backend, width: u32) -> Result<Rendered, String> {
    let renderer = Renderer::new(RenderOptions {
        backend,
        width: Some(width),
        ..RenderOptions::default()
    });
    let start = Instant::now();
    let frame = renderer.render(scene).map_err(|e| e.to_string())?;
    let wall = start.elapsed();
    let image = srgb8(&frame, &PngOptions::default());
    Ok(Rendered { frame, image, wall })
}

/// Writes an 8-bit RGB image as PNG.
pub fn save_rgb8(image: &Image<[u8; 3]>, path: &Path) -> Result<(), String> {
    image::save_buffer_with_format(
        path,
        image.pixels().as_flattened(),
        image.width(),
        image.height(),
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| format!("cannot write {}: {e}", path.display()))
}
