//! Ray generation: the camera rays of a band of rows — per pixel its centre and, with
//! anti-aliasing, its samples — into the frame's paths (`shaders/raygen.wgsl`). The CPU twin is
//! `fray_core::Projector::ray` with `fray_core::PixelSamples` (the GPU's depth and anti-aliased
//! colour are checked against the CPU's frames).

use super::band::{PassSpec, Role, Workload};

/// The ray generation pass: the band's pixels × rays per pixel, 64 a workgroup.
pub const RAYGEN: PassSpec = PassSpec {
    label: "raygen",
    entry: "raygen.wgsl",
    roles: &[Role::Frame],
    workload: Workload::Rays,
};
