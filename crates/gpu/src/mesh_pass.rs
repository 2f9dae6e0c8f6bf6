//! The batch mesh pass (one struct, its pipeline and buffers): `shaders/mesh_batch.wgsl` casts a
//! batch of reference-relative rays against every mesh instance with `mesh.wgsl` — the f32 twin
//! of `fray_mesh::MeshBvh::nearest_hit`/`any_hit` under `fray_mesh::Instance` — and reads back
//! per ray the nearest hit `(t, instance, triangle, barycentrics)`, the any-hit flag over the
//! same range, and the hit's surface (world geometric and shading normals, uv). A parity test
//! (`tests/mesh_parity.rs`) bounds the difference.
//!
//! The arrays are `fray_mesh::gpu_layout::GpuMeshes` ([`mesh_layout`]: its refusals as
//! [`GpuError`]s) uploaded by [`mesh_buffers`] into the [`MESHES`] group — one texture of
//! 16-byte texels and a uniform saying where each array starts in it ([`MeshBuffers`]), checked
//! against the device's limits; the frame's mesh intersection and shade passes bind the same
//! resources. A camera that moves rewrites only the instance blocks ([`MeshPass::rebase`],
//! [`MeshBuffers::write_instances`]).

use crate::bindings::{self, MESH_BATCH, MESHES};
use crate::passes::PipelineCache;
use crate::readback::{batch_buffers, run_batch};
use crate::shader::{ModuleOptions, Specialisation};
use crate::terrain_pass::GpuRay;
use crate::{GpuContext, GpuError};
use fray_core::MemoryBudget;
use fray_mesh::MeshBvh;
use fray_mesh::gpu_layout::{
    GpuMeshInstance, GpuMeshNode, GpuMeshTriangle, GpuMeshVertex, GpuMeshes, MESH_NO_HIT,
    MeshLayoutError,
};
use glam::{DAffine3, DVec3};

const PASS: &str = "mesh";
const WORKGROUP: u32 = 64;

/// The complete mesh batch module: the generated prelude (with the mesh structs and constants,
/// from `fray_mesh::gpu_layout`), the batch and mesh bindings, ray.wgsl, mesh.wgsl and
/// mesh_batch.wgsl.
pub fn mesh_source() -> String {
    crate::shader::compose("mesh_batch.wgsl", &ModuleOptions::BATCH).unwrap_or_default()
}

/// What a batch ray hit, as the GPU found it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuMeshHit {
    /// Distance along the ray (in units of its direction); −1 for a miss.
    pub t: f32,
    /// The barycentric weights of the triangle's corners.
    pub barycentric: [f32; 3],
    /// The instance hit (`MESH_NO_HIT` for a miss).
    pub instance: u32,
    /// The mesh's own index of the triangle hit.
    pub triangle: u32,
    /// Whether the any-hit query over the same range found a hit.
    pub any_hit: bool,
    /// World geometric normal (unit, outward by the winding) and shading normal, and the uv.
    pub normal: [f32; 3],
    pub shading_normal: [f32; 3],
    pub uv: [f32; 2],
}

impl GpuMeshHit {
    /// Whether the ray hit.
    pub fn is_hit(&self) -> bool {
        self.instance != MESH_NO_HIT
    }
}

/// A layout refusal as the backend reports it: a BVH too deep for the traversal's stack or
/// arrays past `u32` indices as [`GpuError::TooLarge`], a budget as [`GpuError::Budget`], bad
/// instances as [`GpuError::Mesh`].
pub fn layout_error(e: MeshLayoutError) -> GpuError {
    match e {
        MeshLayoutError::TooDeep { depth, limit, .. } => GpuError::TooLarge {
            what: "a mesh BVH's depth + 1, in entries of the GPU traversal's stack",
            needed: u64::from(depth) + 1,
            limit: u64::from(limit),
        },
        MeshLayoutError::IndexOverflow { what, needed } => GpuError::TooLarge {
            what,
            needed,
            limit: u32::MAX.into(),
        },
        MeshLayoutError::Budget(b) => GpuError::Budget(b),
        other => GpuError::Mesh(other.to_string()),
    }
}

