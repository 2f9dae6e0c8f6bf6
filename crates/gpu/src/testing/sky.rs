//! The sky's batch kernel (`shaders/sky_batch.wgsl`): `sky.wgsl` on camera-relative queries
//! for one sky seen from one eye ([`SkySeen`]), reading back per query what the sky gives it —
//! the sky-view table and the background (table and sun's disc) along its direction, the aerial
//! perspective in front of a surface at its distance, the transmittance to the sun at a point and
//! the transmittance table at an altitude and cosine: the f32 twin of
//! `fray_atmosphere::sky::{SkyView::{lookup, background}, Sky::{aerial_perspective,
//! transmittance_to_sun}, TransmittanceTable::lookup}`. The frame runs the same functions in its
//! media and shade passes.

use super::batch::{BatchPass, Kernel, floats};
use crate::bindings::SKY_TABLES;
use crate::media::sky::{table_texture, view, write_table};
use crate::shader::ModuleOptions;
use crate::{DeviceCharges, GpuContext, GpuError};
use fray_atmosphere::gpu_layout::GpuSky;
use fray_atmosphere::sky::{SkyViewTable, TransmittanceTable};

/// The kernel: one sky.
pub const KERNEL: Kernel = Kernel {
    label: "sky",
    module: "sky_batch.wgsl",
    options: ModuleOptions::BATCH.with(crate::features::Feature::Sky),
    data: &[SKY_TABLES],
    query_rows: 3,
    answer_rows: 6,
};

/// One query, relative to the eye: `(ray origin, surface distance t)` (`t ≥ 1e30`: the whole
/// ray), `(unit ray direction, a table altitude h)`, `(a point p, a table cosine μ)`.
pub type GpuSkyQuery = [[f32; 4]; 3];

/// The query at `origin` along `dir` with the surface at `t`, the sun asked at `point`, the
/// table at `table` = (altitude, cosine), in the kernel's f32 rows.
pub fn sky_query(
    origin: glam::DVec3,
    dir: glam::DVec3,
    t: f64,
    point: glam::DVec3,
    table: (f64, f64),
) -> GpuSkyQuery {
    let (o, d, p) = (origin.as_vec3(), dir.as_vec3(), point.as_vec3());
    let t = t.min(1e30) as f32;
    let (h, mu) = (table.0 as f32, table.1 as f32);
    [[o.x, o.y, o.z, t], [d.x, d.y, d.z, h], [p.x, p.y, p.z, mu]]
}

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

/// One sky seen from one eye, as the kernel reads it: `GpuSky::new` for the eye, the sky's
/// transmittance table and the eye's sky-view table.
#[derive(Clone, Copy, Debug)]
pub struct SkySeen<'a> {
    pub block: &'a GpuSky,
    pub transmittance: &'a TransmittanceTable,
    pub view: &'a SkyViewTable,
}

/// The sky's kernel, for any sky and eye.
#[derive(Debug)]
pub struct SkyBatch {
    pass: BatchPass,
}

impl SkyBatch {
    /// Builds the kernel's pipeline.
    pub fn new(ctx: &GpuContext) -> Result<Self, GpuError> {
        Ok(Self {
            pass: BatchPass::new(ctx, KERNEL)?,
        })
    }

    /// What `sky` gives each of `queries` (its block and tables uploaded for this batch).
    pub fn answers(
        &self,
        ctx: &GpuContext,
        sky: SkySeen<'_>,
        queries: &[GpuSkyQuery],
    ) -> Result<Vec<GpuSkyAnswer>, GpuError> {
        if queries.is_empty() {
            return Ok(Vec::new());
        }
        let params = crate::bindings::upload(
            ctx,
            "sky batch parameters",
            &[*sky.block],
            bytemuck::Zeroable::zeroed(),
            wgpu::BufferUsages::UNIFORM,
        )?;
        let mut charges = DeviceCharges::unlimited();
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
        let tables = self.pass.bind(
            ctx,
            &SKY_TABLES,
            &[
                params.as_entire_binding(),
                wgpu::BindingResource::TextureView(&tv),
                wgpu::BindingResource::TextureView(&vv),
            ],
        );
        let queries: Vec<[f32; 4]> = queries.iter().flatten().copied().collect();
        let words = self.pass.run(ctx, &queries, [0; 3], &[&tables])?;
        let rgb = |w: [u32; 4]| {
            let v = floats(w);
            [v[0], v[1], v[2]]
        };
        Ok(words
            .chunks_exact(6)
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

    /// The sky kernel's `GpuSky` is laid out as Rust's (every field in order, at Rust's offset).
    #[test]
    fn the_sky_kernels_struct_layout_matches_rust() {
        let source = crate::shader::compose(KERNEL.module, &KERNEL.options).unwrap();
        crate::shader::assert_validates_with_struct::<GpuSky>(&source);
    }
}
