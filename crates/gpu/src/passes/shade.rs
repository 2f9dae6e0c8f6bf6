//! Surfaces and shading: one invocation per ray of the band that hit — the surface (a free
//! form's normal and leaf, a terrain's normal, a mesh triangle's face or interpolated normal),
//! the cut face, ambient + Lambert + normalised
//! Phong with each light through the RGB transmittance of a shadow ray that every kind answers
//! any-hit and through the media's transmittance — the fog's, the clouds', and the air's for the
//! sky's sun (`shaders/shade.wgsl`, fray-trace's `Integrator` in f32).

use super::band::{PassSpec, Role, Workload};

/// The shade pass: the frame, the free forms, the lights and materials (with the fog layer, the
/// sky's block and tables and the clouds' where the scene has them: `bindings::shading`), and
/// only with terrains, meshes or textures their group (`bindings::surfaces`: any of them
/// together). One invocation per ray of the band; Whitted's levels dispatch it indirectly.
pub const SHADE: PassSpec = PassSpec {
    label: "shade",
    entry: "shade.wgsl",
    roles: &[Role::Frame, Role::FreeForms, Role::Shading, Role::Surfaces],
    workload: Workload::Rays,
};
