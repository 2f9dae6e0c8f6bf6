//! The clouds' batch kernel (`shaders/clouds_batch.wgsl`): `clouds.wgsl` on rays through one
//! cloud volume, reading back per ray what the march does to it — transmittance, in-scatter,
//! density samples — its optical depth, the density at its origin and a pixel's jitter: the f32
//! twin of `fray_clouds::march::{march, optical_depth, pixel_jitter}` and
//! `GridVolume::density`. The frame runs the same functions in its media and shade passes.

use super::batch::{BatchPass, Kernel, floats};
use crate::bindings::CLOUD_VOLUME;
use crate::media::clouds::CloudTextures;
use crate::shader::ModuleOptions;
use crate::{DeviceCharges, GpuContext, GpuError};
use fray_clouds::gpu_layout::GpuClouds;
use fray_clouds::march::GridVolume;

/// The kernel: one cloud volume.
pub const KERNEL: Kernel = Kernel {
    label: "clouds",
    module: "clouds_batch.wgsl",
    options: ModuleOptions::BATCH.with(crate::features::Feature::Clouds),
    data: &[CLOUD_VOLUME],
    query_rows: 3,
    answer_rows: 2,
};

/// One ray of a batch, relative to the block's reference point: `(origin, t0)`,
/// `(unit direction, t1)` (`t1 ≥ 1e30`: unbounded), `(jitter, pixel x, pixel y, 0)`.
pub type GpuCloudRay = [[f32; 4]; 3];

/// What the cloud did to a batch ray, as the GPU found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuCloudTerms {
    /// The march over `[t0, t1]`: `L = transmittance · L_behind + in_scatter`.
    pub transmittance: f32,
    pub in_scatter: [f32; 3],
    /// Its density samples.
    pub samples: u32,
    /// The optical depth over `[t0, t1]` (`optical_depth`, at the march's step).
    pub optical_depth: f32,
    /// The extinction at the ray's origin.
    pub density: f32,
    /// `pixel_jitter` of the ray's pixel.
    pub pixel_jitter: f32,
}

/// One cloud volume uploaded for the kernel.
#[derive(Debug)]
pub struct CloudsBatch {
    pass: BatchPass,
    volume: wgpu::BindGroup,
}

impl CloudsBatch {
    /// Uploads `volume`'s grids and `block` (its parameters, relative to the rays' reference
    /// point).
    pub fn new(ctx: &GpuContext, volume: &GridVolume, block: &GpuClouds) -> Result<Self, GpuError> {
        let params = crate::bindings::upload(
            ctx,
            "clouds batch block",
            &[*block],
            bytemuck::Zeroable::zeroed(),
            wgpu::BufferUsages::UNIFORM,
        )?;
        let (textures, _) = CloudTextures::upload(ctx, &mut DeviceCharges::unlimited(), volume)?;
        let (density, max) = textures.views();
        let pass = BatchPass::new(ctx, KERNEL)?;
        let volume = pass.bind(
            ctx,
            &CLOUD_VOLUME,
            &[
                params.as_entire_binding(),
                wgpu::BindingResource::TextureView(&density),
                wgpu::BindingResource::TextureView(&max),
            ],
        );
        Ok(Self { pass, volume })
    }

    /// What the cloud does to each of `rays`.
    pub fn terms(
        &self,
        ctx: &GpuContext,
        rays: &[GpuCloudRay],
    ) -> Result<Vec<GpuCloudTerms>, GpuError> {
        let queries: Vec<[f32; 4]> = rays.iter().flatten().copied().collect();
        let words = self.pass.run(ctx, &queries, [0; 3], &[&self.volume])?;
        Ok(words
            .chunks_exact(2)
            .map(|w| {
                let (a, b) = (floats(w[0]), floats(w[1]));
                GpuCloudTerms {
                    transmittance: a[0],
                    in_scatter: [a[1], a[2], a[3]],
                    samples: b[0] as u32,
                    optical_depth: b[1],
                    density: b[2],
                    pixel_jitter: b[3],
                }
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The clouds kernel's `GpuClouds` is laid out as Rust's (every field in order, at Rust's
    /// offset).
    #[test]
    fn the_clouds_kernels_struct_layout_matches_rust() {
        let source = crate::shader::compose(KERNEL.module, &KERNEL.options).unwrap();
        crate::shader::assert_validates_with_struct::<GpuClouds>(&source);
    }
}
