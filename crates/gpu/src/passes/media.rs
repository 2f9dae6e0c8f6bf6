//! The media pass, between shade and resolve: one invocation per ray of the band, the radiance
//! reaching the camera through the scene's media — `T · L_surface + L_in` over `[t_near, t_hit]`
//! for a hit (the fog's terms, the sky's air and the cloud volume's march composed in the CPU's
//! order), `T · background + L_in` over `[t_near, ∞)` for a miss (the sky's background, or the
//! scene's colour, through the fog and the clouds) — `shaders/media.wgsl` over
//! `shaders/fog.wgsl`, `shaders/sky.wgsl` and `shaders/clouds.wgsl`, the f32 twins of
//! fray-trace's `Media`, fray-atmosphere's `FogLayer` and `Sky` and fray-clouds' `march`. Built
//! only for scenes with fog, a sky or clouds; resolve is then specialised to take every ray's
//! radiance.

use super::{Kernel, PassSetup};
use crate::bindings::{self, FRAME, Group};
use crate::shader::ModuleOptions;
use crate::{GpuContext, GpuError};

/// The media pass.
#[derive(Debug)]
pub struct MediaPass {
    kernel: Kernel,
}

impl MediaPass {
    /// The groups it binds for a scene composed with `options`: the frame (paths), the lights
    /// (suns, ambient in the frame) with the fog layer, the sky and the clouds
    /// (`bindings::shading`).
    pub fn groups(options: &ModuleOptions) -> [Group; 2] {
        [
            FRAME,
            bindings::shading(options.fog, options.sky, options.clouds, options.whitted),
        ]
    }

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let kernel = Kernel::new(setup, "media.wgsl", &Self::groups(setup.options))?;
        Ok(Self { kernel })
    }

    /// Takes `rays` rays (the band's) through the media.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        groups: [&wgpu::BindGroup; 2],
        rays: u32,
    ) {
        self.kernel.run(pass, ctx, &groups, rays.div_ceil(64));
    }

    /// Takes the queue's current level of secondary rays through the media
    /// (`crate::passes::whitted`), as many workgroups as `args` says.
    pub fn encode_indirect(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        groups: [&wgpu::BindGroup; 2],
        args: &wgpu::Buffer,
    ) {
        self.kernel.run_indirect(pass, &groups, args);
    }
}