/// `meshes` and `instances` (mesh index, mesh-to-world) laid out for the GPU relative to
/// `reference` ([`GpuMeshes::build`]), refusals as [`GpuError`]s ([`layout_error`]).
pub fn mesh_layout(
    meshes: &[&MeshBvh],
    instances: &[(u32, DAffine3)],
    reference: DVec3,
    budget: &MemoryBudget,
) -> Result<GpuMeshes, GpuError> {
    GpuMeshes::build(meshes, instances, reference, budget).map_err(layout_error)
}

/// Texels (of 16 bytes) per row of the mesh texture ([`crate::params::DATA_TEXTURE_WIDTH`]).
pub const MESH_TEXTURE_WIDTH: u32 = crate::params::DATA_TEXTURE_WIDTH;

/// Texels of one element of each array.
const fn texels<T>() -> u64 {
    (std::mem::size_of::<T>() / 16) as u64
}

/// The [`MESHES`] group's resources: the layout uniform `(instance count, first texel of the
/// nodes, of the triangles, of the vertices)` and the one texture every array is packed into
/// (`Rgba32Uint`, [`MESH_TEXTURE_WIDTH`] texels per row; instances first, then nodes,
/// triangles and vertices, each element its struct's words in field order). A texture, not
/// storage buffers: the shade pass already binds the eight storage buffers WebGPU's defaults
/// allow (`bindings`), while sampled textures have a limit of their own (16).
#[derive(Debug)]
pub struct MeshBuffers {
    pub info: wgpu::Buffer,
    pub texture: wgpu::Texture,
    /// What `info` holds.
    pub layout: [u32; 4],
    /// Bytes uploaded (the uniform and every texel written).
    pub bytes: u64,
}

impl MeshBuffers {
    /// The bind group of [`MESHES`] over these buffers.
    pub fn bind(&self, ctx: &GpuContext, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        let view = self.view();
        MESHES.bind(
            &ctx.device,
            layout,
            &[
                self.info.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
            ],
        )
    }

    /// A view of the texture (for a group that binds it with others).
    pub fn view(&self) -> wgpu::TextureView {
        self.texture
            .create_view(&wgpu::TextureViewDescriptor::default())
    }

    /// Rewrites the instance blocks (the texture's first texels) with `blocks`, nothing else;
    /// returns the bytes written.
    pub fn write_instances(&self, ctx: &GpuContext, blocks: &[GpuMeshInstance]) -> u64 {
        write_texels(ctx, &self.texture, 0, bytemuck::cast_slice(blocks))
    }
}

/// Writes `data` (16-byte texels) into `texture` from texel `first` on, row-major with
/// [`MESH_TEXTURE_WIDTH`] per row: a partial first row, whole rows, a partial last row — no
/// texel outside the range is touched. Returns the bytes written.
pub(crate) fn write_texels(
    ctx: &GpuContext,
    texture: &wgpu::Texture,
    first: u64,
    data: &[[u32; 4]],
) -> u64 {
    let w = u64::from(MESH_TEXTURE_WIDTH);
    let mut at = first;
    let mut rest = data;
    let write = |x: u64, y: u64, width: u64, rows: u64, texels: &[[u32; 4]]| {
        ctx.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: x as u32,
                    y: y as u32,
                    z: 0,
                },
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some((width * 16) as u32),
                rows_per_image: Some(rows as u32),
            },
            wgpu::Extent3d {
                width: width as u32,
                height: rows as u32,
                depth_or_array_layers: 1,
            },
        );
    };
    let x = at % w;
    if x != 0 && !rest.is_empty() {
        let n = (w - x).min(rest.len() as u64);
        write(x, at / w, n, 1, &rest[..n as usize]);
        at += n;
        rest = &rest[n as usize..];
    }
    let rows = rest.len() as u64 / w;
    if rows > 0 {
        let n = (rows * w) as usize;
        write(0, at / w, w, rows, &rest[..n]);
        at += rows * w;
        rest = &rest[n..];
    }
    if !rest.is_empty() {
        write(0, at / w, rest.len() as u64, 1, rest);
    }
    std::mem::size_of_val(data) as u64
}

