//! `fray-trace`: the CPU backend, fray's f64 reference renderer.
//!
#![doc = include_str!("../README.md")]
//!
//! ## In detail
//!
//! Every primitive kind — free-form CSG solids (`fray-geometry`), height-map terrains
//! (`fray-terrain`), triangle meshes (`fray-mesh`) — answers the same few queries ([`Primitive`]:
//! bounds, nearest hit over a ray range, transmittance, the surface at a hit); the nearest hit over
//! all of them becomes a [`SurfaceInteraction`], which the one [`Integrator`] shades: ambient +
//! Lambert (albedo/π) + normalised Phong light, each light through the RGB transmittance of a
//! shadow ray, plus Whitted's mirror reflection and refraction ([`optics`]) to a maximum depth and
//! within a secondary-ray budget per camera ray ([`ray_budget`]). Tiles render in parallel with
//! rayon; the image does not depend on the thread count. With [`TraceSettings::culling`] (the
//! default) the tiles come from the `fray-quadtree` scheduler: empty tiles are skipped and each
//! tile casts only the primitives, CSG leaves and perturbations its rays may meet — the same image,
//! less work.

mod freeform;
mod hit;
mod integrator;
mod interaction;
mod media;
mod media_grid;
mod mesh;
mod mesh_shadows;
pub mod optics;
mod primitive;
mod probe;
pub mod ray_budget;
mod render;
mod secondary;
mod settings;
mod shade;
mod shadow_cull;
mod terrain;
mod texture;

/// How the caster answers plain rays ([`TraceSettings::method`]), re-exported.
pub use fray_geometry::CastMethod;
/// The work list (moved to `fray-scene`, which both backends share), re-exported.
pub use fray_scene::work_list;
pub use freeform::FreeFormPrimitive;
pub use hit::{
    AnyPrimitive, Candidates, SceneHit, interaction, nearest_hit, nearest_hit_among, transmittance,
    transmittance_among,
};
pub use integrator::Integrator;
pub use interaction::SurfaceInteraction;
pub use media::{Media, MediaTerms};
pub use media_grid::{DEPTH_TOLERANCE, MediaGrid, OPTICAL_TOLERANCE, TERMS_TOLERANCE};
pub use mesh::MeshPrimitive;
pub use primitive::{KindHit, PART_PENDING, Primitive, RayCounts, Surface, TraceContext};
pub use probe::{PixelWork, pixel_work};
pub use render::{FRAME_BYTES_PER_PIXEL, Progress, render, render_into};
pub use secondary::{
    Interiors, MAX_SHADOW_CROSSINGS, nearest_hit_from_surface, transmittance_through_surfaces,
};
pub use settings::{MAX_THREADS_PER_CORE, TraceError, TraceSettings, check_threads, max_threads};
pub use shade::Reflectance;
pub use terrain::TerrainPrimitive;
