//! The scene-wide ray queries over every primitive kind: the nearest hit — the pair (ray
//! parameter, primitive), narrowed kind by kind in [`PrimitiveKind::ALL`] order, so a tie keeps
//! the earlier kind's hit —, the surface interaction at it, and the transmittance along a ray.

use crate::freeform::FreeFormPrimitive;
use crate::interaction::SurfaceInteraction;
use crate::mesh::MeshPrimitive;
use crate::primitive::{KindHit, Primitive, Surface, TraceContext};
use crate::secondary::Interiors;
use crate::terrain::TerrainPrimitive;
use fray_core::{Aabb, CameraRay, Interval, PixelFootprint, Ray, Rgb};
use fray_geometry::ActiveSet;
use fray_scene::{PrimitiveId, PrimitiveKind, Scene};

/// A hit of the scene whose surface is still to come: the primitive and its kind's hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneHit {
    pub primitive: PrimitiveId,
    pub hit: KindHit,
}

/// A work item's candidates: each primitive (in the work list's order: kind by kind) with its
/// active subset (free forms; ignored for the other kinds).
pub type Candidates = [(PrimitiveId, ActiveSet)];

/// One primitive of the scene as its kind's [`Primitive`]: the static dispatch every scene-wide
/// query goes through (a new kind is one more variant).
#[derive(Clone, Copy, Debug)]
pub enum AnyPrimitive<'a> {
    FreeForm(FreeFormPrimitive<'a>),
    Terrain(TerrainPrimitive<'a>),
    Mesh(MeshPrimitive<'a>),
}

impl<'a> AnyPrimitive<'a> {
    /// Primitive `id` of `scene`, restricted to `active` (free forms) and cast at the level of
    /// detail of `footprint` (terrains; [`PixelFootprint::ZERO`]: exactly). `None` if the scene
    /// has no such primitive.
    #[inline]
    pub fn of(
        scene: &'a Scene,
        id: PrimitiveId,
        active: Option<&'a ActiveSet>,
        footprint: PixelFootprint,
    ) -> Option<Self> {
        let i = id.index as usize;
        match id.kind {
            PrimitiveKind::FreeForm => scene
                .objects
                .get(i)
                .map(|object| Self::FreeForm(FreeFormPrimitive { object, active })),
            PrimitiveKind::Terrain => scene
                .terrains
                .get(i)
                .map(|t| Self::Terrain(TerrainPrimitive::for_camera(t, footprint))),
            PrimitiveKind::Mesh => scene
                .meshes
                .get(i)
                .map(|object| Self::Mesh(MeshPrimitive { object })),
        }
    }
}

impl Primitive for AnyPrimitive<'_> {
    fn bounds(&self) -> Aabb {
        match self {
            Self::FreeForm(p) => p.bounds(),
            Self::Terrain(p) => p.bounds(),
            Self::Mesh(p) => p.bounds(),
        }
    }

    #[inline]
    fn nearest_hit(
        &self,
        ray: &Ray,
        range: Interval,
        eps: f64,
        ctx: &mut TraceContext,
    ) -> Option<KindHit> {
        match self {
            Self::FreeForm(p) => p.nearest_hit(ray, range, eps, ctx),
            Self::Terrain(p) => p.nearest_hit(ray, range, eps, ctx),
            Self::Mesh(p) => p.nearest_hit(ray, range, eps, ctx),
        }
    }

    fn transmittance(&self, ray: &Ray, range: Interval, eps: f64, ctx: &mut TraceContext) -> Rgb {
        match self {
            Self::FreeForm(p) => p.transmittance(ray, range, eps, ctx),
            Self::Terrain(p) => p.transmittance(ray, range, eps, ctx),
            Self::Mesh(p) => p.transmittance(ray, range, eps, ctx),
        }
    }

    #[inline]
    fn surface(&self, ray: &Ray, hit: &KindHit) -> Surface {
        match self {
            Self::FreeForm(p) => p.surface(ray, hit),
            Self::Terrain(p) => p.surface(ray, hit),
            Self::Mesh(p) => p.surface(ray, hit),
        }
    }

    fn uv_per_world(&self, part: u32) -> f64 {
        match self {
            Self::FreeForm(p) => p.uv_per_world(part),
            Self::Terrain(p) => p.uv_per_world(part),
            Self::Mesh(p) => p.uv_per_world(part),
        }
    }
}

/// The nearest hit in `range` over every primitive of `scene`, exactly (terrains at their
/// finest level), with its surface. Each primitive is searched only up to the best hit so far,
/// so occluded ones cost little.
pub fn nearest_hit(
    scene: &Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
) -> Option<SurfaceInteraction> {
    let hit = nearest_pending(
        scene,
        ctx,
        ray,
        range,
        eps,
        None,
        PixelFootprint::ZERO,
        None,
    )?;
    Some(interaction(scene, ray, range.lo, &hit, None))
}

/// [`nearest_hit`] over a subset: only the listed primitives, free forms restricted to their
/// [`ActiveSet`]s. The same hit as [`nearest_hit`] when the subset is conservative for the ray
/// (primitives left out cannot be hit, sets hold what the ray may need) — what a quadtree work
/// item guarantees for the rays of its tile.
pub fn nearest_hit_among(
    scene: &Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
    candidates: &Candidates,
) -> Option<SurfaceInteraction> {
    let some = Some(candidates);
    let hit = nearest_pending(
        scene,
        ctx,
        ray,
        range,
        eps,
        some,
        PixelFootprint::ZERO,
        None,
    )?;
    Some(interaction(scene, ray, range.lo, &hit, some))
}

/// The nearest hit over `candidates` (all primitives for `None`), terrains at the level of
/// detail of `footprint`, its surface still to come. With `interiors` (rays leaving a surface),
/// a ray that starts inside a transmissive free form finds where it leaves it
/// ([`Interiors::exit_hit`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn nearest_pending(
    scene: &Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
    candidates: Option<&Candidates>,
    footprint: PixelFootprint,
    interiors: Option<&Interiors>,
) -> Option<SceneHit> {
    let mut best: Option<SceneHit> = None;
    let mut narrow = |id: PrimitiveId, active: Option<&ActiveSet>| {
        let hi = best.map_or(range.hi, |b| b.hit.t);
        let segment = Interval { lo: range.lo, hi };
        let found = match interiors.and_then(|i| i.exit_hit(scene, id, ray, segment, eps, ctx)) {
            Some(exit) => exit,
            None => AnyPrimitive::of(scene, id, active, footprint)
                .and_then(|p| p.nearest_hit(ray, segment, eps, ctx)),
        };
        if let Some(hit) = found
            && best.is_none_or(|b| hit.t < b.hit.t)
        {
            best = Some(SceneHit { primitive: id, hit });
        }
    };
    match candidates {
        None => scene.primitives().for_each(|id| narrow(id, None)),
        Some(listed) => listed.iter().for_each(|(id, a)| narrow(*id, Some(a))),
    }
    best
}

