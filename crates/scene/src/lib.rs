//! `fray-scene`: RON scene files, their validation with located errors, the feature set.
//!
#![doc = include_str!("../README.md")]
//!
//! ## In detail
//!
//! [`load`] reads a file and [`parse`] a string; both check every value and resolve the
//! [`description`] (what the file says, angles in degrees) into a [`Scene`] (what it means,
//! angles in radians, a built [`fray_core::Projector`] and [`fray_geometry::Solid`]s). The file
//! format is documented in `docs/scene-format.md`. [`work_list`] makes the work items both
//! backends render, from the scene's cell test for the `fray-quadtree` scheduler.

mod animation;
mod assets;
mod atmosphere;
mod checks;
mod clouds;
pub mod description;
mod error;
mod features;
mod kinds;
mod load;
mod locate;
mod path;
mod primitive;
mod resolve;
mod scene;
mod solid;
mod switches;
mod texture;
mod work;

pub use animation::{
    Animation, CameraPath, Curve, Heights, MAX_FRAMES, MAX_WAVES, ObjectTrack, Sequence,
    TrackTarget,
};
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
// Everything public of the resolved scene, a kind's object type (`TerrainObject`, …) included,
// so that adding a kind's storage to `scene.rs` needs no line here.
pub use scene::*;
pub use switches::Switches;
pub use texture::TextureSlot;
pub use work::{work_list, work_list_view, work_list_within};
