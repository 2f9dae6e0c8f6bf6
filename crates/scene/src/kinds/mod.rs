//! The primitive kinds of a scene, each in its own file (its resolution, storage access, boxes,
//! materials, feature flag and cell test: a [`SceneKind`]), and the one dispatch over
//! [`PrimitiveKind`]. The scene's per-kind questions (`count`, `primitive_bounds`,
//! `material_of`, …) are answered here by asking each kind, in [`PrimitiveKind::ALL`] order.

mod free_form;
mod kind;
mod mesh;
mod terrain;

pub(crate) use kind::{Culling, ObjectContext, SceneKind};

use crate::scene::Scene;
use crate::{PrimitiveId, PrimitiveKind};

/// The kind's implementation: the one place that lists the kinds.
pub(crate) fn of(kind: PrimitiveKind) -> &'static dyn SceneKind {
    match kind {
        PrimitiveKind::FreeForm => &free_form::FreeForms,
        PrimitiveKind::Terrain => &terrain::Terrains,
        PrimitiveKind::Mesh => &mesh::Meshes,
    }
}

impl Scene {
    /// The box around all primitives of every kind (empty if there are none).
    pub fn bounds(&self) -> fray_core::Aabb {
        self.primitives()
            .filter_map(|id| self.primitive_bounds(id))
            .fold(fray_core::Aabb::EMPTY, |b, p| b.union(&p))
    }

    /// Every primitive, kind by kind in [`PrimitiveKind::ALL`] order.
    pub fn primitives(&self) -> impl Iterator<Item = PrimitiveId> + '_ {
        PrimitiveKind::ALL.into_iter().flat_map(move |kind| {
            (0..self.count(kind) as u32).map(move |index| PrimitiveId::new(kind, index))
        })
    }

    /// How many primitives of `kind` the scene holds.
    pub fn count(&self, kind: PrimitiveKind) -> usize {
        of(kind).count(self)
    }

    /// The box of primitive `id` (`None` if the scene has no such primitive).
    pub fn primitive_bounds(&self, id: PrimitiveId) -> Option<fray_core::Aabb> {
        of(id.kind).bounds(self, id.index as usize)
    }

    /// The material index of `part` of primitive `id` (a free form's leaf; terrains and meshes
    /// have one part, 0), or `None` for a primitive or part the scene does not have.
    pub fn material_of(&self, id: PrimitiveId, part: u32) -> Option<u32> {
        of(id.kind).material_of(self, id.index as usize, part)
    }

    /// Every material index the scene's primitives use, kind by kind.
    pub(crate) fn used_materials(&self) -> impl Iterator<Item = u32> + '_ {
        PrimitiveKind::ALL
            .into_iter()
            .flat_map(move |kind| of(kind).materials(self))
    }
}
