//! The batch terrain pass (one struct, its pipeline and buffers): `shaders/terrain.wgsl` casts a
//! batch of camera-relative rays against one terrain and reads back per ray the hit
//! `(t, normal)` and `(kind, levels above the finest, cell)`. It is the f32 twin of
//! `fray_terrain::Terrain::cast_footprint` (bilinear and B-spline bicubic, walls, starts, pixel
//! LOD); a parity test bounds the difference. The GPU frame casts terrains with the same
//! `cast_terrain` (the terrain intersection and shade passes) over the arrays
//! [`terrain_arrays`] lays out for any number of terrains: their parameter blocks
//! (`terrains[k]`), and their max pyramids (rectangular levels) and samples concatenated.

use crate::bindings::{self, TERRAIN_BATCH, TERRAINS};
use crate::passes::PipelineCache;
use crate::readback::{batch_buffers, run_batch};
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use fray_core::PixelFootprint;
use fray_terrain::Terrain;
use fray_terrain::gpu_layout::{self, GpuTerrainParams};
use glam::DVec3;
use wgpu::util::DeviceExt;

const PASS: &str = "terrain";
const WORKGROUP: u32 = 64;

/// What the batch module is composed with: one terrain.
const OPTIONS: ModuleOptions = ModuleOptions {
    terrain: true,
    ..ModuleOptions::BATCH
};

/// The complete terrain batch module: the generated prelude (which holds the terrain's parameter
/// struct, from `fray_terrain::gpu_layout`), the batch and terrain bindings, terrain.wgsl and
/// terrain_batch.wgsl.
pub fn terrain_source() -> String {
    crate::shader::compose("terrain_batch.wgsl", &OPTIONS).unwrap_or_default()
}

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

/// One terrain as the GPU draws it: its material index and the pixel footprint its camera rays
/// use ([`PixelFootprint::ZERO`]: exact).
#[derive(Clone, Copy, Debug)]
pub struct TerrainUpload<'a> {
    pub terrain: &'a Terrain,
    pub material: u32,
    pub footprint: PixelFootprint,
}

/// Writes `values` (`f32`s, possibly produced on the fly) into a new storage buffer mapped at
/// creation, a chunk at a time: no host copy of the whole array is made. Charged to `charges`
/// first.
fn mapped_f32_buffer(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    label: &str,
    len: u64,
    mut fill: impl FnMut(&mut dyn FnMut(&[f32])),
) -> Result<wgpu::Buffer, GpuError> {
    let size = (len.max(1) * 4).next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
    charges.charge_uploaded(label, size)?;
    let buffer = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: true,
    });
    {
        let mut view = buffer
            .slice(..)
            .get_mapped_range_mut()
            .map_err(|e| GpuError::Dispatch {
                pass: PASS,
                reason: format!("cannot write the {label}: {e}"),
            })?;
        let mut at = 0usize;
        fill(&mut |chunk: &[f32]| {
            let bytes: &[u8] = bytemuck::cast_slice(chunk);
            view.slice(at..at + bytes.len()).copy_from_slice(bytes);
            at += bytes.len();
        });
    }
    buffer.unmap();
    Ok(buffer)
}