/// [`nearest_pending`] for every camera ray of a tile at once (`pixels`: each ray and its hit
/// slot, overwritten) with the same answers — per pixel the same casts in the same order, each
/// ending at that pixel's best so far — candidates outer, pixels inner (free forms through
/// [`FreeFormPrimitive::narrow_tile`], meshes as packets through [`MeshPrimitive::narrow_tile`]). A free-form hit's leaf and normal are left for
/// [`complete_surface`], which the frame loop runs over all of a tile's hits afterwards.
#[allow(clippy::too_many_arguments)]
pub(crate) fn nearest_hits_deferred(
    scene: &Scene,
    ctx: &mut TraceContext,
    pixels: &mut [(Option<CameraRay>, Option<SceneHit>)],
    shape: TileShape,
    eps: f64,
    candidates: Option<&Candidates>,
    footprint: PixelFootprint,
) {
    for (_, hit) in pixels.iter_mut() {
        *hit = None;
    }
    let mut narrow_all = |id: PrimitiveId, active: Option<&ActiveSet>| match AnyPrimitive::of(
        scene, id, active, footprint,
    ) {
        Some(AnyPrimitive::FreeForm(p)) => p.narrow_tile(id.index, pixels, eps, ctx),
        Some(AnyPrimitive::Mesh(p)) => p.narrow_tile(id, pixels, shape, ctx),
        Some(other) => {
            for (camera_ray, best) in pixels.iter_mut() {
                let Some(c) = camera_ray else {
                    continue;
                };
                let hi = best.map_or(f64::INFINITY, |b| b.hit.t);
                let range = Interval { lo: c.t_near, hi };
                if let Some(hit) = other.nearest_hit(&c.ray, range, eps, ctx)
                    && best.is_none_or(|b| hit.t < b.hit.t)
                {
                    *best = Some(SceneHit { primitive: id, hit });
                }
            }
        }
        None => {}
    };
    match candidates {
        None => scene.primitives().for_each(|id| narrow_all(id, None)),
        Some(listed) => listed.iter().for_each(|(id, a)| narrow_all(*id, Some(a))),
    }
}

