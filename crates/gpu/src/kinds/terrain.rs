//! Terrains on the GPU: what stays resident — their parameter blocks (rebased to each camera),
//! their max pyramids and samples concatenated into two storage buffers written straight from
//! the terrains while mapped, each view's level-of-detail parameters — and their intersection
//! pass: one workgroup per work item of the band, each pixel's camera
//! rays cast against the item's terrain candidates at their pixel level of detail
//! (`shaders/terrain.wgsl`, the f32 twin of `fray_terrain::Terrain::cast_footprint`) over
//! `[t_near, nearest hit so far]`, narrowing the paths' hits after the free forms. Built only
//! for scenes with terrains.

use super::{GpuKind, ResidentKind, Upload};
use crate::DeviceCharges;
use crate::View;
use crate::counters::Counter;
use crate::passes::rebase::{RebaseLayout, Rebased};
use crate::passes::spec::{PassSpec, Role, Workload};
use crate::{GpuContext, GpuError};
use fray_core::PixelFootprint;
use fray_scene::{PrimitiveKind, Scene};
use fray_terrain::Terrain;
use fray_terrain::gpu_layout::{self, GpuTerrainParams};
use glam::DVec3;
use std::mem::offset_of;
use wgpu::BufferUsages as U;

/// The terrain kind on the GPU.
#[derive(Clone, Copy, Debug)]
pub struct Terrains;

impl GpuKind for Terrains {
    fn kind(&self) -> PrimitiveKind {
        PrimitiveKind::Terrain
    }

    fn upload(
        &self,
        at: Upload<'_>,
        charges: &mut DeviceCharges,
    ) -> Result<Option<Box<dyn ResidentKind>>, GpuError> {
        Ok(Some(Box::new(upload_terrains(at, charges)?)))
    }

    fn intersection(&self) -> PassSpec {
        INTERSECTION
    }

    fn read_stats(&self, words: &[u32], stats: &mut fray_core::RenderStats) {
        stats.terrain_rays = Counter::TerrainRays.read(words);
        stats.terrain_segments = Counter::TerrainSegments.read(words);
        stats.terrain_cells = Counter::TerrainCells.read(words);
        stats.terrain_stops = Counter::TerrainStops.read(words);
        stats.terrain_stop_levels = Counter::TerrainStopLevels.read(words);
    }
}

impl ResidentKind for ResidentTerrains {
    fn resources(&self) -> Vec<wgpu::BindingResource<'_>> {
        vec![
            self.table.as_entire_binding(),
            self.lods.as_entire_binding(),
            self.pyramid.as_entire_binding(),
            self.samples.as_entire_binding(),
        ]
    }

    fn rebased(&self) -> Vec<&Rebased> {
        vec![&self.params]
    }

    fn copy_tables(&self, encoder: &mut wgpu::CommandEncoder) {
        let t = self;
        encoder.copy_buffer_to_buffer(&t.params.target, 0, &t.table, 0, t.table.size());
    }

    fn write_view(
        &mut self,
        ctx: &GpuContext,
        scene: &Scene,
        view: &View,
    ) -> Result<u64, GpuError> {
        // Each terrain's level of detail at this view's pixel footprint.
        let footprint = view.camera.pixel_footprint(view.width, view.height);
        let lods = terrain_lods(scene, footprint);
        ctx.queue
            .write_buffer(&self.lods, 0, bytemuck::cast_slice(&lods));
        Ok((lods.len() * 16) as u64)
    }

    fn bytes(&self) -> u64 {
        self.bytes
    }
}

/// Its intersection pass.
const INTERSECTION: PassSpec = PassSpec {
    label: "terrains",
    entry: "intersect_terrain.wgsl",
    roles: &[Role::Frame, Role::Work, Role::Kind(PrimitiveKind::Terrain)],
    workload: Workload::Items,
};

/// Where the terrain parameters' positions are (the rebase pass moves them).
pub const TERRAIN_LAYOUT: RebaseLayout = RebaseLayout::new(
    size_of::<GpuTerrainParams>(),
    &[offset_of!(GpuTerrainParams, origin)],
    &[],
    &[],
);

/// The terrains on the GPU.
#[derive(Debug)]
pub struct ResidentTerrains {
    /// The parameters (anchor-relative source, camera-relative copy).
    pub params: Rebased,
    /// The camera-relative parameters as the uniform table the passes read (copied from
    /// `params.target` each frame the camera moves).
    pub table: wgpu::Buffer,
    /// This view's level-of-detail parameters, one vec4 per terrain (camera data, written per
    /// frame).
    pub lods: wgpu::Buffer,
    pub pyramid: wgpu::Buffer,
    pub samples: wgpu::Buffer,
    /// The bytes uploaded.
    pub bytes: u64,
}

/// The terrains' parameters (their pyramids and samples at offsets in the concatenated arrays,
/// their materials) anchor-relative, and the concatenated arrays, written straight into mapped
/// GPU buffers (`terrains::terrain_arrays`); returns them.
fn upload_terrains(
    at: Upload<'_>,
    charges: &mut DeviceCharges,
) -> Result<ResidentTerrains, GpuError> {
    let Upload {
        ctx,
        cache,
        scene,
        anchor,
        ..
    } = at;
    let material_count = scene.materials.len() as u32;
    let uploads: Vec<TerrainUpload<'_>> = scene
        .terrains
        .iter()
        .map(|t| TerrainUpload {
            terrain: &t.terrain,
            material: t.material.min(material_count),
            // The level of detail is the view's: `terrain_lods`, per frame.
            footprint: fray_core::PixelFootprint::ZERO,
        })
        .collect();
    let (params, pyramid, samples) = terrain_arrays(ctx, charges, &uploads, anchor)?;
    let (params_rebased, params_bytes) = Rebased::new(
        ctx,
        charges,
        cache,
        "terrain params",
        &params,
        TERRAIN_LAYOUT,
    )?;
    let table_bytes = (params.len() * size_of::<GpuTerrainParams>()) as u64;
    let table = charges.empty(ctx, "terrain table", table_bytes, U::UNIFORM | U::COPY_DST)?;
    let lods = charges.empty(
        ctx,
        "terrain lods",
        16 * params.len() as u64,
        U::UNIFORM | U::COPY_DST,
    )?;
    let bytes = params_bytes + pyramid.size() + samples.size();
    Ok(ResidentTerrains {
        params: params_rebased,
        table,
        lods,
        pyramid,
        samples,
        bytes,
    })
}

/// This view's level-of-detail parameters of each terrain of `scene` (camera rays at the
/// terrain's `lod`; `GpuTerrainParams::with_pixel_lod`, exactly as the CPU casts them).
pub fn terrain_lods(scene: &Scene, footprint: fray_core::PixelFootprint) -> Vec<[f32; 4]> {
    scene
        .terrains
        .iter()
        .map(|t| {
            let fp = match t.lod {
                fray_scene::TerrainLod::Pixel => footprint.coarser(t.terrain.options().lod_bias),
                fray_scene::TerrainLod::Exact => fray_core::PixelFootprint::ZERO,
            };
            GpuTerrainParams::new(&t.terrain, DVec3::ZERO)
                .with_pixel_lod(&t.terrain, fp)
                .lod
        })
        .collect()
}

const PASS: &str = "terrain";

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
}
