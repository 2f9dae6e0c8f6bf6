//! Resolve: the band's pixels from their camera rays — colour the samples' box-filtered
//! radiance, depth and normal from the centre ray — into the frame's storage textures, with the
//! tone-mapped sRGB display image made on the GPU (`shaders/resolve.wgsl`; the CPU twins are the
//! frame loop's box filter, `fray_core::ToneMap` and `linear_to_srgb`).

use super::band::{PassSpec, Role, Workload};

/// The resolve pass: 8 × 8 pixels a workgroup.
pub const RESOLVE: PassSpec = PassSpec {
    label: "resolve",
    entry: "resolve.wgsl",
    roles: &[Role::Frame, Role::Targets],
    workload: Workload::Tiles,
};
