//! Ray generation: the camera rays of a band of rows — per pixel its centre and, with
//! anti-aliasing, its samples — into the frame's paths (`shaders/raygen.wgsl`). The CPU twin is
//! `fray_core::Projector::ray` with `fray_core::PixelSamples`; `tests/passes.rs` checks the rays.

use super::{PipelineCache, dispatch};
use crate::bindings::{FRAME, Group};
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use std::sync::Arc;

/// The ray generation pass.
#[derive(Debug)]
pub struct RayGenPass {
    pipeline: Arc<wgpu::ComputePipeline>,
}

impl RayGenPass {
    /// The groups it binds.
    pub const GROUPS: [Group; 1] = [FRAME];

    pub fn new(
        cache: &PipelineCache,
        ctx: &GpuContext,
        options: &ModuleOptions,
        specialisation: &Specialisation,
    ) -> Result<Self, GpuError> {
        let pipeline =
            cache.pipeline(ctx, "raygen.wgsl", &Self::GROUPS, options, specialisation)?;
        Ok(Self { pipeline })
    }

    /// Generates `rays` rays (the band's pixels × rays per pixel).
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        frame: &wgpu::BindGroup,
        rays: u32,
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, frame, &[]);
        dispatch(pass, ctx, rays.div_ceil(64));
    }
}
