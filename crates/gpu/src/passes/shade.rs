//! Surfaces and shading: one invocation per ray of the band that hit — the surface (a free
//! form's normal and leaf, a terrain's normal), the cut face, ambient + Lambert + normalised
//! Phong with each light through the RGB transmittance of a shadow ray that every kind answers
//! any-hit (`shaders/shade.wgsl`, fray-trace's `Integrator` in f32).

use super::{Kernel, PassSetup};
use crate::bindings::{FRAME, FREE_FORMS, Group, SHADING, TERRAINS};
use crate::{GpuContext, GpuError};

/// The shade pass.
#[derive(Debug)]
pub struct ShadePass {
    kernel: Kernel,
    terrain: bool,
}

impl ShadePass {
    /// The groups it binds (the terrains' only with terrains).
    pub const GROUPS: [Group; 4] = [FRAME, FREE_FORMS, SHADING, TERRAINS];

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let groups = if setup.options.terrain {
            &Self::GROUPS[..]
        } else {
            &Self::GROUPS[..3]
        };
        let kernel = Kernel::new(setup, "shade.wgsl", groups)?;
        Ok(Self {
            kernel,
            terrain: setup.options.terrain,
        })
    }

    /// Shades `rays` rays (the band's); `terrains` is bound only with terrains.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        [frame, free_forms, shading]: [&wgpu::BindGroup; 3],
        terrains: Option<&wgpu::BindGroup>,
        rays: u32,
    ) {
        let workgroups = rays.div_ceil(64);
        match (self.terrain, terrains) {
            (true, Some(t)) => {
                self.kernel
                    .run(pass, ctx, &[frame, free_forms, shading, t], workgroups)
            }
            _ => self
                .kernel
                .run(pass, ctx, &[frame, free_forms, shading], workgroups),
        }
    }
}
