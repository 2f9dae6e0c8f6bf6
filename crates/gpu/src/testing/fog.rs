//! The fog's batch kernel (`shaders/fog_batch.wgsl`): `fog.wgsl` on camera-relative rays through
//! one fog layer, reading back per ray what the fog does to it — transmittance, the ambient and
//! sun factors of its in-scatter, its optical depth, and the transmittance toward the sun from
//! its origin: the f32 twin of `fray_atmosphere::FogLayer::{terms, optical_depth,
//! sun_transmittance}`. The frame runs the same functions in its media and shade passes.

use super::batch::{BatchPass, Kernel, floats};
use crate::bindings::FOG_LAYER;
use crate::shader::ModuleOptions;
use crate::{GpuContext, GpuError};
use fray_atmosphere::gpu_layout::GpuFog;

/// The kernel: one fog layer.
pub const KERNEL: Kernel = Kernel {
    label: "fog",
    module: "fog_batch.wgsl",
    options: ModuleOptions::BATCH.with(crate::features::Feature::Fog),
    data: &[FOG_LAYER],
    query_rows: 3,
    answer_rows: 2,
};

/// One ray of a batch, relative to the fog's reference point: `(origin, t_lo)`,
/// `(unit direction, t_hi)` (`t_hi ≥ 1e30`: unbounded), `(unit direction toward a sun, 0)`.
pub type GpuFogRay = [[f32; 4]; 3];

/// What the fog did to a batch ray, as the GPU found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuFogTerms {
    /// `e^{−τ}` over the ray's range.
    pub transmittance: f32,
    /// `1 − e^{−τ}`: `albedo · ambient` times this is the ambient light's in-scatter.
    pub ambient: f32,
    /// `albedo · irradiance` times this is the sun's in-scatter (phase included), by the
    /// layer's model.
    pub sun: f32,
    /// The optical depth `τ` (`≥ 1e30`: unbounded).
    pub depth: f32,
    /// The transmittance toward the sun from the ray's origin (`FogLayer::sun_transmittance`).
    pub sun_transmittance: f32,
    /// `e^{−τ}` again, by `fog_optical_depth` (the shade pass's point-light path).
    pub segment_transmittance: f32,
}

/// One fog layer uploaded for the kernel.
#[derive(Debug)]
pub struct FogBatch {
    pass: BatchPass,
    layer: wgpu::BindGroup,
}

impl FogBatch {
    /// Uploads `fog` (its heights already relative to the rays' reference point).
    pub fn new(ctx: &GpuContext, fog: &GpuFog) -> Result<Self, GpuError> {
        let layer = crate::bindings::upload(
            ctx,
            "fog batch layer",
            &[*fog],
            bytemuck::Zeroable::zeroed(),
            wgpu::BufferUsages::UNIFORM,
        )?;
        let pass = BatchPass::new(ctx, KERNEL)?;
        let layer = pass.bind(ctx, &FOG_LAYER, &[layer.as_entire_binding()]);
        Ok(Self { pass, layer })
    }

    /// What the fog does to each of `rays`.
    pub fn terms(
        &self,
        ctx: &GpuContext,
        rays: &[GpuFogRay],
    ) -> Result<Vec<GpuFogTerms>, GpuError> {
        let queries: Vec<[f32; 4]> = rays.iter().flatten().copied().collect();
        let words = self.pass.run(ctx, &queries, [0; 3], &[&self.layer])?;
        Ok(words
            .chunks_exact(2)
            .map(|w| {
                let (a, b) = (floats(w[0]), floats(w[1]));
                GpuFogTerms {
                    transmittance: a[0],
                    ambient: a[1],
                    sun: a[2],
                    depth: a[3],
                    sun_transmittance: b[0],
                    segment_transmittance: b[1],
                }
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fog kernel's `GpuFog` is laid out as Rust's (every field in order, at Rust's offset).
    #[test]
    fn the_fog_kernels_struct_layout_matches_rust() {
        let source = crate::shader::compose(KERNEL.module, &KERNEL.options).unwrap();
        crate::shader::assert_validates_with_struct::<GpuFog>(&source);
    }
}
