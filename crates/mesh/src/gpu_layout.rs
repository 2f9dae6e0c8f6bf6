//! The meshes as the GPU reads them (the f32 twin's data, `shaders/mesh.wgsl`): every mesh's
//! BVH nodes, triangles and vertex attributes concatenated into three arrays, and one block per
//! instance saying where its mesh starts and how a world point gets into the mesh's space — so
//! several meshes and any number of instances of each share one set of buffers. Each struct is
//! declared once with `fray_core::gpu_struct!` (the Rust `Pod` struct and its WGSL twin from one
//! field list).
//!
//! Precision: each mesh is stored relative to its own **anchor** (the centre of its f64 root
//! box, in the mesh's space), subtracted in f64 before rounding to f32, so the f32 corners keep
//! `ε_f32 · (mesh size)` wherever the mesh sits. Node boxes are the f64 boxes minus the anchor
//! **rounded outward** (down for the minimum, up for the maximum): rounding is monotone, so a
//! box still bounds the f32 corners of every triangle under it. The world enters only through
//! the instance blocks ([`GpuMeshInstance`]): the affine map from reference-relative world
//! positions (the camera's) to anchor-relative mesh positions, computed in f64 before rounding.
//! A camera that moves rewrites only those blocks ([`GpuMeshes::instances_at`]); the nodes,
//! triangles and vertices stay resident.
//!
//! Stack depth: the WGSL traversal keeps its pending nodes in a fixed private stack of
//! [`MESH_STACK`] entries; a BVH needs `max_depth + 1` of them (both children of an inner node
//! are pushed, nearer last), and [`GpuMeshes::build`] refuses a mesh whose BVH is deeper
//! ([`MeshLayoutError::TooDeep`]) instead of letting the GPU drop nodes.

use crate::MeshBvh;
pub use fray_core::gpu_struct::GpuStruct;
use fray_core::{BudgetError, MemoryBudget};
use glam::{DAffine3, DVec3};

/// Entries of the WGSL traversal's private stack (`array<u32, MESH_STACK>` and an `f32` entry
/// distance each: 512 bytes per invocation). A mesh's BVH may be at most `MESH_STACK − 1` deep.
pub const MESH_STACK: u32 = 64;
/// An instance's `root` when its mesh has no triangles.
pub const MESH_NO_NODE: u32 = u32::MAX;
/// A hit's `instance` when nothing was hit.
pub const MESH_NO_HIT: u32 = u32::MAX;
/// [`GpuMeshInstance::flags`]: the mesh has texture coordinates (else every uv is 0).
pub const MESH_FLAG_UVS: u32 = 1;
/// [`GpuMeshInstance::flags`]: shade with the interpolated vertex normals (else the face's);
/// set by [`GpuMeshes::with_smooth`].
pub const MESH_FLAG_SMOOTH: u32 = 2;

fray_core::gpu_struct! {
    /// A BVH node (32 bytes). Its box is the f64 box minus the mesh's anchor, rounded outward.
    /// Indices are absolute (into the concatenated arrays): an inner node's children are nodes
    /// `first` and `first + 1`; a leaf's triangles are `mesh_triangles[first..first + count]`.
    pub struct GpuMeshNode {
        pub min_x: f32,
        pub min_y: f32,
        pub min_z: f32,
        pub first: u32,
        pub max_x: f32,
        pub max_y: f32,
        pub max_z: f32,
        /// 0 for an inner node, else the leaf's triangle count.
        pub count: u32,
    }
}

fray_core::gpu_struct! {
    /// A triangle (64 bytes), in its mesh's leaf order: its corners minus the mesh's anchor,
    /// rounded to f32 (`w` is 0; a vertex shared by several triangles has the same bits in
    /// each, which the watertight test relies on), the mesh's own index of it (what a hit
    /// reports, as `MeshHit::triangle`), and its corners' vertices in the concatenated vertex
    /// array (for normals and uvs).
    pub struct GpuMeshTriangle {
        pub a: [f32; 4],
        pub b: [f32; 4],
        pub c: [f32; 4],
        pub index: u32,
        pub v0: u32,
        pub v1: u32,
        pub v2: u32,
    }
}

