//! The free-form intersection pass: one workgroup per work item of the band, each pixel's
//! camera rays cast against the item's free-form candidates (active leaves and perturbations,
//! pruned CSG programs) by the halving search of `shaders/freeform.wgsl`, the f32 twin of
//! `fray_geometry::RayCaster`; the nearest hit goes into each ray's path.

use super::{Kernel, PassSetup};
use crate::bindings::{FRAME, FREE_FORMS, Group, WORK};
use crate::{GpuContext, GpuError};

/// The free-form intersection pass.
#[derive(Debug)]
pub struct FreeFormPass {
    kernel: Kernel,
}

impl FreeFormPass {
    /// The groups it binds.
    pub const GROUPS: [Group; 3] = [FRAME, FREE_FORMS, WORK];

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let entry = "intersect_freeform.wgsl";
        let kernel = Kernel::new(setup, entry, &Self::GROUPS)?;
        Ok(Self { kernel })
    }

    /// Casts the rays of `items` work items (bind groups in [`FreeFormPass::GROUPS`] order).
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        groups: [&wgpu::BindGroup; 3],
        items: u32,
    ) {
        self.kernel.run(pass, ctx, &groups, items);
    }
}