/// How a tile lists its camera rays: row by row, `width` pixels a row, each pixel's
/// `rays_per_pixel` rays in a row (the centre, then its samples).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct TileShape {
    pub(crate) width: u32,
    pub(crate) rays_per_pixel: u32,
}

/// The active subset `candidates` lists for `id`, if any.
#[inline]
fn active_of(candidates: Option<&Candidates>, id: PrimitiveId) -> Option<&ActiveSet> {
    candidates?
        .iter()
        .find(|(c, _)| *c == id)
        .map(|(_, active)| active)
}

/// Completes a free-form hit in place (its leaf and outward normal, evaluated with the
/// candidate's active subset when culling) — the deferred pass of the frame loop; other kinds'
/// hits come complete.
#[inline]
pub(crate) fn complete_surface(
    scene: &Scene,
    ray: &Ray,
    candidates: Option<&Candidates>,
    hit: &mut SceneHit,
) {
    if hit.primitive.kind != PrimitiveKind::FreeForm
        || hit.hit.part != crate::primitive::PART_PENDING
    {
        return;
    }
    let Some(object) = scene.objects.get(hit.primitive.index as usize) else {
        return;
    };
    let active = active_of(candidates, hit.primitive);
    let p = FreeFormPrimitive { object, active };
    (hit.hit.detail, hit.hit.part) = p.normal_and_leaf(ray, hit.hit.t);
}

/// The outward shading normal of a completed `hit` on `ray` (cast from `range_start`): what
/// [`interaction`] would give as `shading_normal`, without the rest of the record.
#[inline]
pub(crate) fn shading_normal(
    scene: &Scene,
    ray: &Ray,
    range_start: f64,
    hit: &SceneHit,
) -> glam::DVec3 {
    if hit.hit.t <= range_start {
        return -ray.dir;
    }
    if hit.primitive.kind == PrimitiveKind::FreeForm
        && hit.hit.part != crate::primitive::PART_PENDING
    {
        return hit.hit.detail;
    }
    match AnyPrimitive::of(scene, hit.primitive, None, PixelFootprint::ZERO) {
        Some(p) => p.surface(ray, &hit.hit).shading_normal,
        None => -ray.dir,
    }
}