/// Uploads `layout`'s arrays into one texture ([`MeshBuffers`]), its rows checked against the
/// device's 2D texture limit first, and the layout uniform.
pub fn mesh_buffers(
    ctx: &GpuContext,
    charges: &mut crate::DeviceCharges,
    layout: &GpuMeshes,
) -> Result<MeshBuffers, GpuError> {
    use wgpu::BufferUsages as U;
    let count = |n: usize| n as u64;
    let nodes_at = count(layout.instances.len()) * texels::<GpuMeshInstance>();
    let triangles_at = nodes_at + count(layout.nodes.len()) * texels::<GpuMeshNode>();
    let vertices_at = triangles_at + count(layout.triangles.len()) * texels::<GpuMeshTriangle>();
    let total = vertices_at + count(layout.vertices.len()) * texels::<GpuMeshVertex>();
    let rows = crate::bindings::data_texture_rows(
        total,
        MESH_TEXTURE_WIDTH,
        [
            "texels per row of the mesh texture",
            "rows of the mesh texture (4096 texels of 16 bytes each)",
        ],
        &ctx.limits,
    )?;
    let index = |v: u64| {
        u32::try_from(v).map_err(|_| GpuError::TooLarge {
            what: "texels of the mesh texture",
            needed: total,
            limit: u32::MAX.into(),
        })
    };
    let info = [
        index(count(layout.instances.len()))?,
        index(nodes_at)?,
        index(triangles_at)?,
        index(vertices_at)?,
    ];
    index(total)?;
    let info_buffer = charges.upload(ctx, "mesh layout", &[info], [0; 4], U::UNIFORM)?;
    let texture = bindings::data_texture(ctx, charges, "meshes", MESH_TEXTURE_WIDTH, rows)?;
    let mut bytes = 16;
    bytes += write_texels(ctx, &texture, 0, bytemuck::cast_slice(&layout.instances));
    bytes += write_texels(ctx, &texture, nodes_at, bytemuck::cast_slice(&layout.nodes));
    bytes += write_texels(
        ctx,
        &texture,
        triangles_at,
        bytemuck::cast_slice(&layout.triangles),
    );
    bytes += write_texels(
        ctx,
        &texture,
        vertices_at,
        bytemuck::cast_slice(&layout.vertices),
    );
    Ok(MeshBuffers {
        info: info_buffer,
        texture,
        layout: info,
        bytes,
    })
}

/// The batch mesh pass over a set of meshes and instances.
#[derive(Debug)]
pub struct MeshPass {
    cache: PipelineCache,
    pipeline: std::sync::Arc<wgpu::ComputePipeline>,
    layout: GpuMeshes,
    buffers: MeshBuffers,
    meshes: wgpu::BindGroup,
}

impl MeshPass {
    /// Builds the pipeline and uploads `meshes` with `instances` (mesh index, mesh-to-world
    /// transform) relative to `reference` (the camera), under the default memory budget.
    pub fn new(
        ctx: &GpuContext,
        meshes: &[&MeshBvh],
        instances: &[(u32, DAffine3)],
        reference: DVec3,
    ) -> Result<Self, GpuError> {
        let layout = mesh_layout(meshes, instances, reference, &MemoryBudget::default())?;
        Self::from_layout(ctx, layout)
    }

    /// Builds the pipeline and uploads `layout`.
    pub fn from_layout(ctx: &GpuContext, layout: GpuMeshes) -> Result<Self, GpuError> {
        let buffers = mesh_buffers(ctx, &mut crate::DeviceCharges::unlimited(), &layout)?;
        let cache = PipelineCache::default();
        let pipeline = cache.pipeline(
            ctx,
            "mesh_batch.wgsl",
            &[MESH_BATCH, MESHES],
            &ModuleOptions::BATCH,
            &Specialisation::default(),
        )?;
        let meshes = buffers.bind(ctx, &cache.layout(ctx, &MESHES));
        Ok(Self {
            cache,
            pipeline,
            layout,
            buffers,
            meshes,
        })
    }