fray_core::gpu_struct! {
    /// A vertex's shading attributes (32 bytes): the mesh's unit normal in mesh space (`w` 0;
    /// the file's or angle-weighted, `TriangleMesh::normals`) and its texture coordinates (0
    /// without them).
    pub struct GpuMeshVertex {
        pub normal: [f32; 4],
        pub uv: [f32; 2],
        pub pad: [f32; 2],
    }
}

fray_core::gpu_struct! {
    /// One placed mesh (64 bytes). Rows of the affine map from reference-relative world
    /// positions to anchor-relative mesh positions, `p_mesh[i] = dot(to_mesh_i.xyz, p) +
    /// to_mesh_i.w` (directions: the `xyz` parts alone; the ray is not renormalised, so `t`
    /// stays the world ray's). The same rows give world normals: `n_world ∝ Σᵢ n_mesh[i] ·
    /// to_mesh_i.xyz` (the inverse transpose).
    pub struct GpuMeshInstance {
        pub to_mesh_x: [f32; 4],
        pub to_mesh_y: [f32; 4],
        pub to_mesh_z: [f32; 4],
        /// The mesh's root node in the concatenated nodes ([`MESH_NO_NODE`]: no triangles).
        pub root: u32,
        /// Which of the meshes given to [`GpuMeshes::build`].
        pub mesh: u32,
        /// The material index (0 unless [`GpuMeshes::with_materials`] sets it).
        pub material: u32,
        /// [`MESH_FLAG_UVS`], [`MESH_FLAG_SMOOTH`].
        pub flags: u32,
    }
}

/// The WGSL declarations of the mesh structs (generated from their one definition).
pub fn wgsl_declarations() -> String {
    let mut s = String::from("// Generated by fray_mesh::gpu_layout — do not edit.\n");
    for decl in [
        GpuMeshNode::declaration(),
        GpuMeshTriangle::declaration(),
        GpuMeshVertex::declaration(),
        GpuMeshInstance::declaration(),
    ] {
        s.push_str(&decl);
    }
    s
}

/// The constants mesh.wgsl reads, for the generated prelude.
pub fn wgsl_constants() -> [(&'static str, u32); 5] {
    [
        ("MESH_STACK", MESH_STACK),
        ("MESH_NO_NODE", MESH_NO_NODE),
        ("MESH_NO_HIT", MESH_NO_HIT),
        ("MESH_FLAG_UVS", MESH_FLAG_UVS),
        ("MESH_FLAG_SMOOTH", MESH_FLAG_SMOOTH),
    ]
}

/// Why meshes cannot be laid out for the GPU.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshLayoutError {
    /// The BVH is deeper than the GPU traversal's stack holds.
    #[error(
        "mesh {mesh}'s BVH is {depth} levels deep: its GPU traversal needs a stack of {} \
         entries, more than the {limit} it has",
        depth + 1
    )]
    TooDeep { mesh: usize, depth: u32, limit: u32 },
    /// The concatenated arrays would need indices past `u32`.
    #[error("the meshes need {needed} {what}, more than a u32 index reaches")]
    IndexOverflow { what: &'static str, needed: u64 },
    /// An instance names a mesh that is not there.
    #[error("instance {instance} names mesh {mesh}, but there are only {meshes}")]
    NoSuchMesh {
        instance: usize,
        mesh: u32,
        meshes: usize,
    },
    /// An instance's transform is not finite and invertible.
    #[error(
        "instance {instance}'s transform must be finite and invertible (determinant {determinant})"
    )]
    BadTransform { instance: usize, determinant: f64 },
    /// A mesh (relative to its anchor) or an instance's map is beyond the range of f32.
    #[error("{what} is beyond the range of f32")]
    OutOfRange { what: String },
    #[error(transparent)]
    Budget(#[from] BudgetError),
}

