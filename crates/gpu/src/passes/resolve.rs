//! Resolve: the band's pixels from their camera rays — colour the samples' box-filtered
//! radiance, depth and normal from the centre ray — into the frame's storage textures, with the
//! tone-mapped sRGB display image made on the GPU (`shaders/resolve.wgsl`; the CPU twins are the
//! frame loop's box filter, `fray_core::ToneMap` and `linear_to_srgb`).

use super::PipelineCache;
use crate::bindings::{FRAME, Group, TARGETS};
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use std::sync::Arc;

/// The resolve pass.
#[derive(Debug)]
pub struct ResolvePass {
    pipeline: Arc<wgpu::ComputePipeline>,
}

impl ResolvePass {
    /// The groups it binds.
    pub const GROUPS: [Group; 2] = [FRAME, TARGETS];

    pub fn new(
        cache: &PipelineCache,
        ctx: &GpuContext,
        options: &ModuleOptions,
        specialisation: &Specialisation,
    ) -> Result<Self, GpuError> {
        let pipeline =
            cache.pipeline(ctx, "resolve.wgsl", &Self::GROUPS, options, specialisation)?;
        Ok(Self { pipeline })
    }

    /// Resolves a band `width` pixels wide and `rows` tall.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        [frame, targets]: [&wgpu::BindGroup; 2],
        width: u32,
        rows: u32,
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, frame, &[]);
        pass.set_bind_group(1, targets, &[]);
        pass.dispatch_workgroups(width.div_ceil(8), rows.div_ceil(8), 1);
    }
}
