//! Surfaces and shading: one invocation per ray of the band that hit — the surface (a free
//! form's normal and leaf, a terrain's normal), the cut face, ambient + Lambert + normalised
//! Phong with each light through a shadow ray that every kind answers any-hit
//! (`shaders/shade.wgsl`, fray-trace's `Integrator` in f32).

use super::{PipelineCache, dispatch};
use crate::bindings::{FRAME, FREE_FORMS, Group, SHADING, TERRAINS};
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use std::sync::Arc;

/// The shade pass.
#[derive(Debug)]
pub struct ShadePass {
    pipeline: Arc<wgpu::ComputePipeline>,
    terrain: bool,
}

impl ShadePass {
    /// The groups it binds (the terrains' only with terrains).
    pub const GROUPS: [Group; 4] = [FRAME, FREE_FORMS, SHADING, TERRAINS];

    pub fn new(
        cache: &PipelineCache,
        ctx: &GpuContext,
        options: &ModuleOptions,
        specialisation: &Specialisation,
    ) -> Result<Self, GpuError> {
        let groups = if options.terrain {
            &Self::GROUPS[..]
        } else {
            &Self::GROUPS[..3]
        };
        let pipeline = cache.pipeline(ctx, "shade.wgsl", groups, options, specialisation)?;
        Ok(Self {
            pipeline,
            terrain: options.terrain,
        })
    }

    /// Shades `rays` rays (the band's).
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        [frame, free_forms, shading]: [&wgpu::BindGroup; 3],
        terrains: Option<&wgpu::BindGroup>,
        rays: u32,
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, frame, &[]);
        pass.set_bind_group(1, free_forms, &[]);
        pass.set_bind_group(2, shading, &[]);
        if let (true, Some(t)) = (self.terrain, terrains) {
            pass.set_bind_group(3, t, &[]);
        }
        dispatch(pass, ctx, rays.div_ceil(64));
    }
}
