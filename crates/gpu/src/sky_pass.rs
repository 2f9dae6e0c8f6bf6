//! The batch sky pass (one struct and its pipeline): `shaders/sky.wgsl` over a batch of
//! camera-relative queries for one sky seen from one eye ([`SkyBatch`]), reading back per query
//! what the sky gives it — the sky-view table and the background (table and sun's disc) along
//! its direction, the aerial perspective in front of a surface at its distance, the
//! transmittance to the sun at a point and the transmittance table at an altitude and cosine.
//! It is the f32 twin of `fray_atmosphere::sky::{SkyView::{lookup, background},
//! Sky::{aerial_perspective, transmittance_to_sun}, TransmittanceTable::lookup}`; a parity test
//! bounds the difference. The GPU frame runs the same functions in its media and shade passes.

use crate::bindings::SKY_BATCH;
use crate::passes::PipelineCache;
use crate::readback::{batch_buffers, run_batch};
use crate::shader::{ModuleOptions, Specialisation};
use crate::sky_tables::{table_texture, view, write_table};
use crate::{GpuContext, GpuError};
use fray_atmosphere::gpu_layout::GpuSky;
use fray_atmosphere::sky::{SkyViewTable, TransmittanceTable};
use wgpu::util::DeviceExt;

const PASS: &str = "sky";
const WORKGROUP: u32 = 64;
/// vec4s per answer.
const ANSWER_VEC4S: usize = 6;

/// What the batch module is composed with (it binds nothing of a scene).
const OPTIONS: ModuleOptions = ModuleOptions {
    sky: true,
    ..ModuleOptions::BATCH
};

/// One query, relative to the eye: `(ray origin, surface distance t)` (`t ≥ 1e30`: the whole
/// ray), `(unit ray direction, a table altitude h)`, `(a point p, a table cosine μ)`.
pub type GpuSkyQuery = [[f32; 4]; 3];

/// What the sky gave a query, as the GPU found it (RGB each).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuSkyAnswer {
    /// The sky-view table along the direction (`SkyView::lookup`).
    pub view: [f32; 3],
    /// The background along it: the table and, where the block draws it, the sun's disc.
    pub background: [f32; 3],
    /// The aerial perspective over `[0, t]` of the ray (`Sky::aerial_perspective`).
    pub in_scatter: [f32; 3],
    pub transmittance: [f32; 3],
    /// The transmittance to the sun at the point (`Sky::transmittance_to_sun`).
    pub to_sun: [f32; 3],
    /// The transmittance table at `(R_g + h, μ)` (`TransmittanceTable::lookup`).
    pub table: [f32; 3],
}

/// The batch sky pass: its pipeline, built once, for any sky and eye.
#[derive(Debug)]
pub struct SkyPass {
    cache: PipelineCache,
    pipeline: std::sync::Arc<wgpu::ComputePipeline>,
}

/// One sky seen from one eye, as a batch reads it: `GpuSky::new` for the eye, the sky's
/// transmittance table and the eye's sky-view table.
#[derive(Clone, Copy, Debug)]
pub struct SkyBatch<'a> {
    pub block: &'a GpuSky,
    pub transmittance: &'a TransmittanceTable,
    pub view: &'a SkyViewTable,
}

impl SkyPass {
    /// Builds the pipeline.
    pub fn new(ctx: &GpuContext) -> Result<Self, GpuError> {
        let cache = PipelineCache::default();
        let pipeline = cache.pipeline(
            ctx,
            "sky_batch.wgsl",
            &[SKY_BATCH],
            &OPTIONS,
            &Specialisation::default(),
        )?;
        Ok(Self { cache, pipeline })
    }

    /// What `sky` gives each of `queries` (its block and tables uploaded for this batch).
    pub fn answers(
        &self,
        ctx: &GpuContext,
        sky: SkyBatch<'_>,
        queries: &[GpuSkyQuery],
    ) -> Result<Vec<GpuSkyAnswer>, GpuError> {
        if queries.is_empty() {
            return Ok(Vec::new());
        }
        let device = &ctx.device;
        let bytes = (queries.len() * ANSWER_VEC4S * 16) as u64;
        let (query_buffer, output) = batch_buffers(
            ctx,
            ("sky batch queries", "sky batch results"),
            queries,
            bytes,
        )?;
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("sky batch parameters"),
            contents: bytemuck::bytes_of(sky.block),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let mut charges = crate::DeviceCharges::unlimited();
        let mut table = |label, width, height, texels: &[[f32; 4]]| {
            let texture = table_texture(ctx, &mut charges, label, width, height)?;
            write_table(ctx, &texture, width, texels);
            Ok::<_, GpuError>(texture)
        };
        let t = sky.transmittance;
        let transmittance = table(
            "sky batch transmittance table",
            t.width(),
            t.height(),
            t.texels(),
        )?;
        let v = sky.view;
        let sky_view = table(
            "sky batch sky-view table",
            v.width(),
            v.height(),
            v.texels(),
        )?;
        let (tv, vv) = (view(&transmittance), view(&sky_view));
        let bind_group = SKY_BATCH.bind(
            device,
            &self.cache.layout(ctx, &SKY_BATCH),
            &[
                params.as_entire_binding(),
                wgpu::BindingResource::TextureView(&tv),
                wgpu::BindingResource::TextureView(&vv),
                query_buffer.as_entire_binding(),
                output.as_entire_binding(),
            ],
        );
        let raw: Vec<[[f32; 4]; ANSWER_VEC4S]> = run_batch(
            ctx,
            &self.pipeline,
            &[&bind_group],
            queries.len() as u32,
            WORKGROUP,
            &output,
            bytes,
            PASS,
        )?;
        let rgb = |v: [f32; 4]| [v[0], v[1], v[2]];
        Ok(raw
            .iter()
            .map(|a| GpuSkyAnswer {
                view: rgb(a[0]),
                background: rgb(a[1]),
                in_scatter: rgb(a[2]),
                transmittance: rgb(a[3]),
                to_sun: rgb(a[4]),
                table: rgb(a[5]),
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The batch module (generated structs + sky.wgsl) validates with naga, and its `GpuSky` is
    /// laid out as Rust's (every field in order, at Rust's offset).
    #[test]
    fn sky_wgsl_validates_and_its_struct_layout_matches_rust() {
        let source = crate::shader::compose("sky_batch.wgsl", &OPTIONS).unwrap();
        crate::shader::assert_validates_with_struct::<GpuSky>(&source);
    }
}
