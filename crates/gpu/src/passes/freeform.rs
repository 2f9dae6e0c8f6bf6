//! The free-form intersection pass: one workgroup per work item of the band, each pixel's
//! camera rays cast against the item's free-form candidates (active leaves and perturbations,
//! pruned CSG programs) by the halving search of `shaders/freeform.wgsl`, the f32 twin of
//! `fray_geometry::RayCaster`; the nearest hit goes into each ray's path.

use super::band::{PassSpec, Role, Workload};

/// The free-form intersection pass.
pub const FREE_FORMS: PassSpec = PassSpec {
    label: "free forms",
    entry: "intersect_freeform.wgsl",
    roles: &[Role::Frame, Role::FreeForms, Role::Work],
    workload: Workload::Items,
};
