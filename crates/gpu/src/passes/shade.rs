//! Surfaces and shading: one invocation per ray of the band that hit — the surface (a free
//! form's normal and leaf, a terrain's normal, a mesh triangle's face or interpolated normal),
//! the cut face, ambient + Lambert + normalised
//! Phong with each light through the RGB transmittance of a shadow ray that every kind answers
//! any-hit and through the media's transmittance — the fog's, the clouds', and the air's for the
//! sky's sun (`shaders/shade.wgsl`, fray-trace's `Integrator` in f32).

use super::{Kernel, PassSetup};
use crate::bindings::{self, FRAME, FREE_FORMS, Group};
use crate::shader::ModuleOptions;
use crate::{GpuContext, GpuError};

/// The shade pass.
#[derive(Debug)]
pub struct ShadePass {
    kernel: Kernel,
    /// Whether it binds a fourth group (terrains, meshes and/or textures: `bindings::surfaces`).
    surfaces: bool,
}

impl ShadePass {
    /// The groups it binds for a scene composed with `options`: the frame, the free forms, the
    /// lights and materials (with the fog layer, the sky's block and tables and the clouds'
    /// where the scene has them: `bindings::shading`), and only with terrains, meshes or
    /// textures their group (`bindings::surfaces`: any of them together).
    pub fn groups(options: &ModuleOptions) -> Vec<Group> {
        let shading = bindings::shading(options.fog, options.sky, options.clouds, options.whitted);
        let mut groups = vec![FRAME, FREE_FORMS, shading];
        groups.extend(bindings::surfaces(
            options.terrain,
            options.meshes,
            options.textures,
        ));
        groups
    }

    pub fn new(setup: &PassSetup<'_>) -> Result<Self, GpuError> {
        let kernel = Kernel::new(setup, "shade.wgsl", &Self::groups(setup.options))?;
        let o = setup.options;
        let surfaces = bindings::surfaces(o.terrain, o.meshes, o.textures).is_some();
        Ok(Self { kernel, surfaces })
    }

    /// Shades `rays` rays (the band's); `shading` is the group [`ShadePass::groups`] names (with
    /// the scene's media), `surfaces` its terrains-and-meshes group, bound only with terrains or
    /// meshes.
    pub fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        ctx: &GpuContext,
        [frame, free_forms, shading]: [&wgpu::BindGroup; 3],
        surfaces: Option<&wgpu::BindGroup>,
        rays: u32,
    ) {
        let workgroups = rays.div_ceil(64);
        match (self.surfaces, surfaces) {
            (true, Some(s)) => {
                self.kernel
                    .run(pass, ctx, &[frame, free_forms, shading, s], workgroups)
            }
            _ => self
                .kernel
                .run(pass, ctx, &[frame, free_forms, shading], workgroups),
        }
    }

    /// Shades the queue's current level of secondary rays (`crate::passes::whitted`), as many
    /// workgroups as `args` says.
    pub fn encode_indirect(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        [frame, free_forms, shading]: [&wgpu::BindGroup; 3],
        surfaces: Option<&wgpu::BindGroup>,
        args: &wgpu::Buffer,
    ) {
        match (self.surfaces, surfaces) {
            (true, Some(s)) => {
                self.kernel
                    .run_indirect(pass, &[frame, free_forms, shading, s], args)
            }
            _ => self
                .kernel
                .run_indirect(pass, &[frame, free_forms, shading], args),
        }
    }
}
