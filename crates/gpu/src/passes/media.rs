//! The media pass, between shade and resolve: one invocation per ray of the band, the radiance
//! reaching the camera through the scene's fog — `T · L_surface + L_in` over `[t_near, t_hit]`
//! for a hit, `T · background + L_in` over `[t_near, ∞)` for a miss (`shaders/media.wgsl` over
//! `shaders/fog.wgsl`, the f32 twin of fray-trace's `Media` and fray-atmosphere's `FogLayer`).
//! Built only for scenes with fog; resolve is then specialised to take every ray's radiance.

use super::{Kernel, PassSetup};
use crate::bindings::{FRAME, Group, SHADING_FOG};
use crate::{GpuContext, GpuError};

/// The media pass.
#[derive(Debug)]
pub struct MediaPass {
    kernel: Kernel,
}

impl MediaPass {
    /// The groups it binds: the frame (paths), the lights (suns, ambient in the frame) with the
    /// fog layer.
    pub const GROUPS: [Group; 2] = [FRAME, SHADING_FOG];

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let kernel = Kernel::new(setup, "media.wgsl", &Self::GROUPS)?;
        Ok(Self { kernel })
    }

    /// Takes `rays` rays (the band's) through the fog.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        groups: [&wgpu::BindGroup; 2],
        rays: u32,
    ) {
        self.kernel.run(pass, ctx, &groups, rays.div_ceil(64));
    }
}