/// Where one mesh lies in the concatenated arrays, and its anchor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuMeshRange {
    /// The point (mesh space, f64) the mesh's f32 positions are relative to: its root box's
    /// centre (0 for an empty mesh).
    pub anchor: DVec3,
    pub first_node: u32,
    pub nodes: u32,
    pub first_triangle: u32,
    pub triangles: u32,
    pub first_vertex: u32,
    pub vertices: u32,
    /// `MeshBvh::max_depth`: the traversal needs `max_depth + 1` stack entries.
    pub max_depth: u32,
    pub has_uvs: bool,
}

/// Meshes and their instances flattened for the GPU (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct GpuMeshes {
    /// Per mesh: its ranges and anchor.
    pub meshes: Vec<GpuMeshRange>,
    /// Per instance: its mesh and its mesh-to-world transform, as given.
    pub placements: Vec<(u32, DAffine3)>,
    /// Per instance, relative to the reference point given to [`GpuMeshes::build`].
    pub instances: Vec<GpuMeshInstance>,
    pub nodes: Vec<GpuMeshNode>,
    pub triangles: Vec<GpuMeshTriangle>,
    pub vertices: Vec<GpuMeshVertex>,
}

/// The largest f32 at most `x` (f64 → f32 rounded down).
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// The smallest f32 at least `x` (f64 → f32 rounded up).
fn up(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

fn v4(v: DVec3) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, 0.0]
}

impl GpuMeshes {
    /// `meshes` flattened, with `instances` — `(mesh index, mesh-to-world transform)` — relative
    /// to `reference` (world, f64: the camera), every material 0; each BVH's depth checked
    /// against [`MESH_STACK`], the host arrays against `budget` and the `u32` indices before
    /// anything is allocated.
    pub fn build(
        meshes: &[&MeshBvh],
        instances: &[(u32, DAffine3)],
        reference: DVec3,
        budget: &MemoryBudget,
    ) -> Result<Self, MeshLayoutError> {
        Self::build_with_stack(meshes, instances, reference, budget, MESH_STACK)
    }

