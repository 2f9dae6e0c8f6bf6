//! The terrain intersection pass: one workgroup per work item of the band, each pixel's camera
//! rays cast against the item's terrain candidates at their pixel level of detail
//! (`shaders/terrain.wgsl`, the f32 twin of `fray_terrain::Terrain::cast_footprint`) over
//! `[t_near, nearest hit so far]`, narrowing the paths' hits after the free forms. Built only
//! for scenes with terrains.

use super::band::{PassSpec, Role, Workload};

/// The terrain intersection pass.
pub const TERRAINS: PassSpec = PassSpec {
    label: "terrains",
    entry: "intersect_terrain.wgsl",
    roles: &[Role::Frame, Role::Work, Role::Terrains],
    workload: Workload::Items,
};
