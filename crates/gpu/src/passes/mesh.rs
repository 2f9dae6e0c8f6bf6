//! The mesh intersection pass: one workgroup per work item of the band, each pixel's camera
//! rays cast against the item's mesh candidates — one instance each, its BVH nearest child
//! first and the watertight triangle test in f32 (`shaders/mesh.wgsl`, the f32 twin of
//! `fray_mesh::Instance::nearest_hit`) — over `(t_near, nearest hit so far)`, narrowing the
//! paths' hits after the free forms and the terrains (a tie keeps the earlier kind's hit) and
//! recording the instance, the triangle and its barycentrics for the shade pass. Built only
//! for scenes with meshes.

use super::band::{PassSpec, Role, Workload};

/// The mesh intersection pass.
pub const MESHES: PassSpec = PassSpec {
    label: "meshes",
    entry: "intersect_mesh.wgsl",
    roles: &[Role::Frame, Role::Work, Role::Meshes],
    workload: Workload::Items,
};