    /// [`GpuMeshes::build`] for a traversal stack of `stack` entries (a module composed with a
    /// smaller `MESH_STACK`, or a test of the refusal).
    pub fn build_with_stack(
        meshes: &[&MeshBvh],
        instances: &[(u32, DAffine3)],
        reference: DVec3,
        budget: &MemoryBudget,
        stack: u32,
    ) -> Result<Self, MeshLayoutError> {
        // Ranges first: depth, index and budget checks before the arrays are allocated.
        let mut ranges = Vec::with_capacity(meshes.len());
        let (mut nodes, mut triangles, mut vertices) = (0u64, 0u64, 0u64);
        let index = |what, v: u64| {
            u32::try_from(v).map_err(|_| MeshLayoutError::IndexOverflow { what, needed: v })
        };
        for (m, bvh) in meshes.iter().enumerate() {
            let depth = bvh.max_depth();
            if u64::from(depth) + 1 > u64::from(stack) {
                return Err(MeshLayoutError::TooDeep {
                    mesh: m,
                    depth,
                    limit: stack,
                });
            }
            let (n, t, v) = (
                bvh.node_count() as u64,
                bvh.leaf_order().len() as u64,
                bvh.mesh().positions.len() as u64,
            );
            let b = bvh.bounds();
            let anchor = if n == 0 {
                DVec3::ZERO
            } else {
                (b.min + b.max) * 0.5
            };
            if n > 0 {
                let extent = (b.max - anchor).max(anchor - b.min);
                if !v4(extent).iter().all(|x| x.is_finite()) {
                    return Err(MeshLayoutError::OutOfRange {
                        what: format!("mesh {m} (relative to its centre)"),
                    });
                }
            }
            ranges.push(GpuMeshRange {
                anchor,
                first_node: index("BVH nodes", nodes)?,
                nodes: index("BVH nodes", n)?,
                first_triangle: index("triangles", triangles)?,
                triangles: index("triangles", t)?,
                first_vertex: index("vertices", vertices)?,
                vertices: index("vertices", v)?,
                max_depth: depth,
                has_uvs: bvh.mesh().uvs.is_some(),
            });
            nodes += n;
            triangles += t;
            vertices += v;
        }
        index("BVH nodes", nodes)?;
        index("triangles", triangles)?;
        index("vertices", vertices)?;
        let size = |n: u64, bytes: usize| n.saturating_mul(bytes as u64);
        let bytes = size(instances.len() as u64, size_of::<GpuMeshInstance>())
            .saturating_add(size(nodes, size_of::<GpuMeshNode>()))
            .saturating_add(size(triangles, size_of::<GpuMeshTriangle>()))
            .saturating_add(size(vertices, size_of::<GpuMeshVertex>()));
        budget.check("the meshes' GPU arrays", bytes)?;

        let mut out = Self {
            meshes: ranges,
            placements: instances.to_vec(),
            instances: Vec::with_capacity(instances.len()),
            nodes: Vec::with_capacity(nodes as usize),
            triangles: Vec::with_capacity(triangles as usize),
            vertices: Vec::with_capacity(vertices as usize),
        };
        for (bvh, range) in meshes.iter().zip(&out.meshes) {
            let anchor = range.anchor;
            out.nodes.extend(bvh.nodes().map(|n| {
                let (lo, hi) = (n.min - anchor, n.max - anchor);
                let base = if n.is_leaf() {
                    range.first_triangle
                } else {
                    range.first_node
                };
                GpuMeshNode {
                    min_x: down(lo.x),
                    min_y: down(lo.y),
                    min_z: down(lo.z),
                    first: base + n.first,
                    max_x: up(hi.x),
                    max_y: up(hi.y),
                    max_z: up(hi.z),
                    count: n.count,
                }
            }));
            let mesh = bvh.mesh();
            let corner = |v: u32| v4(mesh.positions[v as usize] - anchor);
            out.triangles.extend(bvh.leaf_order().iter().map(|&t| {
                let [i, j, k] = mesh.triangles[t as usize];
                GpuMeshTriangle {
                    a: corner(i),
                    b: corner(j),
                    c: corner(k),
                    index: t,
                    v0: range.first_vertex + i,
                    v1: range.first_vertex + j,
                    v2: range.first_vertex + k,
                }
            }));
            out.vertices
                .extend(mesh.normals.iter().enumerate().map(|(v, n)| {
                    let uv = mesh
                        .uvs
                        .as_ref()
                        .map_or([0.0; 2], |uvs| [uvs[v].x as f32, uvs[v].y as f32]);
                    GpuMeshVertex {
                        normal: v4(*n),
                        uv,
                        pad: [0.0; 2],
                    }
                }));
        }
        out.instances = out.instances_at(reference)?;
        Ok(out)
    }

    /// The instance blocks relative to `reference` (world, f64): what a frame from a moved
    /// camera rewrites (nothing else depends on the reference point). Each keeps the material
    /// and the smooth flag its current block has ([`GpuMeshes::with_materials`],
    /// [`GpuMeshes::with_smooth`]).
    pub fn instances_at(&self, reference: DVec3) -> Result<Vec<GpuMeshInstance>, MeshLayoutError> {
        self.placements
            .iter()
            .enumerate()
            .map(|(i, &(mesh, to_world))| {
                let range = self
                    .meshes
                    .get(mesh as usize)
                    .ok_or(MeshLayoutError::NoSuchMesh {
                        instance: i,
                        mesh,
                        meshes: self.meshes.len(),
                    })?;
                let mut block = instance_block(i, range, mesh, to_world, reference)?;
                if let Some(current) = self.instances.get(i) {
                    block.material = current.material;
                    block.flags |= current.flags & MESH_FLAG_SMOOTH;
                }
                Ok(block)
            })
            .collect()
    }

    /// These meshes with instance `k`'s material `materials[k]` (instances past the slice keep
    /// theirs).
    pub fn with_materials(mut self, materials: &[u32]) -> Self {
        for (block, &m) in self.instances.iter_mut().zip(materials) {
            block.material = m;
        }
        self
    }