/// The terrains' parameter blocks (relative to `reference`, with each terrain's material,
/// footprint and offsets into the concatenated arrays) and the lengths of the concatenated max
/// pyramids and samples, checked against `limit` bytes per buffer (the device's storage binding
/// and buffer size limits) and the `u32` indices — before anything is allocated.
fn terrain_layout(
    terrains: &[TerrainUpload<'_>],
    reference: DVec3,
    limit: u64,
) -> Result<(Vec<GpuTerrainParams>, u64, u64), GpuError> {
    let too_large = |what, needed: u64, limit: u64| GpuError::TooLarge {
        what,
        needed,
        limit,
    };
    let mut params = Vec::with_capacity(terrains.len());
    let (mut pyramid, mut samples) = (0u64, 0u64);
    for t in terrains {
        let index =
            |v: u64, what| u32::try_from(v).map_err(|_| too_large(what, v, u32::MAX.into()));
        let p = GpuTerrainParams::new(t.terrain, reference)
            .with_pixel_lod(t.terrain, t.footprint)
            .with_material(t.material)
            .at_offsets(
                index(pyramid, "terrain pyramid values")?,
                index(samples, "terrain samples")?,
            )
            .map_err(|e| too_large("terrain pyramid values", e.needed, u32::MAX.into()))?;
        params.push(p);
        pyramid += gpu_layout::pyramid_len(t.terrain) as u64;
        samples += t.terrain.map().samples().len() as u64;
    }
    let block = std::mem::size_of::<GpuTerrainParams>() as u64;
    for (what, bytes) in [
        ("terrain pyramid bytes", pyramid * 4),
        ("terrain sample bytes", samples * 4),
        ("terrain parameter bytes", params.len() as u64 * block),
    ] {
        if bytes > limit {
            return Err(too_large(what, bytes, limit));
        }
    }
    Ok((params, pyramid, samples))
}

/// The terrains' arrays for a module that includes terrain.wgsl: the parameter blocks (relative
/// to `reference`), the concatenated max pyramids and the concatenated samples
/// ([`terrain_layout`], checked against the device's limits first), the arrays written straight
/// into buffers mapped at creation.
pub(crate) fn terrain_arrays(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    terrains: &[TerrainUpload<'_>],
    reference: DVec3,
) -> Result<(Vec<GpuTerrainParams>, wgpu::Buffer, wgpu::Buffer), GpuError> {
    let limit = ctx
        .limits
        .max_storage_buffer_binding_size
        .min(ctx.limits.max_buffer_size);
    let (params, pyramid, samples) = terrain_layout(terrains, reference, limit)?;
    const CHUNK: usize = 1 << 16;
    let pyramids = mapped_f32_buffer(ctx, charges, "terrain pyramids", pyramid, |write| {
        let mut chunk = vec![0.0f32; CHUNK];
        for t in terrains {
            for src in t.terrain.max_pyramid().values().chunks(CHUNK) {
                for (o, &v) in chunk.iter_mut().zip(src) {
                    *o = v.max(gpu_layout::NO_SURFACE);
                }
                write(&chunk[..src.len()]);
            }
        }
    })?;
    let samples = mapped_f32_buffer(ctx, charges, "terrain samples", samples, |write| {
        for t in terrains {
            for src in t.terrain.map().samples().chunks(CHUNK) {
                write(src);
            }
        }
    })?;
    Ok((params, pyramids, samples))
}

/// The batch terrain pass of one terrain.
#[derive(Debug)]
pub struct TerrainPass {
    cache: PipelineCache,
    pipeline: std::sync::Arc<wgpu::ComputePipeline>,
    /// The terrains group: its bind group (parameters, level of detail, pyramid, samples).
    terrains: wgpu::BindGroup,
    /// Cast with the pixel footprint (1) or exactly (0).
    pixel_lod: u32,
    epsilon: f32,
}

impl TerrainPass {
    /// Builds the pipeline and uploads `terrain` relative to `reference` (the camera), casting
    /// exactly, with the bicubic tolerance at its f32 floor (see [`TerrainPass::with_epsilon`]).
    pub fn new(ctx: &GpuContext, terrain: &Terrain, reference: DVec3) -> Result<Self, GpuError> {
        Self::build(ctx, terrain, reference, PixelFootprint::ZERO)
    }

    /// [`TerrainPass::new`] casting with the pixel footprint `footprint` (as
    /// `fray_terrain::Terrain::cast_footprint` takes it: already widened by the LOD bias).
    pub fn with_pixel_lod(
        ctx: &GpuContext,
        terrain: &Terrain,
        reference: DVec3,
        footprint: PixelFootprint,
    ) -> Result<Self, GpuError> {
        Self::build(ctx, terrain, reference, footprint)
    }

    /// This pass with the bicubic root tolerance `eps` (world units; `Terrain::cast`'s `eps`),
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
        let (params, pyramid, samples) = terrain_arrays(
            ctx,
            &mut crate::DeviceCharges::unlimited(),
            &[upload],
            reference,
        )?;
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
        let cache = PipelineCache::default();
        let pipeline = cache.pipeline(
            ctx,
            "terrain_batch.wgsl",
            &[TERRAIN_BATCH, TERRAINS],
            &OPTIONS,
            &Specialisation::default(),
        )?;
        let terrains = TERRAINS.bind(
            &ctx.device,
            &cache.layout(ctx, &TERRAINS),
            &[
                params_buffer.as_entire_binding(),
                lods.as_entire_binding(),
                pyramid.as_entire_binding(),
                samples.as_entire_binding(),
            ],
        );
        Ok(Self {
            cache,
            pipeline,
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
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        let device = &ctx.device;
        let batch = [rays.len() as u32, 0, self.pixel_lod, self.epsilon.to_bits()];
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("terrain batch"),
            contents: bytemuck::cast_slice(&batch),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bytes = (rays.len() * 32) as u64;
        let (ray_buffer, output) = batch_buffers(
            ctx,
            ("terrain batch rays", "terrain batch hits"),
            rays,
            bytes,
        )?;
        let bind_group = TERRAIN_BATCH.bind(
            device,
            &self.cache.layout(ctx, &TERRAIN_BATCH),
            &[
                uniform.as_entire_binding(),
                ray_buffer.as_entire_binding(),
                output.as_entire_binding(),
            ],
        );
        let raw: Vec<[[f32; 4]; 2]> = run_batch(
            ctx,
            &self.pipeline,
            &[&bind_group, &self.terrains],
            rays.len() as u32,
            WORKGROUP,
            &output,
            bytes,
            PASS,
        )?;
        Ok(raw
            .iter()
            .map(|[a, b]| GpuTerrainHit {
                t: a[0],
                normal: [a[1], a[2], a[3]],
                kind: b[0] as u32,
                levels_above_finest: b[1] as u32,
                cell: [b[2] as u32, b[3] as u32],
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Terrains are laid out one after the other (offsets per terrain) and refused over the
    /// device's limit with what, how much and the limit — checked before any allocation.
    #[test]
    fn terrain_layout_concatenates_and_refuses_over_the_limit() {
        use fray_terrain::{Heightmap, Placement, TerrainOptions};
        let terrain = |w, h| {
            let map = Heightmap::from_fn(w, h, |i, j| (i + 2 * j) as f32).unwrap();
            let placement = Placement::new(DVec3::ZERO, glam::DVec2::ONE, 1.0).unwrap();
            Terrain::new(map, placement, TerrainOptions::default()).unwrap()
        };
        let (a, b) = (terrain(5, 4), terrain(33, 2));
        let upload = |terrain, material| TerrainUpload {
            terrain,
            material,
            footprint: PixelFootprint::ZERO,
        };
        let both = [upload(&a, 0), upload(&b, 3)];
        let (params, pyramid, samples) = terrain_layout(&both, DVec3::ZERO, 1 << 20).unwrap();
        let (pa, pb) = (
            a.max_pyramid().values().len(),
            b.max_pyramid().values().len(),
        );
        assert_eq!((pyramid, samples), ((pa + pb) as u64, 20 + 66));
        assert_eq!((params[0].levels[0][0], params[0].sizes[2]), (0, 0));
        assert_eq!(
            (params[1].levels[0][0], params[1].sizes[2]),
            (pa as u32, 20)
        );
        assert_eq!(
            params[1].levels[1][1],
            (pa + b.max_pyramid().offset(5)) as u32
        );
        assert_eq!((params[0].material[0], params[1].material[0]), (0, 3));
        // 86 samples are 344 bytes (the pyramids 320): refused under a 330-byte limit.
        let e = terrain_layout(&both, DVec3::ZERO, 330).unwrap_err();
        assert_eq!(
            e,
            GpuError::TooLarge {
                what: "terrain sample bytes",
                needed: 344,
                limit: 330
            }
        );
        assert!(
            e.to_string().contains(
                "terrain sample bytes — the scene needs 344, the GPU backend allows at most 330"
            ),
            "{e}"
        );
    }

    /// The terrain module (generated struct + shader) parses and validates with naga, and the
    /// compiled struct's layout is the Rust one (every field in order, at Rust's offset).
    #[test]
    fn terrain_wgsl_validates_and_its_struct_layout_matches_rust() {
        crate::shader::assert_validates_with_struct::<GpuTerrainParams>(&terrain_source());
    }
}
