//! Image fixtures written to disk for texture tests.

use std::path::Path;

/// Writes a `side × side` RGB PNG into `dir` whose quadrants are red (top left), green (top
/// right), blue (bottom left) and white (bottom right); returns its path.
pub fn quadrants_png(dir: &Path, side: u32) -> String {
    let mut pixels = Vec::new();
    for y in 0..side {
        for x in 0..side {
            let (left, top) = (x < side / 2, y < side / 2);
            pixels.extend_from_slice(match (left, top) {
                (true, true) => &[255, 0, 0],
                (false, true) => &[0, 255, 0],
                (true, false) => &[0, 0, 255],
                (false, false) => &[255, 255, 255],
            });
        }
    }
    let path = dir.join(format!("quadrants{side}.png"));
    image::save_buffer(&path, &pixels, side, side, image::ColorType::Rgb8)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    path.display().to_string()
}
