//! The batch clouds pass (one struct, its pipeline and textures): `shaders/clouds.wgsl` over a
//! batch of rays through one cloud volume, reading back per ray what the march does to it —
//! transmittance, in-scatter, density samples — its optical depth, the density at its origin and
//! a pixel's jitter. It is the f32 twin of `fray_clouds::march::{march, optical_depth,
//! pixel_jitter}` and `GridVolume::density`; a parity test bounds the difference. The GPU frame
//! runs the same functions in its media and shade passes.

use crate::bindings::CLOUDS_BATCH;
use crate::cloud_textures::CloudTextures;
use crate::passes::PipelineCache;
use crate::readback::{batch_buffers, run_batch};
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use fray_clouds::gpu_layout::GpuClouds;
use fray_clouds::march::GridVolume;
use wgpu::util::DeviceExt;

const PASS: &str = "clouds";
const WORKGROUP: u32 = 64;

/// What the batch module is composed with (it binds nothing of a scene).
const OPTIONS: ModuleOptions = ModuleOptions {
    clouds: true,
    ..ModuleOptions::BATCH
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

/// The batch clouds pass of one volume.
#[derive(Debug)]
pub struct CloudsPass {
    cache: PipelineCache,
    pipeline: std::sync::Arc<wgpu::ComputePipeline>,
    params: wgpu::Buffer,
    textures: CloudTextures,
}

impl CloudsPass {
    /// Builds the pipeline and uploads `volume`'s grids and `block` (its parameters, relative to
    /// the rays' reference point).
    pub fn new(ctx: &GpuContext, volume: &GridVolume, block: &GpuClouds) -> Result<Self, GpuError> {
        let cache = PipelineCache::default();
        let pipeline = cache.pipeline(
            ctx,
            "clouds_batch.wgsl",
            &[CLOUDS_BATCH],
            &OPTIONS,
            &Specialisation::default(),
        )?;
        let params = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("clouds batch block"),
                contents: bytemuck::bytes_of(block),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let (textures, _) =
            CloudTextures::upload(ctx, &mut crate::DeviceCharges::unlimited(), volume)?;
        Ok(Self {
            cache,
            pipeline,
            params,
            textures,
        })
    }

    /// What the cloud does to each of `rays`.
    pub fn terms(
        &self,
        ctx: &GpuContext,
        rays: &[GpuCloudRay],
    ) -> Result<Vec<GpuCloudTerms>, GpuError> {
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        let device = &ctx.device;
        let bytes = (rays.len() * 32) as u64;
        let (ray_buffer, output) = batch_buffers(
            ctx,
            ("clouds batch rays", "clouds batch results"),
            rays,
            bytes,
        )?;
        let (density, max) = self.textures.views();
        let bind_group = CLOUDS_BATCH.bind(
            device,
            &self.cache.layout(ctx, &CLOUDS_BATCH),
            &[
                self.params.as_entire_binding(),
                wgpu::BindingResource::TextureView(&density),
                wgpu::BindingResource::TextureView(&max),
                ray_buffer.as_entire_binding(),
                output.as_entire_binding(),
            ],
        );
        let raw: Vec<[[f32; 4]; 2]> = run_batch(
            ctx,
            &self.pipeline,
            &[&bind_group],
            rays.len() as u32,
            WORKGROUP,
            &output,
            bytes,
            PASS,
        )?;
        Ok(raw
            .iter()
            .map(|[a, b]| GpuCloudTerms {
                transmittance: a[0],
                in_scatter: [a[1], a[2], a[3]],
                samples: b[0] as u32,
                optical_depth: b[1],
                density: b[2],
                pixel_jitter: b[3],
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batch module (generated struct + clouds.wgsl) validates with naga, and its
    /// `GpuClouds` is laid out as Rust's (every field in order, at Rust's offset).
    #[test]
    fn clouds_wgsl_validates_and_its_struct_layout_matches_rust() {
        let source = crate::shader::compose("clouds_batch.wgsl", &OPTIONS).unwrap();
        crate::shader::assert_validates_with_struct::<GpuClouds>(&source);
    }
}
