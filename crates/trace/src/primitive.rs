//! The per-kind interface of the CPU backend: what every primitive kind answers — its box, the
//! nearest hit over a ray range, the transmittance over a ray range and the surface at a hit —
//! and the per-thread context its queries share (scratch space and work counters).
//!
//! Free forms (`freeform.rs`), terrains (`terrain.rs`) and meshes (`mesh.rs`) implement
//! [`Primitive`]; the scene-wide queries (`hit.rs`) walk the kinds in [`PrimitiveKind::ALL`]
//! order. A new kind is a new file implementing the trait plus one arm in each scene-wide query
//! (see ARCHITECTURE.md's checklist).
//!
//! [`PrimitiveKind::ALL`]: fray_scene::PrimitiveKind::ALL

use fray_core::{Aabb, Interval, Ray, Rgb};
use fray_geometry::{CastStats, RayCaster};
use fray_terrain::TerrainStats;
use glam::{DVec2, DVec3};

/// One thread's scratch space and counters for ray queries: reused from ray to ray, it holds no
/// scene data.
#[derive(Debug, Default)]
pub struct TraceContext {
    /// The free-form caster's scratch space (and its [`fray_geometry::CastMethod`]).
    pub caster: RayCaster,
    /// The work done since the counters were last taken.
    pub counts: RayCounts,
    /// Scratch space of the meshes' tile-wise narrowing (`MeshPrimitive::narrow_tile`).
    pub(crate) mesh: MeshScratch,
}

/// A tile's rays for one mesh instance: world rays, their mesh-space copies, ranges, hits and
/// the pixel slot each came from (reused from tile to tile).
#[derive(Debug, Default)]
pub(crate) struct MeshScratch {
    pub(crate) rays: Vec<Ray>,
    pub(crate) local: Vec<Ray>,
    pub(crate) ranges: Vec<Interval>,
    pub(crate) hits: Vec<Option<fray_mesh::MeshHit>>,
    pub(crate) slots: Vec<u32>,
    /// The tile's ray slots in packet order (pixels in Morton order), for the tile shape and
    /// ray count it was made for.
    pub(crate) order: Vec<u32>,
    pub(crate) order_for: Option<(u32, u32, usize)>,
}

/// The work of ray queries, summed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Free-form work: bound and point evaluations, closed-form casts.
    pub cast: CastStats,
    /// Terrain casts of camera rays (one per ray and terrain searched).
    pub terrain_rays: u64,
    /// The terrain searches' work on camera rays.
    pub terrain: TerrainStats,
    /// Shadow rays cast (one per lit point and light).
    pub shadow_rays: u64,
    /// Camera rays whose media terms were interpolated from the media grid, and those the grid
    /// could not interpolate (depths disagree) and evaluated exactly.
    pub media_interpolated: u64,
    pub media_exact: u64,
    /// Density samples the cloud marches of camera rays took (0 without clouds).
    pub cloud_samples: u64,
    /// Rays cast against mesh instances (nearest-hit queries, one per ray and instance).
    pub mesh_rays: u64,
    /// Those of them cast a tile at a time (the frame loop's camera rays, through the
    /// instance's packet path).
    pub mesh_tile_rays: u64,
    /// Shadow rays cast against mesh instances a tile at a time (the frame loop's camera hits'
    /// shadow rays, through the instance's packet path; one per ray and instance).
    pub mesh_shadow_tile_rays: u64,
    /// Reflected and refracted rays traced (Whitted secondary rays).
    pub secondary_rays: u64,
}

impl TraceContext {
    /// A context whose caster answers plain rays by `method`.
    pub fn new(method: fray_geometry::CastMethod) -> Self {
        Self {
            caster: RayCaster::with_method(method),
            counts: RayCounts::default(),
            mesh: MeshScratch::default(),
        }
    }

    /// The counts so far, leaving zeros (the scratch space stays).
    pub fn take_counts(&mut self) -> RayCounts {
        std::mem::take(&mut self.counts)
    }
}

/// A hit of one primitive, before its surface is known: the ray parameter, the kind's part
/// (a free form's leaf — [`PART_PENDING`] until the surface is computed —, a terrain's level of
/// detail above the finest) and what the kind learned at hit time that its surface needs
/// (`detail`: a terrain's outward face normal; a free form's outward normal once computed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KindHit {
    pub t: f64,
    pub part: u32,
    pub detail: DVec3,
}

/// A free-form hit whose leaf (and normal) is still to be found.
pub const PART_PENDING: u32 = u32::MAX;

/// The surface at a hit, as its kind describes it: outward unit normals, the part (which
/// selects the material) and the surface's own parametrisation where it has one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// The outward unit normal of the surface that was hit.
    pub geometric_normal: DVec3,
    /// The outward unit normal to shade with: the geometric one, or a smoother one (the
    /// interpolant's beneath a terrain's level-of-detail hit).
    pub shading_normal: DVec3,
    /// The part hit: a free form's leaf, 0 for a terrain.
    pub part: u32,
    /// Texture coordinates where the kind has them (a mesh's file UVs; a terrain's drape uv:
    /// texel centres on the samples, the image's top row on map row 0, `v` up);
    /// free forms have none (they are textured by projection).
    pub uv: Option<DVec2>,
}

/// What every primitive kind answers on the CPU. `eps` is the hit tolerance in world units.
pub trait Primitive {
    /// A box that holds every point of the primitive.
    fn bounds(&self) -> Aabb;

    /// The nearest hit within `range` (callers pass the best hit so far as `range.hi`), never
    /// before `range.lo`; a ray that starts inside hits at `range.lo`.
    fn nearest_hit(
        &self,
        ray: &Ray,
        range: Interval,
        eps: f64,
        ctx: &mut TraceContext,
    ) -> Option<KindHit>;

    /// The fraction of light, per channel, that passes along `range` of the ray: 0 where an
    /// opaque kind is hit, 1 where nothing is.
    fn transmittance(&self, ray: &Ray, range: Interval, eps: f64, ctx: &mut TraceContext) -> Rgb;

    /// The surface at `hit`, a hit of this primitive on `ray`.
    fn surface(&self, ray: &Ray, hit: &KindHit) -> Surface;

    /// The uv per world unit of the surface's own coordinates ([`Surface::uv`]) on `part`: how
    /// far a texture lookup's footprint stretches there (0 where the kind has no uv). Asked only
    /// for textured hits, so kinds compute it here rather than in every [`Primitive::surface`].
    fn uv_per_world(&self, _part: u32) -> f64 {
        0.0
    }
}
