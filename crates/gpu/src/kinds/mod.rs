//! Primitive kinds on the GPU as values: each kind implements [`GpuKind`] once — what it keeps
//! resident for a scene ([`ResidentKind`]: its arrays, how they follow the camera, the resources
//! it binds) and its intersection pass — and the upload, the bind groups and the frame walk
//! [`KINDS`], the scene's kinds in their intersection order (`PrimitiveKind::ALL`: a tie keeps
//! the earlier kind's hit). What a kind binds is its `bindings::Part` (`Part::of_kind`), alone in
//! its intersection pass and joined into the shade pass's surfaces group; what a scene composes
//! and specialises with is the set of its features, a kind by its `PrimitiveKind`
//! (`crate::features`). Free forms, the core, keep their arrays in the resident scene itself (every
//! shading module binds them). ARCHITECTURE.md's checklist names every file a new kind touches.

pub mod freeform;
pub mod mesh;
pub mod terrain;

use crate::passes::PipelineCache;
use crate::passes::rebase::Rebased;
use crate::passes::spec::PassSpec;
use crate::{DeviceCharges, GpuContext, GpuError, View};
use fray_core::MemoryBudget;
use fray_scene::{PrimitiveKind, Scene};
use glam::DVec3;

/// What a kind's upload reads: the device, the pipelines (the rebase pass's), the scene, the
/// point every resident position is relative to, and the render's memory account (for what it
/// lays out on the host first).
#[derive(Clone, Copy)]
#[allow(missing_debug_implementations)] // the device and the pipeline cache print nothing useful
pub struct Upload<'a> {
    pub ctx: &'a GpuContext,
    pub cache: &'a PipelineCache,
    pub scene: &'a Scene,
    pub anchor: DVec3,
    pub budget: &'a MemoryBudget,
}

/// What a kind keeps on the GPU for a scene with primitives of it.
pub trait ResidentKind: std::fmt::Debug + Send + Sync {
    /// Its part's resources, in the order of the part's bindings (`bindings::Part::bindings`).
    fn resources(&self) -> Vec<wgpu::BindingResource<'_>>;

    /// The arrays the rebase pass moves to each camera (anchor-relative source, camera-relative
    /// copy), if it has any.
    fn rebased(&self) -> Vec<&Rebased> {
        Vec::new()
    }

    /// Copies its rebased arrays into the uniform tables its passes read (after the rebase).
    fn copy_tables(&self, _encoder: &mut wgpu::CommandEncoder) {}

    /// Writes what depends on the view — the camera, the image size — before a frame (queue
    /// writes); returns the bytes written.
    fn write_view(&mut self, ctx: &GpuContext, scene: &Scene, view: &View)
    -> Result<u64, GpuError>;

    /// The bytes it uploaded.
    fn bytes(&self) -> u64;
}

/// A primitive kind on the GPU.
pub trait GpuKind: Sync {
    /// The scene's kind it draws.
    fn kind(&self) -> PrimitiveKind;

    /// Uploads the scene's primitives of this kind (called only where it has some), every
    /// buffer and texture charged to `charges` before it is allocated; `None` where the kind
    /// keeps nothing of its own (free forms: their arrays are the resident scene's).
    fn upload(
        &self,
        at: Upload<'_>,
        charges: &mut DeviceCharges,
    ) -> Result<Option<Box<dyn ResidentKind>>, GpuError>;

    /// Its intersection pass: one workgroup per work item of a band, each pixel's camera rays
    /// cast against the item's candidates of this kind over `[t_near, the nearest hit so far]`,
    /// narrowing the paths' hits (`Workload::Items`).
    fn intersection(&self) -> PassSpec;

    /// Reads its counters (`crate::counters`) from a frame's read-back `words` into `stats`.
    fn read_stats(&self, words: &[u32], stats: &mut fray_core::RenderStats);
}

/// Every kind the GPU draws, in `PrimitiveKind::ALL`'s order.
pub const KINDS: [&dyn GpuKind; 3] = [&freeform::FreeForms, &terrain::Terrains, &mesh::Meshes];

/// The kind `kind` on the GPU.
pub fn of(kind: PrimitiveKind) -> &'static dyn GpuKind {
    KINDS[kind.code() as usize]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table follows `PrimitiveKind::ALL`: `of` finds each kind at its code, and each
    /// intersection pass runs over the work items.
    #[test]
    fn the_table_holds_every_kind_in_intersection_order() {
        let kinds: Vec<_> = KINDS.iter().map(|k| k.kind()).collect();
        assert_eq!(kinds, PrimitiveKind::ALL);
        for kind in PrimitiveKind::ALL {
            assert_eq!(of(kind).kind(), kind);
            let pass = of(kind).intersection();
            assert_eq!(pass.workload, crate::passes::spec::Workload::Items);
        }
    }
}