    /// These meshes with instance `k` shaded smooth (interpolated vertex normals) where
    /// `smooth[k]`, faceted otherwise ([`MESH_FLAG_SMOOTH`]; instances past the slice keep
    /// theirs).
    pub fn with_smooth(mut self, smooth: &[bool]) -> Self {
        for (block, &on) in self.instances.iter_mut().zip(smooth) {
            block.flags = (block.flags & !MESH_FLAG_SMOOTH) | if on { MESH_FLAG_SMOOTH } else { 0 };
        }
        self
    }
}

/// The block of instance `i` (mesh `mesh` at `range`, placed by `to_world`) relative to
/// `reference`: `p_mesh − anchor = L · (p_world − reference) + (L · reference + l − anchor)`
/// where `to_world⁻¹ = (L, l)`, the constant in f64.
fn instance_block(
    i: usize,
    range: &GpuMeshRange,
    mesh: u32,
    to_world: DAffine3,
    reference: DVec3,
) -> Result<GpuMeshInstance, MeshLayoutError> {
    let determinant = to_world.matrix3.determinant();
    if !(determinant.is_finite() && determinant != 0.0 && to_world.translation.is_finite()) {
        return Err(MeshLayoutError::BadTransform {
            instance: i,
            determinant,
        });
    }
    let to_mesh = to_world.inverse();
    let offset = to_mesh.transform_point3(reference) - range.anchor;
    let l = to_mesh.matrix3;
    let row = |k: usize| {
        let r = l.row(k);
        [r.x as f32, r.y as f32, r.z as f32, offset[k] as f32]
    };
    let block = GpuMeshInstance {
        to_mesh_x: row(0),
        to_mesh_y: row(1),
        to_mesh_z: row(2),
        root: if range.nodes == 0 {
            MESH_NO_NODE
        } else {
            range.first_node
        },
        mesh,
        material: 0,
        flags: if range.has_uvs { MESH_FLAG_UVS } else { 0 },
    };
    let finite = [block.to_mesh_x, block.to_mesh_y, block.to_mesh_z]
        .iter()
        .flatten()
        .all(|x| x.is_finite());
    if !finite {
        return Err(MeshLayoutError::OutOfRange {
            what: format!("instance {i}'s map into its mesh's space"),
        });
    }
    Ok(block)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TriangleMesh;

    fn grid(n: usize, offset: DVec3) -> MeshBvh {
        // An n × n grid of quads in z = 0 (two triangles each), moved by `offset`.
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(DVec3::new(i as f64 * 0.37, j as f64 * 0.29, 0.0) + offset);
            }
        }
        let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        MeshBvh::build(TriangleMesh::new(positions, triangles).unwrap())
    }

    #[test]
    fn the_wgsl_twins_lay_out_as_rust() {
        GpuMeshNode::check_layout().unwrap();
        GpuMeshTriangle::check_layout().unwrap();
        GpuMeshVertex::check_layout().unwrap();
        GpuMeshInstance::check_layout().unwrap();
        assert_eq!(
            [
                size_of::<GpuMeshNode>(),
                size_of::<GpuMeshTriangle>(),
                size_of::<GpuMeshVertex>(),
                size_of::<GpuMeshInstance>()
            ],
            [32, 64, 32, 64]
        );
        let decl = wgsl_declarations();
        assert!(
            decl.contains("struct GpuMeshNode {\n    min_x: f32,"),
            "{decl}"
        );
        assert!(decl.contains("    to_mesh_x: vec4<f32>,\n"), "{decl}");
    }

    /// Two meshes and three instances share one set of arrays: offsets per mesh, absolute
    /// indices, triangles in leaf order with the mesh's own index, every f32 box bounding its
    /// subtree's f32 corners (rounded outward) even far from the origin.
    #[test]
    fn meshes_concatenate_and_boxes_bound_the_f32_triangles() {
        let far = DVec3::new(3.0e5, -2.0e4, 1.0e6);
        let (a, b) = (grid(3, DVec3::ZERO), grid(9, far));
        let place = DAffine3::from_scale_rotation_translation(
            DVec3::new(2.0, 0.5, 3.0),
            glam::DQuat::from_rotation_y(0.7),
            DVec3::new(100.0, -4.0, 7.0),
        );
        let reference = DVec3::new(10.0, 20.0, 30.0);
        let g = GpuMeshes::build(
            &[&a, &b],
            &[(0, DAffine3::IDENTITY), (1, DAffine3::IDENTITY), (0, place)],
            reference,
            &MemoryBudget::default(),
        )
        .unwrap();
        let (ra, rb) = (g.meshes[0], g.meshes[1]);
        assert_eq!((ra.first_node, ra.nodes), (0, a.node_count() as u32));
        assert_eq!(rb.first_node, ra.nodes);
        assert_eq!((rb.first_triangle, ra.triangles), (18, 18));
        assert_eq!((rb.first_vertex, ra.vertices), (16, 16));
        assert_eq!(g.nodes.len(), a.node_count() + b.node_count());
        assert_eq!(g.triangles.len(), 18 + 162);
        assert_eq!(g.vertices.len(), 16 + 100);
        assert_eq!(
            g.instances
                .iter()
                .map(|i| (i.root, i.mesh))
                .collect::<Vec<_>>(),
            vec![(0, 0), (ra.nodes, 1), (0, 0)]
        );
        // Every node's box holds its children's boxes and its leaves' f32 corners.
        fn check(g: &GpuMeshes, index: u32) {
            let n = g.nodes[index as usize];
            let inside = |p: [f32; 4]| {
                (n.min_x..=n.max_x).contains(&p[0])
                    && (n.min_y..=n.max_y).contains(&p[1])
                    && (n.min_z..=n.max_z).contains(&p[2])
            };
            if n.count > 0 {
                for t in &g.triangles[n.first as usize..(n.first + n.count) as usize] {
                    assert!(inside(t.a) && inside(t.b) && inside(t.c), "{t:?} in {n:?}");
                }
            } else {
                for c in [n.first, n.first + 1] {
                    let m = g.nodes[c as usize];
                    assert!(inside([m.min_x, m.min_y, m.min_z, 0.0]));
                    assert!(inside([m.max_x, m.max_y, m.max_z, 0.0]));
                    check(g, c);
                }
            }
        }
        check(&g, 0);
        check(&g, rb.first_node);
        // Triangles: the mesh's own index, its vertices absolute, corners anchor-relative.
        for (slot, t) in g.triangles[rb.first_triangle as usize..].iter().enumerate() {
            let own = b.leaf_order()[slot];
            assert_eq!(t.index, own);
            let [i, j, _] = b.mesh().triangles[own as usize];
            assert_eq!((t.v0, t.v1), (rb.first_vertex + i, rb.first_vertex + j));
            let want = b.mesh().positions[i as usize] - rb.anchor;
            assert_eq!(t.a, v4(want));
        }
        // The far mesh keeps f32 precision: its corners are within 2 of its anchor.
        assert!(rb.anchor.distance(far + DVec3::new(1.665, 1.305, 0.0)) < 1e-9);
        assert!(g.triangles.iter().all(|t| t.a[0].abs() < 3.0));
        // The instance map takes the reference point to the mesh-space reference point.
        let i2 = g.instances[2];
        let want = place.inverse().transform_point3(reference) - ra.anchor;
        assert_eq!(
            [i2.to_mesh_x[3], i2.to_mesh_y[3], i2.to_mesh_z[3]],
            [want.x as f32, want.y as f32, want.z as f32]
        );
        // Moving the camera changes only the instance blocks.
        let moved = g.instances_at(reference + DVec3::X).unwrap();
        assert_ne!(moved[2], g.instances[2]);
        assert_eq!(moved[2].to_mesh_x[..3], g.instances[2].to_mesh_x[..3]);
        let g = g.with_materials(&[4, 5]).with_smooth(&[true, false, true]);
        assert_eq!(
            g.instances.iter().map(|i| i.material).collect::<Vec<_>>(),
            vec![4, 5, 0]
        );
        // Materials and the smooth flag survive a move; the mirror flag is the transform's.
        let moved = g.instances_at(reference + DVec3::Y).unwrap();
        assert_eq!(
            moved
                .iter()
                .map(|i| (i.material, i.flags))
                .collect::<Vec<_>>(),
            g.instances
                .iter()
                .map(|i| (i.material, i.flags))
                .collect::<Vec<_>>()
        );
        assert_eq!(
            g.instances.iter().map(|i| i.flags).collect::<Vec<_>>(),
            vec![MESH_FLAG_SMOOTH, 0, MESH_FLAG_SMOOTH]
        );
        let mirrored = GpuMeshes::build(
            &[&a],
            &[(0, DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0)))],
            reference,
            &MemoryBudget::default(),
        )
        .unwrap();
        // No flag: the inverse transpose already turns a mirroring instance's normals outward.
        assert_eq!(mirrored.instances[0].flags, 0);
    }

    #[test]
    fn rounding_outward_bounds_the_f64_value() {
        for x in [0.1, -0.1, 1.0 / 3.0, 1e-40, -3.0e5 - 0.123, 2.0, 0.0] {
            let (d, u) = (down(x), up(x));
            assert!(f64::from(d) <= x && x <= f64::from(u), "{x}");
            assert!(u == d || u == d.next_up(), "{x}: {d} {u}");
        }
    }

    /// Deep BVHs, bad instances, budgets and the f32 range are refused with what and how much.
    #[test]
    fn refusals_name_what_and_how_much() {
        let a = grid(6, DVec3::ZERO);
        let depth = a.max_depth();
        assert!(depth >= 3, "{depth}");
        let budget = MemoryBudget::default();
        let id = [(0, DAffine3::IDENTITY)];
        // A stack of exactly depth + 1 entries is enough; one fewer is refused.
        assert!(GpuMeshes::build_with_stack(&[&a], &id, DVec3::ZERO, &budget, depth + 1).is_ok());
        let e = GpuMeshes::build_with_stack(&[&a], &id, DVec3::ZERO, &budget, depth).unwrap_err();
        assert_eq!(
            e,
            MeshLayoutError::TooDeep {
                mesh: 0,
                depth,
                limit: depth
            }
        );
        assert!(e.to_string().contains("stack of"), "{e}");
        let e = GpuMeshes::build(&[&a], &[(1, DAffine3::IDENTITY)], DVec3::ZERO, &budget);
        assert!(matches!(
            e,
            Err(MeshLayoutError::NoSuchMesh { mesh: 1, .. })
        ));
        let flat = DAffine3::from_scale(DVec3::new(1.0, 0.0, 1.0));
        let e = GpuMeshes::build(&[&a], &[(0, flat)], DVec3::ZERO, &budget);
        assert!(matches!(
            e,
            Err(MeshLayoutError::BadTransform { instance: 0, .. })
        ));
        let e = GpuMeshes::build(&[&a], &id, DVec3::ZERO, &MemoryBudget::new(1000)).unwrap_err();
        assert!(
            matches!(&e, MeshLayoutError::Budget(b) if b.needed > 1000),
            "{e}"
        );
        let huge = grid(1, DVec3::ZERO);
        let mut m = huge.mesh().clone();
        m.positions[0].x = 1e300;
        let huge = MeshBvh::build(m);
        let e = GpuMeshes::build(&[&huge], &id, DVec3::ZERO, &budget).unwrap_err();
        assert!(matches!(e, MeshLayoutError::OutOfRange { .. }), "{e}");
        // An empty mesh lays out with no root: its instances are skipped on the GPU.
        let empty = MeshBvh::build(TriangleMesh::new(Vec::new(), Vec::new()).unwrap());
        let g = GpuMeshes::build(&[&empty], &id, DVec3::ZERO, &budget).unwrap();
        assert_eq!(g.instances[0].root, MESH_NO_NODE);
        assert!(g.nodes.is_empty() && g.triangles.is_empty());
    }
}
