//! The free-form intersection pass: one workgroup per work item of the band, each pixel's
//! camera rays cast against the item's free-form candidates (active leaves and perturbations,
//! pruned CSG programs) by the halving search of `shaders/freeform.wgsl`, the f32 twin of
//! `fray_geometry::RayCaster`; the nearest hit goes into each ray's path.

use super::{PipelineCache, dispatch};
use crate::bindings::{FRAME, FREE_FORMS, Group, WORK};
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use std::sync::Arc;

/// The free-form intersection pass.
#[derive(Debug)]
pub struct FreeFormPass {
    pipeline: Arc<wgpu::ComputePipeline>,
}

impl FreeFormPass {
    /// The groups it binds.
    pub const GROUPS: [Group; 3] = [FRAME, FREE_FORMS, WORK];

    pub fn new(
        cache: &PipelineCache,
        ctx: &GpuContext,
        options: &ModuleOptions,
        specialisation: &Specialisation,
    ) -> Result<Self, GpuError> {
        let pipeline = cache.pipeline(
            ctx,
            "intersect_freeform.wgsl",
            &Self::GROUPS,
            options,
            specialisation,
        )?;
        Ok(Self { pipeline })
    }

    /// Casts the rays of `items` work items.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        [frame, free_forms, work]: [&wgpu::BindGroup; 3],
        items: u32,
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, frame, &[]);
        pass.set_bind_group(1, free_forms, &[]);
        pass.set_bind_group(2, work, &[]);
        dispatch(pass, ctx, items);
    }
}
