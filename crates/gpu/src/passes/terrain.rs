//! The terrain intersection pass: one workgroup per work item of the band, each pixel's camera
//! rays cast against the item's terrain candidates at their pixel level of detail
//! (`shaders/terrain.wgsl`, the f32 twin of `fray_terrain::Terrain::cast_footprint`) over
//! `[t_near, nearest hit so far]`, narrowing the paths' hits after the free forms. Built only
//! for scenes with terrains.

use super::{Kernel, PassSetup};
use crate::bindings::{FRAME, Group, TERRAINS, WORK};
use crate::{GpuContext, GpuError};

/// The terrain intersection pass.
#[derive(Debug)]
pub struct TerrainIntersectPass {
    kernel: Kernel,
}

impl TerrainIntersectPass {
    /// The groups it binds.
    pub const GROUPS: [Group; 3] = [FRAME, WORK, TERRAINS];

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let entry = "intersect_terrain.wgsl";
        let kernel = Kernel::new(setup, entry, &Self::GROUPS)?;
        Ok(Self { kernel })
    }

    /// Casts the rays of `items` work items at their terrain candidates (bind groups in
    /// [`TerrainIntersectPass::GROUPS`] order).
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
