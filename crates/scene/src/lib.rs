//! `fray-scene`: the scene description — RON scene files, materials, lights, objects — its
//! validation with errors that name file, line and field, the feature set, and the scene's cell
//! test for the `fray-quadtree` scheduler ([`work_list`]: the work items both backends render).
//!
//! [`load`] reads a file and [`parse`] a string; both check every value and resolve the
//! [`description`] (what the file says, angles in degrees) into a [`Scene`] (what it means,
//! angles in radians, a built [`fray_core::Projector`] and [`fray_geometry::Solid`]s). The file
//! format is documented in `docs/scene-format.md`.
//!
//! ```
//! use fray_scene::{Light, SceneError, parse};
//!
//! let scene = parse(
//!     r#"Scene(
//!         camera: Pinhole(eye: (0, 1, -5), look_at: (0, 0, 0), fov_y: 60),
//!         lights: [Sun(direction: (0, 2, 0))],
//!         materials: { "red": (diffuse: (0.8, 0.1, 0.1)) },
//!         objects: [(material: "red", shape: Sphere(radius: 1))],
//!     )"#,
//!     "inline.ron",
//! )?;
//! assert_eq!((scene.width, scene.height), (640, 480));
//! assert_eq!(scene.materials[scene.objects[0].leaf_materials[0] as usize].name, "red");
//! assert!(matches!(scene.lights[0], Light::Sun { direction, .. } if direction.y == 1.0));
//! assert_eq!(scene.features.names(), ["free-form", "shadows", "sun"]);
//!
//! // Errors name the file, the line and the field.
//! let err = parse("(objects: [\n  (shape: Sphere(radius: -1)),\n])", "bad.ron").unwrap_err();
//! assert_eq!(err.to_string(), "bad.ron:2:18: objects[0].shape.radius: must be > 0, got -1");
//! # Ok::<(), SceneError>(())
//! ```

mod atmosphere;
mod clouds;
pub mod description;
mod error;
mod features;
mod load;
mod locate;
mod mesh;
mod path;
mod primitive;
mod resolve;
mod scene;
mod terrain;
mod texture;
mod work;

pub use atmosphere::{
    Atmosphere, DEFAULT_GRID_SPACING, DEFAULT_GRID_SPACING_TEXT, Fog, GRID_SPACINGS, MAX_SKY_STEPS,
    Sky,
};
pub use clouds::{CloudSource, Clouds, MAX_CLOUD_RESOLUTION, MAX_SKIP_BLOCK, MAX_SUN_STEPS};
pub use description::TerrainLod;
pub use error::SceneError;
pub use features::FeatureSet;
pub use load::{
    BuildOptions, BuildProgress, MAX_INCLUDED_FILES, MAX_OBJECTS, load, load_with, parse,
    parse_description, parse_with,
};
pub use primitive::{PrimitiveId, PrimitiveKind};
pub use resolve::{MAX_DEPTH, MAX_IMAGE_SIDE, MAX_IOR, MAX_SECONDARY_RAYS};
pub use scene::{
    DEFAULT_MAX_SECONDARY_RAYS, Light, Material, MeshObject, Object, Scene, Settings, TerrainObject,
};
pub use texture::TextureSlot;
pub use work::{work_list, work_list_view, work_list_within};
