//! The terrain intersection pass: one workgroup per work item of the band, each pixel's camera
//! rays cast against the item's terrain candidates at their pixel level of detail
//! (`shaders/terrain.wgsl`, the f32 twin of `fray_terrain::Terrain::cast_footprint`) over
//! `[t_near, nearest hit so far]`, narrowing the paths' hits after the free forms. Built only
//! for scenes with terrains.

use super::{PipelineCache, dispatch};
use crate::bindings::{FRAME, Group, TERRAINS, WORK};
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use std::sync::Arc;

/// The terrain intersection pass.
#[derive(Debug)]
pub struct TerrainIntersectPass {
    pipeline: Arc<wgpu::ComputePipeline>,
}

impl TerrainIntersectPass {
    /// The groups it binds.
    pub const GROUPS: [Group; 3] = [FRAME, WORK, TERRAINS];

    pub fn new(
        cache: &PipelineCache,
        ctx: &GpuContext,
        options: &ModuleOptions,
        specialisation: &Specialisation,
    ) -> Result<Self, GpuError> {
        let pipeline = cache.pipeline(
            ctx,
            "intersect_terrain.wgsl",
            &Self::GROUPS,
            options,
            specialisation,
        )?;
        Ok(Self { pipeline })
    }

    /// Casts the rays of `items` work items at their terrain candidates.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        [frame, work, terrains]: [&wgpu::BindGroup; 3],
        items: u32,
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, frame, &[]);
        pass.set_bind_group(1, work, &[]);
        pass.set_bind_group(2, terrains, &[]);
        dispatch(pass, ctx, items);
    }
}
