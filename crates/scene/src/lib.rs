//! `fray-scene`: the scene description — RON scene files, materials, lights, objects — its
//! validation with errors that name file, line and field, and the feature set.

mod features;
mod scene;

pub use features::FeatureSet;
pub use scene::{Light, Material, Object, Scene, Settings};
