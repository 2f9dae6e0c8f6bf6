//! The cameras the number keys choose: key 1 is the scene's own camera; a scene's named
//! cameras, when the format has them, are each one more entry here.

use fray_core::Projector;
use fray_scene::Scene;

/// The scene's cameras in number-key order, with their names.
pub fn named(scene: &Scene) -> Vec<(String, Projector)> {
    vec![("the scene's camera".to_owned(), scene.camera)]
}