    /// What was uploaded.
    pub fn layout(&self) -> &GpuMeshes {
        &self.layout
    }

    /// Moves the pass to reference point `reference`: rewrites the instance blocks only (the
    /// nodes, triangles and vertices stay as uploaded); returns the bytes written.
    pub fn rebase(&mut self, ctx: &GpuContext, reference: DVec3) -> Result<u64, GpuError> {
        let blocks = self.layout.instances_at(reference).map_err(layout_error)?;
        let bytes = self.buffers.write_instances(ctx, &blocks);
        self.layout.instances = blocks;
        Ok(bytes)
    }

    /// Casts `rays` (relative to the reference point; `t_hi` past `BIG` = 1e30 is clamped to
    /// it) against every instance: the nearest hit, the any-hit flag, the surface.
    pub fn cast(&self, ctx: &GpuContext, rays: &[GpuRay]) -> Result<Vec<GpuMeshHit>, GpuError> {
        if rays.is_empty() {
            return Ok(Vec::new());
        }
        let device = &ctx.device;
        let count = u32::try_from(rays.len()).map_err(|_| GpuError::TooLarge {
            what: "mesh batch rays",
            needed: rays.len() as u64,
            limit: u32::MAX.into(),
        })?;
        let instances = self.layout.instances.len() as u32;
        let batch = bindings::upload(
            ctx,
            "mesh batch",
            &[[count, instances, 0, 0]],
            [0; 4],
            wgpu::BufferUsages::UNIFORM,
        )?;
        let bytes = rays.len() as u64 * 64;
        let (ray_buffer, output) =
            batch_buffers(ctx, ("mesh batch rays", "mesh batch hits"), rays, bytes)?;
        let bind_group = MESH_BATCH.bind(
            device,
            &self.cache.layout(ctx, &MESH_BATCH),
            &[
                batch.as_entire_binding(),
                ray_buffer.as_entire_binding(),
                output.as_entire_binding(),
            ],
        );
        let raw: Vec<[[u32; 4]; 4]> = run_batch(
            ctx,
            &self.pipeline,
            &[&bind_group, &self.meshes],
            count,
            WORKGROUP,
            &output,
            bytes,
            PASS,
        )?;
        let f = f32::from_bits;
        Ok(raw
            .iter()
            .map(|[a, b, c, d]| GpuMeshHit {
                t: f(a[0]),
                barycentric: [f(a[1]), f(a[2]), f(a[3])],
                instance: b[0],
                triangle: b[1],
                any_hit: b[2] == 1,
                normal: [f(c[0]), f(c[1]), f(c[2])],
                shading_normal: [f(d[0]), f(d[1]), f(d[2])],
                uv: [f(c[3]), f(d[3])],
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_mesh::TriangleMesh;

    /// The mesh module (generated structs + shaders) parses and validates with naga, and every
    /// mesh struct's compiled layout is the Rust one.
    #[test]
    fn mesh_wgsl_validates_and_its_struct_layouts_match_rust() {
        let source = mesh_source();
        assert!(source.contains("// ---- mesh.wgsl ----"), "composed");
        crate::shader::assert_validates_with_struct::<GpuMeshNode>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshTriangle>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshVertex>(&source);
        crate::shader::assert_validates_with_struct::<GpuMeshInstance>(&source);
    }

    /// `load_mesh_*` (mesh.wgsl) read each element as its texels' words in field order: the
    /// Rust structs lay their fields out so, one 4-byte word each, without padding.
    #[test]
    fn the_texture_loaders_word_order_is_the_structs() {
        use std::mem::offset_of;
        let words = |offsets: &[usize]| offsets.iter().map(|o| o / 4).collect::<Vec<_>>();
        assert_eq!(
            words(&[
                offset_of!(GpuMeshNode, min_x),
                offset_of!(GpuMeshNode, min_y),
                offset_of!(GpuMeshNode, min_z),
                offset_of!(GpuMeshNode, first),
                offset_of!(GpuMeshNode, max_x),
                offset_of!(GpuMeshNode, max_y),
                offset_of!(GpuMeshNode, max_z),
                offset_of!(GpuMeshNode, count),
            ]),
            (0..8).collect::<Vec<_>>()
        );
        assert_eq!(
            words(&[
                offset_of!(GpuMeshTriangle, a),
                offset_of!(GpuMeshTriangle, b),
                offset_of!(GpuMeshTriangle, c),
                offset_of!(GpuMeshTriangle, index),
                offset_of!(GpuMeshTriangle, v0),
                offset_of!(GpuMeshTriangle, v1),
                offset_of!(GpuMeshTriangle, v2),
            ]),
            vec![0, 4, 8, 12, 13, 14, 15]
        );
        assert_eq!(
            words(&[
                offset_of!(GpuMeshVertex, normal),
                offset_of!(GpuMeshVertex, uv),
                offset_of!(GpuMeshVertex, pad),
            ]),
            vec![0, 4, 6]
        );
        assert_eq!(
            words(&[
                offset_of!(GpuMeshInstance, to_mesh_x),
                offset_of!(GpuMeshInstance, to_mesh_y),
                offset_of!(GpuMeshInstance, to_mesh_z),
                offset_of!(GpuMeshInstance, root),
                offset_of!(GpuMeshInstance, mesh),
                offset_of!(GpuMeshInstance, material),
                offset_of!(GpuMeshInstance, flags),
            ]),
            vec![0, 4, 8, 12, 13, 14, 15]
        );
        assert_eq!(
            [
                texels::<GpuMeshInstance>(),
                texels::<GpuMeshNode>(),
                texels::<GpuMeshTriangle>(),
                texels::<GpuMeshVertex>()
            ],
            [4, 2, 4, 2],
            "the strides mesh.wgsl's loaders use"
        );
    }

    /// The stack-depth policy: a BVH deeper than the traversal's stack is refused, before
    /// anything is allocated, as `TooLarge` with what, how much and the limit; bad instances and
    /// budgets likewise, never a panic.
    #[test]
    fn layout_refusals_become_gpu_errors() {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..64u32 {
            let x = f64::from(i);
            positions.extend([
                DVec3::new(x, 0.0, 0.0),
                DVec3::new(x + 0.5, 0.0, 0.0),
                DVec3::new(x, 1.0, 0.0),
            ]);
            triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let bvh = MeshBvh::build(TriangleMesh::new(positions, triangles).unwrap());
        let depth = bvh.max_depth();
        let id = [(0, DAffine3::IDENTITY)];
        let budget = MemoryBudget::default();
        let e = GpuMeshes::build_with_stack(&[&bvh], &id, DVec3::ZERO, &budget, depth)
            .map_err(layout_error)
            .unwrap_err();
        assert_eq!(
            e,
            GpuError::TooLarge {
                what: "a mesh BVH's depth + 1, in entries of the GPU traversal's stack",
                needed: u64::from(depth) + 1,
                limit: u64::from(depth),
            }
        );
        assert!(e.to_string().contains("GPU traversal's stack"), "{e}");
        assert!(mesh_layout(&[&bvh], &id, DVec3::ZERO, &budget).is_ok());
        let singular = [(0, DAffine3::from_scale(DVec3::new(0.0, 1.0, 1.0)))];
        let e = mesh_layout(&[&bvh], &singular, DVec3::ZERO, &budget).unwrap_err();
        assert!(
            matches!(&e, GpuError::Mesh(m) if m.contains("invertible")),
            "{e}"
        );
        let e = mesh_layout(&[&bvh], &id, DVec3::ZERO, &MemoryBudget::new(64)).unwrap_err();
        assert!(matches!(e, GpuError::Budget(_)), "{e}");
        let e = mesh_layout(&[], &id, DVec3::ZERO, &budget).unwrap_err();
        assert!(
            matches!(&e, GpuError::Mesh(m) if m.contains("names mesh 0")),
            "{e}"
        );
    }
}