/// The surface interaction of `hit` on `ray` (cast over a range starting at `range_start`),
/// with the material of the part hit.
#[inline]
pub fn interaction(
    scene: &Scene,
    ray: &Ray,
    range_start: f64,
    hit: &SceneHit,
    candidates: Option<&Candidates>,
) -> SurfaceInteraction {
    let complete_free_form = hit.primitive.kind == PrimitiveKind::FreeForm
        && hit.hit.part != crate::primitive::PART_PENDING;
    let surface = if complete_free_form {
        // The frame loop's hits come complete: normal and leaf are known.
        Surface {
            geometric_normal: hit.hit.detail,
            shading_normal: hit.hit.detail,
            part: hit.hit.part,
            uv: None,
        }
    } else {
        // Only a pending free-form hit needs its active subset (a linear search of the list).
        let active = active_of(candidates, hit.primitive);
        match AnyPrimitive::of(scene, hit.primitive, active, PixelFootprint::ZERO) {
            Some(p) => p.surface(ray, &hit.hit),
            // Never for a hit the scene made; a normal facing back keeps shading defined.
            None => Surface {
                geometric_normal: -ray.dir,
                shading_normal: -ray.dir,
                part: 0,
                uv: None,
            },
        }
    };
    let material = scene
        .material_of(hit.primitive, surface.part)
        .unwrap_or(u32::MAX);
    SurfaceInteraction::new(
        ray,
        range_start,
        hit.hit.t,
        hit.primitive,
        surface,
        material,
    )
}

/// The RGB transmittance along `range` of the ray through every primitive of `scene` (shadow
/// rays): the product over primitives, kind by kind, stopping at the first that blocks all
/// light.
pub fn transmittance(
    scene: &Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
) -> Rgb {
    transmittance_of(scene, ctx, ray, range, eps, None, ShadowKinds::All)
}

/// [`transmittance`] through only the listed free forms (increasing indices) and every other
/// primitive: the same answer whenever the free forms left out cannot be hit by the ray (as the
/// per-tile shadow culling ensures).
pub fn transmittance_among(
    scene: &Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
    free_forms: &[u32],
) -> Rgb {
    transmittance_of(
        scene,
        ctx,
        ray,
        range,
        eps,
        Some(free_forms),
        ShadowKinds::All,
    )
}

/// Which kinds a shadow ray asks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ShadowKinds {
    All,
    /// Every kind but the meshes, whose answer is already known (cast as packets).
    AllButMeshes,
}

/// [`transmittance_among`] the listed free forms (`None`: [`transmittance`] through all), and
/// the meshes only if `kinds` asks.
pub(crate) fn transmittance_of(
    scene: &Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
    free_forms: Option<&[u32]>,
    kinds: ShadowKinds,
) -> Rgb {
    let meshes = kinds == ShadowKinds::All;
    match free_forms {
        Some(listed) => {
            let listed = listed.iter().filter_map(|&k| scene.objects.get(k as usize));
            transmittance_through(scene, ctx, ray, range, eps, listed, meshes)
        }
        None => transmittance_through(scene, ctx, ray, range, eps, scene.objects.iter(), meshes),
    }
}

/// The transmittance through `free_forms`, every terrain and (if `meshes`) every mesh.
fn transmittance_through<'a>(
    scene: &'a Scene,
    ctx: &mut TraceContext,
    ray: &Ray,
    range: Interval,
    eps: f64,
    free_forms: impl Iterator<Item = &'a fray_scene::Object>,
    meshes: bool,
) -> Rgb {
    let mut total = Rgb::ONE;
    for object in free_forms {
        let p = FreeFormPrimitive {
            object,
            active: None,
        };
        total *= p.transmittance(ray, range, eps, ctx);
        if total == Rgb::ZERO {
            return total;
        }
    }
    for terrain in &scene.terrains {
        total *= TerrainPrimitive::exact(terrain).transmittance(ray, range, eps, ctx);
        if total == Rgb::ZERO {
            return total;
        }
    }
    for object in scene.meshes.iter().filter(|_| meshes) {
        total *= MeshPrimitive { object }.transmittance(ray, range, eps, ctx);
        if total == Rgb::ZERO {
            return total;
        }
    }
    total
}
