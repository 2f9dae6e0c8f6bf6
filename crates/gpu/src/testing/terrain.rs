//! The terrain's batch kernel (`shaders/terrain_batch.wgsl`): `terrain.wgsl`'s `cast_terrain`
//! on rays given by the caller against one terrain, reading back per ray the hit `(t, normal)`
//! and `(kind, levels above the finest, cell)` — the f32 twin of
//! `fray_terrain::Terrain::cast_footprint` (bilinear and B-spline bicubic, walls, starts, pixel
//! LOD), over the arrays the resident scene uploads (`crate::kinds::terrain`).

use super::batch::{BatchPass, Kernel, floats};
use crate::bindings::{self, TERRAINS};
use crate::kinds::terrain::{TerrainUpload, terrain_arrays};
use crate::shader::ModuleOptions;
use crate::{DeviceCharges, GpuContext, GpuError};
use fray_core::PixelFootprint;
use fray_terrain::Terrain;
use fray_terrain::gpu_layout::GpuTerrainParams;
use glam::DVec3;

/// The kernel: one terrain.
pub const KERNEL: Kernel = Kernel {
    label: "terrain",
    module: "terrain_batch.wgsl",
    options: ModuleOptions::BATCH.with(crate::features::Feature::Kind(
        fray_scene::PrimitiveKind::Terrain,
    )),
    data: &[TERRAINS],
    query_rows: 2,
    answer_rows: 2,
};

/// One ray of a batch, relative to the pass's reference point: `(origin, t_lo)`,
/// `(unit direction, t_hi)`.
pub type GpuRay = [[f32; 4]; 2];

/// What a batch ray hit, as the GPU found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuTerrainHit {
    /// Distance along the ray; negative for a miss.
    pub t: f32,
    /// The hit's normal (`Terrain::cast`'s: a LOD hit's is its column face's).
    pub normal: [f32; 3],
    /// 0 surface, 1 wall, 2 the ray's start (`fray_terrain::HitKind`'s order).
    pub kind: u32,
    /// 0 on the exact surface, `k` on a level-`(n − k)` max column.
    pub levels_above_finest: u32,
    /// The cell (column) hit.
    pub cell: [u32; 2],
}

impl GpuTerrainHit {
    /// Whether the ray hit.
    pub fn is_hit(&self) -> bool {
        self.t >= 0.0
    }

    /// The kind as `fray_terrain::HitKind`.
    pub fn hit_kind(&self) -> fray_terrain::HitKind {
        match self.kind {
            1 => fray_terrain::HitKind::Wall,
            2 => fray_terrain::HitKind::Start,
            _ => fray_terrain::HitKind::Surface,
        }
    }
}

/// One terrain uploaded for the kernel, relative to a reference point.
#[derive(Debug)]
pub struct TerrainBatch {
    pass: BatchPass,
    terrains: wgpu::BindGroup,
    /// Cast with the pixel footprint (1) or exactly (0).
    pixel_lod: u32,
    epsilon: f32,
}

impl TerrainBatch {
    /// Uploads `terrain` relative to `reference` (the camera), casting exactly, with the bicubic
    /// tolerance at its f32 floor (see [`TerrainBatch::with_epsilon`]).
    pub fn new(ctx: &GpuContext, terrain: &Terrain, reference: DVec3) -> Result<Self, GpuError> {
        Self::build(ctx, terrain, reference, PixelFootprint::ZERO)
    }

    /// [`TerrainBatch::new`] casting with the pixel footprint `footprint` (as
    /// `fray_terrain::Terrain::cast_footprint` takes it: already widened by the LOD bias).
    pub fn with_pixel_lod(
        ctx: &GpuContext,
        terrain: &Terrain,
        reference: DVec3,
        footprint: PixelFootprint,
    ) -> Result<Self, GpuError> {
        Self::build(ctx, terrain, reference, footprint)
    }

    /// This batch with the bicubic root tolerance `eps` (world units; `Terrain::cast`'s `eps`),
    /// raised on the GPU to `8 ε_f32` of the piece searched.
    pub fn with_epsilon(mut self, eps: f64) -> Self {
        self.epsilon = eps as f32;
        self
    }

    fn build(
        ctx: &GpuContext,
        terrain: &Terrain,
        reference: DVec3,
        footprint: PixelFootprint,
    ) -> Result<Self, GpuError> {
        let upload = TerrainUpload {
            terrain,
            material: 0,
            footprint,
        };
        let (params, pyramid, samples) =
            terrain_arrays(ctx, &mut DeviceCharges::unlimited(), &[upload], reference)?;
        use wgpu::BufferUsages as U;
        let params_buffer = bindings::upload(
            ctx,
            "terrain params",
            &params,
            GpuTerrainParams::default(),
            U::UNIFORM,
        )?;
        let lods: Vec<[f32; 4]> = params.iter().map(|p| p.lod).collect();
        let lods = bindings::upload(ctx, "terrain lods", &lods, [0.0; 4], U::UNIFORM)?;
        let pass = BatchPass::new(ctx, KERNEL)?;
        let terrains = pass.bind(
            ctx,
            &TERRAINS,
            &[
                params_buffer.as_entire_binding(),
                lods.as_entire_binding(),
                pyramid.as_entire_binding(),
                samples.as_entire_binding(),
            ],
        );
        Ok(Self {
            pass,
            terrains,
            pixel_lod: u32::from(!footprint.is_zero()),
            epsilon: 0.0,
        })
    }

    /// Casts `rays` (relative to the reference point); per ray `(t, normal)`, `t < 0` for a miss.
    pub fn cast(&self, ctx: &GpuContext, rays: &[GpuRay]) -> Result<Vec<[f32; 4]>, GpuError> {
        Ok(self
            .cast_hits(ctx, rays)?
            .iter()
            .map(|h| [h.t, h.normal[0], h.normal[1], h.normal[2]])
            .collect())
    }

    /// Casts `rays` (relative to the reference point): every hit with its kind and cell.
    pub fn cast_hits(
        &self,
        ctx: &GpuContext,
        rays: &[GpuRay],
    ) -> Result<Vec<GpuTerrainHit>, GpuError> {
        let queries: Vec<[f32; 4]> = rays.iter().flatten().copied().collect();
        let params = [0, self.pixel_lod, self.epsilon.to_bits()];
        let words = self.pass.run(ctx, &queries, params, &[&self.terrains])?;
        Ok(words
            .chunks_exact(2)
            .map(|w| {
                let (a, b) = (floats(w[0]), floats(w[1]));
                GpuTerrainHit {
                    t: a[0],
                    normal: [a[1], a[2], a[3]],
                    kind: b[0] as u32,
                    levels_above_finest: b[1] as u32,
                    cell: [b[2] as u32, b[3] as u32],
                }
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The terrain module's struct is laid out as Rust's (every field in order, at Rust's
    /// offset).
    #[test]
    fn the_terrain_kernels_struct_layout_matches_rust() {
        let source = crate::shader::compose(KERNEL.module, &KERNEL.options).unwrap();
        crate::shader::assert_validates_with_struct::<GpuTerrainParams>(&source);
    }
}
