//! The cameras the number keys choose: key 1 is the scene's own camera, keys 2, 3, … its named
//! `cameras` in name order.

use fray_core::Projector;
use fray_scene::Scene;

/// The scene's cameras in number-key order, with their names.
pub fn named(scene: &Scene) -> Vec<(String, Projector)> {
    std::iter::once(("the scene's camera".to_owned(), scene.camera))
        .chain(scene.cameras.iter().map(|c| (c.name.clone(), c.camera)))
        .collect()
}
