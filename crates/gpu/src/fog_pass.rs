//! The batch fog pass (one struct, its pipeline and buffers): `shaders/fog.wgsl` over a batch
//! of camera-relative rays through one fog layer, reading back per ray what the fog does to it —
//! transmittance, the ambient and sun factors of its in-scatter, its optical depth, and the
//! transmittance toward the sun from its origin. It is the f32 twin of
//! `fray_atmosphere::FogLayer::{terms, optical_depth, sun_transmittance}`; a parity test bounds
//! the difference. The GPU frame runs the same functions in its media and shade passes.

use crate::bindings::FOG_BATCH;
use crate::passes::PipelineCache;
use crate::readback::{batch_buffers, run_batch};
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use fray_atmosphere::gpu_layout::GpuFog;
use wgpu::util::DeviceExt;

const PASS: &str = "fog";
const WORKGROUP: u32 = 64;

/// What the batch module is composed with (it binds nothing of the scene).
const OPTIONS: ModuleOptions = ModuleOptions {
    fog: true,
    ..ModuleOptions::BATCH
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

/// The batch fog pass of one layer.
#[derive(Debug)]
pub struct FogPass {
    cache: PipelineCache,
    pipeline: std::sync::Arc<wgpu::ComputePipeline>,
    fog: wgpu::Buffer,
}

impl FogPass {
    /// Builds the pipeline and uploads `fog` (its heights already relative to the rays'
    /// reference point).
    pub fn new(ctx: &GpuContext, fog: &GpuFog) -> Result<Self, GpuError> {
        let cache = PipelineCache::default();
        let pipeline = cache.pipeline(
            ctx,
            "fog_batch.wgsl",
            &[FOG_BATCH],
            &OPTIONS,
            &Specialisation::default(),
        )?;
        let fog = ctx
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("fog batch layer"),
                contents: bytemuck::bytes_of(fog),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        Ok(Self {
            cache,
            pipeline,
            fog,
        })
    }

    /// What the fog does to each of `rays`.
    pub fn terms(
        &self,
        ctx: &GpuContext,
        rays: &[GpuFogRay],
    ) -> Result<Vec<GpuFogTerms>, GpuError> {
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        let device = &ctx.device;
        let bytes = (rays.len() * 32) as u64;
        let (ray_buffer, output) =
            batch_buffers(ctx, ("fog batch rays", "fog batch results"), rays, bytes)?;
        let bind_group = FOG_BATCH.bind(
            device,
            &self.cache.layout(ctx, &FOG_BATCH),
            &[
                self.fog.as_entire_binding(),
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
            .map(|[a, b]| GpuFogTerms {
                transmittance: a[0],
                ambient: a[1],
                sun: a[2],
                depth: a[3],
                sun_transmittance: b[0],
                segment_transmittance: b[1],
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batch module (generated struct + fog.wgsl) validates with naga, and its `GpuFog` is
    /// laid out as Rust's (every field in order, at Rust's offset).
    #[test]
    fn fog_wgsl_validates_and_its_struct_layout_matches_rust() {
        let source = crate::shader::compose("fog_batch.wgsl", &OPTIONS).unwrap();
        crate::shader::assert_validates_with_struct::<GpuFog>(&source);
    }
}
