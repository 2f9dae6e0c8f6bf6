//! Free forms on the GPU, the core kind: their arrays are the resident scene's own (solids, leaves,
//! perturbations, CSG programs — every shading module binds them), so the kind adds its
//! intersection pass and its counters. The pass: one workgroup per work item of the band, each
//! pixel's camera rays cast against the item's free-form candidates (active leaves and
//! perturbations, pruned CSG programs) by the halving search of `shaders/freeform.wgsl`, the f32
//! twin of `fray_geometry::RayCaster`; the nearest hit goes into each ray's path.

use super::{GpuKind, ResidentKind, Upload};
use crate::counters::Counter;
use crate::passes::spec::{PassSpec, Role, Workload};
use crate::{DeviceCharges, GpuError};
use fray_scene::PrimitiveKind;

/// The freeform kind on the GPU.
#[derive(Clone, Copy, Debug)]
pub struct FreeForms;

impl GpuKind for FreeForms {
    fn kind(&self) -> PrimitiveKind {
        PrimitiveKind::FreeForm
    }

    /// Nothing of its own: the solids, leaves, perturbations and programs are the resident
    /// scene's (`crate::resident::ResidentScene`), bound as the `FREE_FORMS` group.
    fn upload(
        &self,
        _at: Upload<'_>,
        _charges: &mut DeviceCharges,
    ) -> Result<Option<Box<dyn ResidentKind>>, GpuError> {
        Ok(None)
    }

    fn intersection(&self) -> PassSpec {
        INTERSECTION
    }

    fn read_stats(&self, words: &[u32], stats: &mut fray_core::RenderStats) {
        stats.bound_evaluations = Counter::BoundEvaluations.read(words);
        stats.point_evaluations = Counter::PointEvaluations.read(words);
    }
}

/// Its intersection pass.
const INTERSECTION: PassSpec = PassSpec {
    label: "free forms",
    entry: "intersect_freeform.wgsl",
    roles: &[Role::Frame, Role::FreeForms, Role::Work],
    workload: Workload::Items,
};
