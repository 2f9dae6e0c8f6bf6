//! Triangle meshes on the GPU: what stays resident — every distinct mesh's BVH, triangles and
//! vertices with the instance blocks in one data texture (the blocks rewritten from f64 for a
//! moved camera, nothing else) — and their intersection pass: one workgroup per work item of
//! the band, each pixel's camera
//! rays cast against the item's mesh candidates — one instance each, its BVH nearest child
//! first and the watertight triangle test in f32 (`shaders/mesh.wgsl`, the f32 twin of
//! `fray_mesh::Instance::nearest_hit`) — over `(t_near, nearest hit so far)`, narrowing the
//! paths' hits after the free forms and the terrains (a tie keeps the earlier kind's hit) and
//! recording the instance, the triangle and its barycentrics for the shade pass. Built only
//! for scenes with meshes.

use super::{GpuKind, ResidentKind, Upload};
use crate::DeviceCharges;
use crate::View;
use crate::bindings::{self, MESHES, write_texels};
use crate::counters::Counter;
use crate::passes::spec::{PassSpec, Role, Workload};
use crate::{GpuContext, GpuError};
use fray_core::MemoryBudget;
use fray_mesh::MeshBvh;
use fray_mesh::gpu_layout::{
    GpuMeshInstance, GpuMeshNode, GpuMeshTriangle, GpuMeshVertex, GpuMeshes, MeshLayoutError,
};
use fray_scene::{PrimitiveKind, Scene};
use glam::{DAffine3, DVec3};

/// The mesh kind on the GPU.
#[derive(Clone, Copy, Debug)]
pub struct Meshes;

impl GpuKind for Meshes {
    fn kind(&self) -> PrimitiveKind {
        PrimitiveKind::Mesh
    }

    fn upload(
        &self,
        at: Upload<'_>,
        charges: &mut DeviceCharges,
    ) -> Result<Option<Box<dyn ResidentKind>>, GpuError> {
        Ok(Some(Box::new(upload_meshes(at, charges)?)))
    }

    fn intersection(&self) -> PassSpec {
        INTERSECTION
    }

    fn read_stats(&self, words: &[u32], stats: &mut fray_core::RenderStats) {
        stats.mesh_rays = Counter::MeshRays.read(words);
    }
}

impl ResidentKind for ResidentMeshes {
    fn resources(&self) -> Vec<wgpu::BindingResource<'_>> {
        vec![
            self.buffers.info.as_entire_binding(),
            wgpu::BindingResource::TextureView(&self.view),
        ]
    }

    fn write_view(
        &mut self,
        ctx: &GpuContext,
        _scene: &Scene,
        view: &View,
    ) -> Result<u64, GpuError> {
        // The instance blocks relative to this camera, from f64 (nothing else of the meshes
        // moves).
        self.move_to(ctx, crate::params::reference_point(&view.camera))
    }

    fn bytes(&self) -> u64 {
        self.buffers.bytes
    }
}

/// Its intersection pass.
const INTERSECTION: PassSpec = PassSpec {
    label: "meshes",
    entry: "intersect_mesh.wgsl",
    roles: &[Role::Frame, Role::Work, Role::Kind(PrimitiveKind::Mesh)],
    workload: Workload::Items,
};

/// The meshes on the GPU.
#[derive(Debug)]
pub struct ResidentMeshes {
    /// The layout uploaded (each distinct mesh once, one instance per mesh object in scene
    /// order, with its material and smooth flag), kept for the instance blocks of a moved
    /// camera.
    pub layout: GpuMeshes,
    pub buffers: MeshBuffers,
    /// The view of its texture the groups bind.
    pub view: wgpu::TextureView,
    /// The point (world, f64) the instance blocks on the GPU are relative to.
    pub reference: DVec3,
}

impl ResidentMeshes {
    /// Rewrites the instance blocks relative to `reference` (a camera's eye, f64), unless they
    /// already are; nothing else of the meshes moves. Returns the bytes written.
    pub fn move_to(&mut self, ctx: &GpuContext, reference: DVec3) -> Result<u64, GpuError> {
        if reference == self.reference {
            return Ok(0);
        }
        let blocks = self.layout.instances_at(reference).map_err(layout_error)?;
        let bytes = self.buffers.write_instances(ctx, &blocks);
        self.layout.instances = blocks;
        self.reference = reference;
        Ok(bytes)
    }
}

/// The scene's meshes laid out relative to `anchor` (`fray_mesh::gpu_layout::GpuMeshes`: each
/// distinct mesh — objects naming one file share its BVH — once, one instance per mesh object
/// in scene order with its material, the default where it has none, and its smooth flag) and
/// uploaded (`meshes::mesh_buffers`).
fn upload_meshes(at: Upload<'_>, charges: &mut DeviceCharges) -> Result<ResidentMeshes, GpuError> {
    let Upload {
        ctx,
        scene,
        anchor,
        budget,
        ..
    } = at;
    let mut distinct: Vec<&std::sync::Arc<fray_mesh::MeshBvh>> = Vec::new();
    let mut placements = Vec::with_capacity(scene.meshes.len());
    for object in &scene.meshes {
        let mesh = &object.instance.mesh;
        let index = match distinct
            .iter()
            .position(|m| std::sync::Arc::ptr_eq(m, mesh))
        {
            Some(i) => i,
            None => {
                distinct.push(mesh);
                distinct.len() - 1
            }
        };
        placements.push((index as u32, object.instance.to_world()));
    }
    let bvhs: Vec<&fray_mesh::MeshBvh> = distinct.iter().map(|m| m.as_ref()).collect();
    let material_count = scene.materials.len() as u32;
    let materials: Vec<u32> = scene
        .meshes
        .iter()
        .map(|m| m.material.min(material_count))
        .collect();
    let smooth: Vec<bool> = scene.meshes.iter().map(|m| m.smooth).collect();
    let layout = mesh_layout(&bvhs, &placements, anchor, budget)?
        .with_materials(&materials)
        .with_smooth(&smooth);
    let buffers = mesh_buffers(ctx, charges, &layout)?;
    Ok(ResidentMeshes {
        layout,
        view: buffers.view(),
        buffers,
        reference: anchor,
    })
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

#[cfg(test)]
mod tests {
    use super::*;
    use fray_mesh::TriangleMesh;

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
